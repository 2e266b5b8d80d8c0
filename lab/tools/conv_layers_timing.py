"""Per layer and pass, the milliseconds of kage.ppo.fast.triton_conv's kernels for K packed runs on a
minibatch of B frames each, in bf16, the ReLU fused as the trainer runs them (conv1 on the uint8 4 x 4 blocks
gathered from shuffled indices of a rollout buffer twice the minibatch, the gather timed too), with the TFLOP/s each reaches and the config the
autotuner chose; beside them cuDNN's grouped channels-last convolution of the same shapes (conv1 on the 4 x 4
space-to-depth frames, as --fused-input runs it). Finds which kernel bounds the update before a full
`kage.bench speed` run.

usage: python3 lab/tools/conv_layers_timing.py [--packs 16] [--minibatch 2048] [--cudnn]
"""
import argparse

import torch
import torch.nn.functional as F

from cuda_timing import median_ms

# (name, input side, in channels, out channels, kernel, stride), NatureCNN on 128 x 128 x 3 frames.
LAYERS = [("conv1", 128, 3, 32, 8, 4), ("conv2", 31, 32, 64, 4, 2), ("conv3", 14, 64, 64, 3, 1)]


def best(kernel) -> str:
    config = getattr(kernel, "best_config", None)
    return "" if config is None else " ".join(f"{k}={v}" for k, v in config.all_kwargs().items())


def time_triton(tc, k: int, b: int) -> None:
    dtype = torch.bfloat16
    frames = torch.randint(0, 256, (2 * k * b, 128, 128, 3), dtype=torch.uint8, device="cuda")
    images = torch.randperm(2 * k * b, device="cuda")[:k * b].view(k, b)
    blocks_ms = median_ms(lambda: tc.frames_to_blocks(frames, images, 4))
    print(f"| conv1 | frames to blocks (gather) | {blocks_ms:.2f} | | |", flush=True)
    blocks = tc.frames_to_blocks(frames, images, 4)
    del frames
    # conv1 as the kernels run it: 2 x 2, stride 1 over the 48-byte blocks.
    for name, side, cin, cout, ks, stride in [("conv1", 32, 48, 32, 2, 1)] + LAYERS[1:]:
        out = (side - ks) // stride + 1
        flops = 2 * k * b * out * out * ks * ks * cin * cout
        w = (torch.randn(k, ks, ks, cin, cout, device="cuda") * 0.05).to(dtype)
        bias = torch.randn(k * cout, device="cuda")
        x = blocks if name == "conv1" else torch.randn(k, b, side, side, cin, device="cuda").to(dtype)
        y = tc._forward(x, w, bias, stride, True)
        dy = torch.randn_like(y)
        passes = [("forward", lambda: tc._forward(x, w, bias, stride, True), tc.forward_kernel),
                  ("wgrad", lambda: tc._wgrad(x, dy, y, ks, ks, stride, True), tc.wgrad_kernel)]
        if name != "conv1":
            passes.append(("dgrad", lambda: tc._dgrad(dy, y, w, side, side, stride, True), tc.dgrad_kernel))
        for pass_name, step, kernel in passes:
            ms = median_ms(step)
            print(f"| {name} | {pass_name} | {ms:.2f} | {flops / ms / 1e9:.0f} | {best(kernel)} |", flush=True)
        del x, y, dy
        torch.cuda.empty_cache()


def time_cudnn(k: int, b: int) -> None:
    for name, side, cin, cout, ks, stride in LAYERS:
        out = (side - ks) // stride + 1
        flops = 2 * k * b * out * out * ks * ks * cin * cout
        if name == "conv1":  # as --fused-input runs it: 2 x 2, stride 1 on 48-channel 4 x 4 blocks
            side, cin, ks, stride = 32, 48, 2, 1
        x = torch.randn(b, k * cin, side, side, device="cuda", dtype=torch.bfloat16).contiguous(
            memory_format=torch.channels_last).requires_grad_(name != "conv1")
        w = torch.randn(k * cout, cin, ks, ks, device="cuda", dtype=torch.bfloat16).contiguous(
            memory_format=torch.channels_last).requires_grad_()
        y = F.relu(F.conv2d(x, w, stride=stride, groups=k))
        dy = torch.randn_like(y)
        forward_ms = median_ms(lambda: F.relu(F.conv2d(x, w, stride=stride, groups=k)))
        backward_ms = median_ms(lambda: torch.autograd.grad(y, [w] + ([x] if x.requires_grad else []), dy,
                                                            retain_graph=True))
        print(f"| {name} | cuDNN forward | {forward_ms:.2f} | {flops / forward_ms / 1e9:.0f} | |")
        print(f"| {name} | cuDNN backward (wgrad + dgrad) | {backward_ms:.2f} | | |", flush=True)
        del x, w, y, dy
        torch.cuda.empty_cache()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--packs", type=int, default=16)
    p.add_argument("--minibatch", type=int, default=2048)
    p.add_argument("--cudnn", action="store_true", help="also time cuDNN's grouped convolutions")
    a = p.parse_args()
    torch.backends.cudnn.benchmark = True
    print(f"{torch.cuda.get_device_name()}, torch {torch.__version__}, K = {a.packs}, minibatch {a.minibatch}, bf16")
    from kage.ppo.fast import triton_conv
    print("\nkage.ppo.fast.triton_conv\n| layer | pass | ms | TFLOP/s | config |\n|---|---|---|---|---|")
    time_triton(triton_conv, a.packs, a.minibatch)
    if a.cudnn:
        print("\ncuDNN\n| layer | pass | ms | TFLOP/s | config |\n|---|---|---|---|---|")
        time_cudnn(a.packs, a.minibatch)


if __name__ == "__main__":
    main()
