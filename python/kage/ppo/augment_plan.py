"""One pass over uint8 frames that applies per-frame image transforms (kage.ppo.augment's standard set): a
plan holds each frame's parameters, and `apply` runs it as one Triton kernel on the GPU
(kage.ppo.fast.augment_kernel: uint8 in and out, the minibatch's gather from the rollout buffer in the same
pass) or as the torch reference below, which defines what the kernel computes.

For output element (y, x, c) of frame f, c = 3 g + j (g: the frame of a stack, j: its colour channel), the
stages run in this order, each where the plan sets it:
1. remap: the source pixel is (clamp(oy + y * wy // H), clamp(ox + x * wx // W)): a shift (wy = H, wx = W)
   or a crop of a wy x wx window resized back by nearest neighbour; the frame's border repeats.
2. conv: sum over i, dy, dx in {-1, 0, 1} of w[j, i, dy, dx] * v[i] at the remapped position of
   (y + dy, x + dx), zero outside the frame; else v[j] at the remapped position.
3. colour: sum over i of m[j, i] * v[i] + o[j] (an affine colour map, in pixel units 0..255).
4. noise: + sigma * z, z a standard normal made by Box-Muller from two uniforms that are a hash of the frame's
   two keys and the element's index (kage.ppo.counter_random's mix32), so each pixel's draw needs no stream.
5. overlay: (1 - alpha) v + alpha * image[index][y, x, j] from a stack of images of the frame's size.
6. cutout: inside the box y0 <= y < y1, x0 <= x < x1, the box's colour.
Then floor(v + 0.5) clamped to [0, 255]. With the remap alone every value is copied exactly.
"""
import dataclasses
from typing import Optional

import torch

from kage.ppo.counter_random import mix32

# The per-frame parameter row: each stage's slice (start, width) of one float32 row.
SLOTS = {"remap": (0, 4), "colour": (4, 12), "noise": (16, 3), "overlay": (19, 2), "cutout": (21, 7),
         "conv": (28, 81)}
ROW = 112
LUMA = (0.299, 0.587, 0.114)  # ITU-R 601, torchvision's grayscale weights


@dataclasses.dataclass
class Plan:
    """Each frame's parameters for the stages it uses, [F, width] float32 each (F = K * B frames in [K, B]
    order), None for a stage that is off; `images`: the overlay's uint8 [M, H, W, 3] stack."""
    remap: Optional[torch.Tensor] = None    # oy, ox, wy, wx (integers)
    conv: Optional[torch.Tensor] = None     # w[j, i, dy + 1, dx + 1], row-major
    colour: Optional[torch.Tensor] = None   # m[j, i] row-major, then o[j]
    noise: Optional[torch.Tensor] = None    # sigma, key1, key2 (keys: integers below 2**24)
    overlay: Optional[torch.Tensor] = None  # image index, alpha
    cutout: Optional[torch.Tensor] = None   # y0, x0, y1, x1, r, g, b
    images: Optional[torch.Tensor] = None

    def stages(self):
        return {name: getattr(self, name) for name in SLOTS if getattr(self, name) is not None}

    def rows(self, frames: int, device) -> torch.Tensor:
        """The [F, ROW] float32 parameter rows the kernel reads."""
        rows = torch.zeros((frames, ROW), dtype=torch.float32, device=device)
        for name, value in self.stages().items():
            start, width = SLOTS[name]
            rows[:, start:start + width] = value.reshape(frames, width)
        return rows


