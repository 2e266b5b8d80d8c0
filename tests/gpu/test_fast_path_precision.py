"""The fast path's numerics, layer by layer, against what bf16 autocast already changes: for each NatureCNN
layer with its ReLU, at K = 8 packed runs of B = 256 frames, the output and the gradients (input for conv2 and
conv3, weight and bias for all) of
- the Triton kernels in bf16, as `--bf16 --triton-conv` runs them (conv1 on the uint8 frames), and
- cuDNN's grouped convolution under bf16 autocast, as `--bf16` alone runs it,
each against a float64 reference on the same inputs. The Triton kernels' error must be no larger than
autocast's: relative L1 error (sum |got - want| / sum |want|), with 10 % slack for the rounding of two
different summation orders. Each side's ReLU mask is its own, as in training."""
import pytest
import torch
import torch.nn.functional as F

from kage.ppo.fast import triton_conv as tc

K, B = 8, 256
# (name, input side, in channels, out channels, kernel, stride)
LAYERS = [("conv1", 128, 3, 32, 8, 4), ("conv2", 31, 32, 64, 4, 2), ("conv3", 14, 64, 64, 3, 1)]
SLACK = 1.1


def grouped(x: torch.Tensor) -> torch.Tensor:
    """[K, B, H, W, C] -> [B, K * C, H, W]: the runs as channel groups."""
    k, b, h, w, c = x.shape
    return x.permute(1, 0, 4, 2, 3).reshape(b, k * c, h, w)


def packed(y: torch.Tensor, k: int) -> torch.Tensor:
    """[B, K * C, H, W] -> [K, B, H, W, C]."""
    b, kc, h, w = y.shape
    return y.reshape(b, k, kc // k, h, w).permute(1, 0, 3, 4, 2)


def relative_l1(got: torch.Tensor, want: torch.Tensor) -> float:
    return ((got.double() - want).abs().sum() / want.abs().sum()).item()


def layer_inputs(layer, device: str):
    """The layer's input as the network gives it (uint8 frames for conv1, a ReLU's output otherwise), its
    parameters as nn.Conv2d(groups=K) initialises them, and an output gradient."""
    name, side, cin, cout, ksize, stride = layer
    torch.manual_seed(0)
    if name == "conv1":
        x = torch.randint(0, 256, (K, B, side, side, cin), dtype=torch.uint8, device=device)
    else:
        x = F.relu(torch.randn(K, B, side, side, cin, device=device))
    conv = torch.nn.Conv2d(K * cin, K * cout, ksize, stride, groups=K, device=device)
    out = (side - ksize) // stride + 1
    dy = torch.randn(K, B, out, out, cout, device=device)
    return x, conv.weight.detach(), conv.bias.detach(), dy


def errors_per_quantity(layer, device: str = "cuda") -> dict:
    """{quantity: (Triton bf16 error, autocast bf16 error)} against float64 for one layer."""
    name, _, _, _, _, stride = layer
    x, weight, bias, dy = layer_inputs(layer, device)
    frames = name == "conv1"
    x_float = x.float() / 255 if frames else x  # what autocast converts to bf16, and the reference's input

    results = {}
    for path in ("float64", "triton", "autocast"):
        w = weight.clone().double() if path == "float64" else weight.clone()
        b = bias.clone().double() if path == "float64" else bias.clone()
        w.requires_grad_()
        b.requires_grad_()
        inputs = [w, b]
        if path == "triton" and frames:
            images = torch.arange(K * B, device=device).view(K, B)
            y = tc.packed_conv_frames(x, images, w, b, stride, torch.bfloat16, relu=True)
        elif path == "triton":
            xin = x.to(torch.bfloat16).requires_grad_()
            inputs.insert(0, xin)
            with torch.autocast(device, dtype=torch.bfloat16):
                y = tc.packed_conv(xin, w, b, stride, relu=True)
        else:
            xin = x_float.double() if path == "float64" else x_float.clone()
            if not frames:
                xin.requires_grad_()
                inputs.insert(0, xin)
            with torch.autocast(device, dtype=torch.bfloat16, enabled=path == "autocast"):
                y = packed(F.relu(F.conv2d(grouped(xin), w, b, stride=stride, groups=K)), K)
        grads = torch.autograd.grad(y, inputs, dy.to(y.dtype))
        results[path] = dict(zip((["dx"] if not frames else []) + ["dw", "db"], grads), y=y)
    return {q: (relative_l1(results["triton"][q], results["float64"][q]),
                relative_l1(results["autocast"][q], results["float64"][q])) for q in results["float64"]}


@pytest.mark.parametrize("layer", LAYERS, ids=[layer[0] for layer in LAYERS])
def test_triton_error_is_no_larger_than_autocast(layer):
    torch.backends.cudnn.allow_tf32 = False  # the float64 reference and the autocast path as they are
    failures = []
    for quantity, (triton_error, autocast_error) in errors_per_quantity(layer).items():
        ok = triton_error <= SLACK * autocast_error
        print(f"{layer[0]} {quantity}: relative L1 error against float64, Triton bf16 {triton_error:.3e}, "
              f"bf16 autocast {autocast_error:.3e} {'PASS' if ok else 'FAIL'}", flush=True)
        if not ok:
            failures.append(quantity)
    assert not failures, f"{layer[0]}: the Triton kernels' error exceeds autocast's for {failures}"
