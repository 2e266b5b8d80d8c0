"""kage.ppo.fast.triton_conv's packed convolutions (Triton implicit-GEMM kernels, the run as a grid axis) against
cuDNN's grouped convolutions, forward and the input, weight and bias gradients, for the NatureCNN's three layers
(alone and with the fused ReLU) at K = 3 and 8 packed runs, in fp32 and bf16; and conv1 as the trainer runs it,
striding over uint8 frames in a rollout buffer at a minibatch's indices (output, weight and bias gradients). The fp32 checks allow 1e-3: tl.dot
rounds fp32 operands to TF32 (10-bit mantissa). The bf16 checks allow 2e-2 (outputs rounded to bf16). Errors are max |got - want| / max |want|.
`python3 tests/gpu/test_triton_conv.py [--profile]` also times the torso against cuDNN channels-last bf16."""
import argparse
import pathlib
import sys

import pytest
import torch
import torch.nn.functional as F
import triton

from kage.ppo.fast import space_to_depth as s2d
from kage.ppo.fast import triton_conv as tc

# NatureCNN's convolutions on 128 x 128 x 3 frames: (name, input side, in channels, out channels, kernel, stride).
LAYERS = [("conv1", 128, 3, 32, 8, 4), ("conv2", 31, 32, 64, 4, 2), ("conv3", 14, 64, 64, 3, 1)]


def relative_error(got: torch.Tensor, want: torch.Tensor) -> float:
    return ((got.float() - want).abs().max() / want.abs().max().clamp_min(1e-30)).item()


def check_layer(k: int, b: int, layer, dtype: torch.dtype, tolerance: float, relu: bool = False) -> int:
    """packed_conv's output and gradients (x, weight, bias) for one layer (with its fused ReLU under `relu`)
    against F.conv2d(groups=K) (and F.relu) in fp32 on the same (dtype-rounded) values; prints one line per
    quantity and returns the number of failures."""
    name, side, cin, cout, ksize, stride = layer
    torch.manual_seed(0)
    x = torch.randn(k, b, side, side, cin, device="cuda").to(dtype).requires_grad_()
    conv = torch.nn.Conv2d(k * cin, k * cout, ksize, stride, groups=k, device="cuda")
    weight, bias = conv.weight.detach().requires_grad_(), conv.bias.detach().uniform_(-1, 1).requires_grad_()
    y = tc.packed_conv(x, weight, bias, stride, relu=relu)
    dy = torch.randn_like(y)
    got = (y,) + torch.autograd.grad(y, (x, weight, bias), dy)

    x_ref = x.detach().float().permute(1, 0, 4, 2, 3).reshape(b, k * cin, side, side).requires_grad_()
    w_ref = weight.detach().to(dtype).float().requires_grad_()
    b_ref = bias.detach().clone().requires_grad_()
    y_ref = F.conv2d(x_ref, w_ref, b_ref, stride=stride, groups=k)
    out = y_ref.shape[-1]
    dy_ref = dy.float().permute(1, 0, 4, 2, 3).reshape(b, k * cout, out, out)
    if relu:
        # ReLU's gradient follows the sign of the kernel's own output, as autograd's F.relu does of the output
        # it saw: output elements within rounding of zero (TF32 or bf16 against the fp32 reference) would
        # otherwise flip the mask and charge whole gradient terms to the kernel. y itself is checked below.
        positive = (y.detach() > 0).float().permute(1, 0, 4, 2, 3).reshape(b, k * cout, out, out)
        dy_ref = dy_ref * positive
    dx_ref, dw_ref, db_ref = torch.autograd.grad(y_ref, (x_ref, w_ref, b_ref), dy_ref)
    if relu:
        y_ref = F.relu(y_ref)
    want = (y_ref.reshape(b, k, cout, out, out).permute(1, 0, 3, 4, 2),
            dx_ref.reshape(b, k, cin, side, side).permute(1, 0, 3, 4, 2), dw_ref, db_ref)

    failures = 0
    for quantity, g, r in zip(("y", "dx", "dw", "db"), got, want):
        error = relative_error(g, r)
        ok = error <= tolerance and g.dtype == (dtype if quantity in ("y", "dx") else torch.float32)
        failures += not ok
        print(f"K = {k}, B = {b}, {str(dtype)[6:]}, {name}{' + ReLU' if relu else ''} {quantity}: max relative error {error:.2e} "
              f"(tolerance {tolerance:.0e}, {str(g.dtype)[6:]}) {'PASS' if ok else 'FAIL'}", flush=True)
    return failures