def apply(frames: torch.Tensor, plan: Plan, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """uint8 frames [K, B, H, W, C] (or, with int64 images [K, B], run k's b-th frame is
    frames.reshape(-1, H, W, C)[images[k, b]], a minibatch read where the rollout stored it) -> the planned
    frames, uint8 [K, B, H, W, C]. C is a multiple of 3 (a stack of frames shares its frame's parameters)."""
    if frames.shape[-1] % 3:
        raise ValueError(f"kage.ppo.augment: frames of {frames.shape[-1]} channels; the colour stages need RGB "
                         "frames (3 channels, or a stack of them)")
    if frames.is_cuda and _kernel_available():
        from kage.ppo.fast import augment_kernel
        count = images.numel() if images is not None else frames.shape[0] * frames.shape[1]
        return augment_kernel.apply(frames, plan.rows(count, frames.device), set(plan.stages()), SLOTS, plan.images,
                                    images)
    return reference(frames, plan, images)


def _kernel_available() -> bool:
    try:
        import triton  # noqa: F401
    except ImportError:
        return False
    return True


def gray_means(frames: torch.Tensor, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """Each frame's mean luma (LUMA) over its pixels and stacked frames, [K, B] float32: the contrast's pivot."""
    if frames.is_cuda and _kernel_available():
        from kage.ppo.fast import augment_kernel
        return augment_kernel.gray_means(frames, images)
    x = frames if images is None else frames.reshape(-1, *frames.shape[-3:])[images]
    k, b, h, w, c = x.shape
    luma = torch.tensor(LUMA, dtype=torch.float32, device=x.device)
    return (x.reshape(k, b, h * w * c // 3, 3).float() @ luma).mean(-1)


def normal_hash(key1: torch.Tensor, key2: torch.Tensor, index: torch.Tensor) -> torch.Tensor:
    """A standard normal for each element index of a frame with keys (key1, key2): Box-Muller over the
    uniforms of two 32-bit hashes (24 bits each, centred in their interval), as the kernel computes it."""
    def uniform(i):
        bits = mix32(mix32(i ^ key1) ^ key2)
        return ((bits >> 8).float() + 0.5) * (1.0 / (1 << 24))
    u1, u2 = uniform(2 * index), uniform(2 * index + 1)
    return torch.sqrt(-2.0 * torch.log(u1)) * torch.cos(6.283185307179586 * u2)


def reference(frames: torch.Tensor, plan: Plan, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """`apply` in torch (the definition the kernel follows; the CPU's path)."""
    x = frames if images is None else frames.reshape(-1, *frames.shape[-3:])[images]
    k, b, h, w, c = x.shape
    f = k * b
    x = x.reshape(f, h, w, c)
    device = x.device
    ys = torch.arange(h, device=device)
    xs = torch.arange(w, device=device)

    def source(dy: int, dx: int):
        """Each frame's source rows [F, H] and columns [F, W] of output position (y + dy, x + dx), and whether
        that position lies in the frame."""
        py, px = ys + dy, xs + dx
        inside = ((py >= 0) & (py < h))[None, :, None] & ((px >= 0) & (px < w))[None, None, :]
        if plan.remap is None:
            rows, cols = py.clamp(0, h - 1).expand(f, h), px.clamp(0, w - 1).expand(f, w)
        else:
            oy, ox, wy, wx = plan.remap.reshape(f, 4).long().unbind(1)
            rows = (oy[:, None] + py.clamp(0, h - 1)[None] * wy[:, None] // h).clamp(0, h - 1)
            cols = (ox[:, None] + px.clamp(0, w - 1)[None] * wx[:, None] // w).clamp(0, w - 1)
        frame = torch.arange(f, device=device)[:, None, None]
        return x[frame, rows[:, :, None], cols[:, None, :]].float(), inside.expand(f, h, w)

    g = c // 3
    if plan.conv is None:
        v = source(0, 0)[0].reshape(f, h, w, g, 3)
    else:
        weights = plan.conv.reshape(f, 3, 3, 3, 3)  # [F, j, i, dy, dx]
        v = torch.zeros((f, h, w, g, 3), device=device)
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                pixels, inside = source(dy, dx)
                pixels = pixels.reshape(f, h, w, g, 3) * inside[..., None, None]
                for i in range(3):
                    v = v + weights[:, None, None, None, :, i, dy + 1, dx + 1] * pixels[..., i:i + 1]
    if plan.colour is not None:
        m = plan.colour.reshape(f, 12)
        matrix, offset = m[:, :9].reshape(f, 3, 3), m[:, 9:]
        v = sum(matrix[:, None, None, None, :, i] * v[..., i:i + 1] for i in range(3)) \
            + offset[:, None, None, None, :]
    if plan.noise is not None:
        sigma, key1, key2 = plan.noise.reshape(f, 3).unbind(1)
        index = torch.arange(h * w * c, device=device, dtype=torch.int64).view(1, h, w, g, 3)
        z = normal_hash(key1.long()[:, None, None, None, None], key2.long()[:, None, None, None, None], index)
        v = v + sigma[:, None, None, None, None] * z
    if plan.overlay is not None:
        index, alpha = plan.overlay.reshape(f, 2).unbind(1)
        picture = plan.images[index.long()].float()[:, :, :, None, :]  # [F, H, W, 1, 3]
        a = alpha[:, None, None, None, None]
        v = (1.0 - a) * v + a * picture
    if plan.cutout is not None:
        box = plan.cutout.reshape(f, 7)
        y0, x0, y1, x1 = (box[:, i, None, None] for i in range(4))
        inside = (ys[None, :, None] >= y0) & (ys[None, :, None] < y1) & (xs[None, None, :] >= x0) & \
            (xs[None, None, :] < x1)
        v = torch.where(inside[..., None, None], box[:, None, None, None, 4:7], v)
    return torch.floor(v + 0.5).clamp(0, 255).to(torch.uint8).reshape(k, b, h, w, c)
