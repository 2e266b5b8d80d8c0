"""The augmentation pass (kage.ppo.fast.augment_kernel.apply) of this tree against another version of the module,
on the device: for each plan of the standard augmentations' stages, both versions run on the same minibatch
(K runs x 2048 frames of 128 x 128 x 3, read at random indices of a rollout buffer of 16,384 frames a run, as the
update's minibatches are), the bytes that differ are counted, and each version is timed with CUDA events (median
of 20 launches after 3). usage: python3 kernel_speed.py OTHER_MODULE.py K [K ...]"""
import importlib.util
import os
import sys

import torch

from kage.ppo import augment_plan
from kage.ppo.augment_plan import Plan
from kage.ppo.fast import augment_kernel

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from cuda_timing import median_ms  # noqa: E402  (lab/tools, the device scripts' timing)


def load(path: str):
    spec = importlib.util.spec_from_file_location("augment_kernel_other", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def plan_of(stages, count, device):
    g = torch.Generator(device="cpu").manual_seed(1)
    plan = Plan()
    if "remap" in stages:  # a shift of up to 4 pixels
        shift = torch.randint(-4, 5, (count, 2), generator=g)
        plan.remap = torch.cat([shift, torch.full((count, 2), 128)], 1).float()
    if "conv" in stages:
        plan.conv = torch.randn((count, 81), generator=g) * (2 / 54) ** 0.5
    if "colour" in stages:
        plan.colour = torch.cat([torch.randn((count, 9), generator=g) * 0.2 + torch.eye(3).reshape(9),
                                 torch.rand((count, 3), generator=g) * 40 - 20], 1)
    if "noise" in stages:
        keys = torch.floor(torch.rand((count, 2), generator=g) * (1 << 24))
        plan.noise = torch.cat([torch.full((count, 1), 8.0), keys], 1)
    if "overlay" in stages:
        plan.overlay = torch.stack([torch.randint(0, 4, (count,), generator=g).float(),
                                    torch.rand((count,), generator=g) * 0.5], 1)
        plan.images = torch.randint(0, 256, (4, 128, 128, 3), dtype=torch.uint8, generator=g).to(device)
    if "cutout" in stages:
        origin = torch.randint(0, 100, (count, 2), generator=g)
        plan.cutout = torch.cat([origin, origin + 20, torch.randint(0, 256, (count, 3), generator=g)], 1).float()
    return plan


def main():
    other = load(sys.argv[1])
    device = torch.device("cuda")
    print(f"device: {torch.cuda.get_device_name()}, torch {torch.__version__}")
    print("| K | stages | frames | other ms | this ms | speed-up | bytes differing |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for k in map(int, sys.argv[2:]):
        buffer = torch.randint(0, 256, (k * 16384, 128, 128, 3), dtype=torch.uint8, device=device)
        images = (torch.randint(0, 16384, (k, 2048), device=device) + 16384 * torch.arange(k, device=device)[:, None])
        for stages in (["conv"], ["colour"], ["noise"], ["overlay"], ["remap"], ["cutout"],
                       ["remap", "conv", "colour"]):
            plan = plan_of(stages, images.numel(), device)
            rows = plan.rows(images.numel(), device).to(device)
            run = lambda module: module.apply(buffer, rows, set(plan.stages()), augment_plan.SLOTS,  # noqa: E731
                                              plan.images, images)
            differing = int((run(other) != run(augment_kernel)).sum())
            before = median_ms(lambda: run(other), repeats=20)
            after = median_ms(lambda: run(augment_kernel), repeats=20)
            print(f"| {k} | {'+'.join(stages)} | {images.numel()} | {before:.2f} | {after:.2f} | "
                  f"{before / after:.2f} | {differing} |", flush=True)
        del buffer


if __name__ == "__main__":
    main()