def check_conv1_frames(k: int, b: int, dtype: torch.dtype, tolerance: float) -> int:
    """conv1 + ReLU from uint8 frames where a [T = 2, K, B] rollout buffer holds them, at shuffled minibatch
    indices (packed_conv_frames), against F.conv2d(groups=K) in fp32 on the gathered frames / 255 rounded to
    `dtype` (as the trainer's other paths convert them); prints one line per quantity, returns the failures."""
    torch.manual_seed(1)
    buffer = torch.randint(0, 256, (2, k, b, 128, 128, 3), dtype=torch.uint8, device="cuda")
    batch = torch.stack([torch.randperm(2 * b, device="cuda")[:b] for _ in range(k)])  # each run's minibatch
    runs = torch.arange(k, device="cuda")[:, None]
    images = (batch // b * k + runs) * b + batch % b
    conv = torch.nn.Conv2d(k * 3, k * 32, 8, 4, groups=k, device="cuda")
    weight, bias = conv.weight.detach().requires_grad_(), conv.bias.detach().uniform_(-0.5, 0.5).requires_grad_()
    y = tc.packed_conv_frames(buffer, images, weight, bias, 4, dtype, relu=True)
    dy = torch.randn_like(y)
    got = (y,) + torch.autograd.grad(y, (weight, bias), dy)

    frames = buffer.transpose(0, 1).reshape(k, 2 * b, 128, 128, 3)[runs, batch]
    x_ref = frames.to(dtype).div_(255.0).float().permute(1, 0, 4, 2, 3).reshape(b, k * 3, 128, 128)
    w_ref = weight.detach().to(dtype).float().requires_grad_()
    b_ref = bias.detach().clone().requires_grad_()
    y_ref = F.conv2d(x_ref, w_ref, b_ref, stride=4, groups=k)
    positive = (y.detach() > 0).float().permute(1, 0, 4, 2, 3).reshape(y_ref.shape)  # as in check_layer
    dw_ref, db_ref = torch.autograd.grad(y_ref, (w_ref, b_ref), dy.float().permute(1, 0, 4, 2, 3).reshape(
        y_ref.shape) * positive)
    want = (F.relu(y_ref).reshape(b, k, 32, 31, 31).permute(1, 0, 3, 4, 2), dw_ref, db_ref)
    failures = 0
    for quantity, g, r in zip(("y", "dw", "db"), got, want):
        error = relative_error(g, r)
        ok = error <= tolerance and g.dtype == (dtype if quantity == "y" else torch.float32)
        failures += not ok
        print(f"K = {k}, B = {b}, {str(dtype)[6:]}, conv1 + ReLU from frames {quantity}: max relative error "
              f"{error:.2e} (tolerance {tolerance:.0e}, {str(g.dtype)[6:]}) {'PASS' if ok else 'FAIL'}", flush=True)
    return failures


def torso_steps(k: int, b: int):
    """Forward + backward (a sum loss) of K NatureCNN torsos on B frames each under bf16 autocast with fp32
    weights: the Triton kernels as --triton-conv runs them (conv1 on the uint8 frames), and cuDNN's grouped
    convolutions in channels-last on the 4 x 4 space-to-depth frames (--fused-input), as the trainer runs them
    with all speed flags but --triton-conv."""
    convs = [torch.nn.Conv2d(k * cin, k * cout, ksize, stride, groups=k, device="cuda")
             for _, _, cin, cout, ksize, stride in LAYERS]
    frames = torch.randint(0, 256, (k, b, 128, 128, 3), dtype=torch.uint8, device="cuda")
    images = torch.arange(k * b, device="cuda").view(k, b)
    cl_convs = [torch.nn.Conv2d(c.in_channels, c.out_channels, c.kernel_size, c.stride, groups=k, device="cuda")
                .to(memory_format=torch.channels_last) for c in convs]
    cl_frames = torch.rand(b, k * 48, 32, 32, device="cuda").to(torch.bfloat16).contiguous(
        memory_format=torch.channels_last)

    def triton_step():
        with torch.autocast("cuda", dtype=torch.bfloat16):
            x = tc.packed_conv_frames(frames, images, convs[0].weight, convs[0].bias, 4, torch.bfloat16, relu=True)
            x = tc.packed_conv(x, convs[1].weight, convs[1].bias, 2, relu=True)
            x = tc.packed_conv(x, convs[2].weight, convs[2].bias, relu=True)
            loss = x.sum()
        for c in convs:
            c.zero_grad(set_to_none=True)
        loss.backward()

    def cudnn_step():
        with torch.autocast("cuda", dtype=torch.bfloat16):
            w1 = s2d.weight_space_to_depth(cl_convs[0].weight, 4).contiguous(memory_format=torch.channels_last)
            x = F.relu(F.conv2d(cl_frames, w1, cl_convs[0].bias, groups=k))
            x = F.relu(cl_convs[1](x))
            x = F.relu(cl_convs[2](x))
            loss = x.sum()
        for c in cl_convs:
            c.zero_grad(set_to_none=True)
        loss.backward()

    return triton_step, cudnn_step


def torso_flop(b: int, k: int) -> float:
    """Multiply-adds x 2 of the forward pass, the weight gradients and the input gradients of conv2 and conv3."""
    total = 0.0
    for i, (_, side, cin, cout, ksize, stride) in enumerate(LAYERS):
        out = (side - ksize) // stride + 1
        gemm = 2.0 * k * b * out * out * cout * cin * ksize * ksize
        total += gemm * (3 if i else 2)
    return total


def print_profile(name: str, step) -> None:
    from torch.profiler import ProfilerActivity, profile
    with profile(activities=[ProfilerActivity.CUDA]) as prof:
        step()
        torch.cuda.synchronize()
    print(name)
    print(prof.key_averages().table(sort_by="cuda_time_total", row_limit=12, max_name_column_width=70))


def full_fp32_references() -> None:
    torch.backends.cudnn.benchmark = True
    torch.backends.cudnn.allow_tf32 = False  # the fp32 references in full fp32
    torch.backends.cuda.matmul.allow_tf32 = False


@pytest.mark.parametrize("relu", [False, True], ids=["conv", "conv_relu"])
@pytest.mark.parametrize("k, b", [(3, 64), (8, 2048)])
@pytest.mark.parametrize("dtype, tolerance", [(torch.float32, 1e-3), (torch.bfloat16, 2e-2)])
@pytest.mark.parametrize("layer", LAYERS, ids=[layer[0] for layer in LAYERS])
def test_packed_conv_equals_grouped_conv(k, b, dtype, tolerance, layer, relu):
    full_fp32_references()
    assert check_layer(k, b, layer, dtype, tolerance, relu) == 0
    torch.cuda.empty_cache()


@pytest.mark.parametrize("k, b", [(3, 64), (8, 2048)])
@pytest.mark.parametrize("dtype, tolerance", [(torch.float32, 1e-3), (torch.bfloat16, 2e-2)])
def test_conv1_from_frames_equals_grouped_conv(k, b, dtype, tolerance):
    full_fp32_references()
    assert check_conv1_frames(k, b, dtype, tolerance) == 0
    torch.cuda.empty_cache()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--profile", action="store_true", help="print the top CUDA kernels of one torso step of each")
    a = p.parse_args()
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "lab" / "tools"))
    from cuda_timing import median_ms  # the lab notebook's timer

    full_fp32_references()
    print(f"{torch.cuda.get_device_name()}, torch {torch.__version__}, triton {triton.__version__}", flush=True)
    failures = 0
    for k, b in ((3, 64), (8, 2048)):
        for dtype, tolerance in ((torch.float32, 1e-3), (torch.bfloat16, 2e-2)):
            for layer in LAYERS:
                for relu in (False, True):
                    failures += check_layer(k, b, layer, dtype, tolerance, relu)
                    torch.cuda.empty_cache()
            failures += check_conv1_frames(k, b, dtype, tolerance)

    k, b = 8, 2048
    triton_step, cudnn_step = torso_steps(k, b)
    triton_ms, cudnn_ms = median_ms(triton_step), median_ms(cudnn_step)
    print(f"torso forward + backward, K = {k}, B = {b}, bf16 (median of 5 after 3 warm-ups): "
          f"triton {triton_ms:.2f} ms ({torso_flop(b, k) / triton_ms / 1e9:.0f} TFLOP/s), "
          f"cuDNN channels-last {cudnn_ms:.2f} ms ({torso_flop(b, k) / cudnn_ms / 1e9:.0f} TFLOP/s), "
          f"cuDNN / triton {cudnn_ms / triton_ms:.2f}")
    print(f"autotuned configs at K = {k}, B = {b}, bf16 (key: B, H, W, Cin, Cout, kh, kw, ReLU, dtypes):")
    for name, kernel in (("forward", tc.forward_kernel), ("dgrad", tc.dgrad_kernel), ("wgrad", tc.wgrad_kernel)):
        for key, config in getattr(kernel, "cache", {}).items():
            if key[0] == b and "bfloat16" in str(key):
                print(f"  {name} {key[1:8]}: {config}")
    if a.profile:
        print_profile("triton", triton_step)
        print_profile("cuDNN channels-last", cudnn_step)
    print("all checks PASS" if failures == 0 else f"{failures} checks FAIL")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
