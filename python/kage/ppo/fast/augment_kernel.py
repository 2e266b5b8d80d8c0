"""kage.ppo.augment_plan's pass as Triton kernels: one program per frame and block of its pixels, uint8 in
and out, the frame read where it lies (the rollout buffer, at a minibatch's indices) so that the gather and
the augmentation are one pass. The stages are constexpr switches: a plan compiles to a kernel with only its
own stages. kage.ppo.augment_plan.reference is the definition, and augment_plan.apply calls these with a
plan's parameter rows (this module imports nothing of it); tests/python/test_augment_kernel.py checks the kernels
against it under Triton's interpreter, tests/gpu/test_augment_gpu.py on the GPU.
"""
from typing import Dict, Optional, Set, Tuple

import torch
import triton
import triton.language as tl

BLOCK = 1024
GRAY_BLOCK = 1024


@triton.jit
def _mix32(x):
    """kage.ppo.counter_random.mix32 on uint32 values: its products modulo 2**32 are uint32 products, which the GPU
    multiplies natively (int64 products are emulated)."""
    x = ((x >> 16) ^ x) * 0x45D9F3B
    x = ((x >> 16) ^ x) * 0x45D9F3B
    return (x >> 16) ^ x


@triton.jit
def _uniform(index, key1, key2):
    bits = _mix32(_mix32(index ^ key1) ^ key2)
    return ((bits >> 8).to(tl.float32) + 0.5) * (1.0 / 16777216.0)


@triton.jit
def _source(y, x, row, H: tl.constexpr, W: tl.constexpr, REMAP: tl.constexpr):
    """The source pixel of output position (y, x) (already inside the frame): remapped, or itself."""
    if REMAP:
        oy = tl.load(row + 0).to(tl.int32)
        ox = tl.load(row + 1).to(tl.int32)
        wy = tl.load(row + 2).to(tl.int32)
        wx = tl.load(row + 3).to(tl.int32)
        sy = tl.minimum(tl.maximum(oy + y * wy // H, 0), H - 1)
        sx = tl.minimum(tl.maximum(ox + x * wx // W, 0), W - 1)
        return sy, sx
    return y, x


@triton.jit
def _finish(v, j, e, y, x, row, pictures_ptr, out, ok, H: tl.constexpr, W: tl.constexpr, NOISE: tl.constexpr,
            OVERLAY: tl.constexpr, CUTOUT: tl.constexpr, NOISE_AT: tl.constexpr, OVERLAY_AT: tl.constexpr,
            CUTOUT_AT: tl.constexpr):
    """The per-channel stages of colour channel j (element indices e) from noise on, then the rounding and the
    store."""
    if NOISE:
        sigma = tl.load(row + NOISE_AT)
        key1 = tl.load(row + NOISE_AT + 1).to(tl.uint32)
        key2 = tl.load(row + NOISE_AT + 2).to(tl.uint32)
        index = e.to(tl.uint32)
        u1 = _uniform(2 * index, key1, key2)
        u2 = _uniform(2 * index + 1, key1, key2)
        v += sigma * (tl.sqrt(-2.0 * tl.log(u1)) * tl.cos(6.283185307179586 * u2))
    if OVERLAY:
        picture = tl.load(row + OVERLAY_AT).to(tl.int64)
        alpha = tl.load(row + OVERLAY_AT + 1)
        p = tl.load(pictures_ptr + ((picture * H + y) * W + x) * 3 + j, mask=ok, other=0).to(tl.float32)
        v = (1.0 - alpha) * v + alpha * p
    if CUTOUT:
        box = row + CUTOUT_AT
        inside_box = (y >= tl.load(box + 0)) & (y < tl.load(box + 2)) & (x >= tl.load(box + 1)) & \
            (x < tl.load(box + 3))
        v = tl.where(inside_box, tl.load(box + 4 + j), v)
    v = tl.minimum(tl.maximum(tl.floor(v + 0.5), 0.0), 255.0)
    tl.store(out + e, v.to(tl.uint8), mask=ok)


@triton.jit
def plan_kernel(frames_ptr, images_ptr, rows_ptr, pictures_ptr, out_ptr,
                H: tl.constexpr, W: tl.constexpr, C: tl.constexpr, ROW_WIDTH: tl.constexpr,
                GATHER: tl.constexpr, REMAP: tl.constexpr, CONV: tl.constexpr, COLOUR: tl.constexpr,
                NOISE: tl.constexpr, OVERLAY: tl.constexpr, CUTOUT: tl.constexpr,
                CONV_AT: tl.constexpr, COLOUR_AT: tl.constexpr, NOISE_AT: tl.constexpr, OVERLAY_AT: tl.constexpr,
                CUTOUT_AT: tl.constexpr, BLOCK_T: tl.constexpr):
    """out[f] = the plan's stages on frame f (images[f] of the frames under GATHER). Each program works on one
    block of one frame's pixel triplets t = (y, x, g), the three colour channels of pixel (y, x) of the stack's
    frame g, elements 3 t + j in row-major order: the convolution and the colour map need all three channels of a
    pixel, so a triplet computes them once for its three outputs."""
    f = tl.program_id(0).to(tl.int64)
    t = tl.program_id(1) * BLOCK_T + tl.arange(0, BLOCK_T)
    ok = t < H * W * (C // 3)
    pixel = t // (C // 3)
    group = t % (C // 3) * 3
    y = pixel // W
    x = pixel % W
    if GATHER:
        source_frame = tl.load(images_ptr + f).to(tl.int64)
    else:
        source_frame = f
    base = frames_ptr + source_frame * (H * W * C)
    row = rows_ptr + f * ROW_WIDTH
    v0 = tl.zeros([BLOCK_T], dtype=tl.float32)
    v1 = tl.zeros([BLOCK_T], dtype=tl.float32)
    v2 = tl.zeros([BLOCK_T], dtype=tl.float32)
    if CONV:
        for dy in tl.static_range(3):
            for dx in tl.static_range(3):
                py = y + (dy - 1)
                px = x + (dx - 1)
                inside = ok & (py >= 0) & (py < H) & (px >= 0) & (px < W)
                sy, sx = _source(tl.minimum(tl.maximum(py, 0), H - 1), tl.minimum(tl.maximum(px, 0), W - 1), row,
                                 H, W, REMAP)
                at = base + (sy * W + sx) * C + group
                for i in tl.static_range(3):
                    p = tl.load(at + i, mask=inside, other=0).to(tl.float32)
                    v0 += tl.load(row + CONV_AT + 0 * 27 + i * 9 + dy * 3 + dx) * p
                    v1 += tl.load(row + CONV_AT + 1 * 27 + i * 9 + dy * 3 + dx) * p
                    v2 += tl.load(row + CONV_AT + 2 * 27 + i * 9 + dy * 3 + dx) * p
    else:
        sy, sx = _source(y, x, row, H, W, REMAP)
        at = base + (sy * W + sx) * C + group
        v0 = tl.load(at + 0, mask=ok, other=0).to(tl.float32)
        v1 = tl.load(at + 1, mask=ok, other=0).to(tl.float32)
        v2 = tl.load(at + 2, mask=ok, other=0).to(tl.float32)
    if COLOUR:
        m = row + COLOUR_AT
        r0 = tl.load(m + 0) * v0 + tl.load(m + 1) * v1 + tl.load(m + 2) * v2 + tl.load(m + 9)
        r1 = tl.load(m + 3) * v0 + tl.load(m + 4) * v1 + tl.load(m + 5) * v2 + tl.load(m + 10)
        r2 = tl.load(m + 6) * v0 + tl.load(m + 7) * v1 + tl.load(m + 8) * v2 + tl.load(m + 11)
        v0, v1, v2 = r0, r1, r2
    out = out_ptr + f * (H * W * C)
    e = t * 3
    _finish(v0, 0, e, y, x, row, pictures_ptr, out, ok, H, W, NOISE, OVERLAY, CUTOUT, NOISE_AT, OVERLAY_AT, CUTOUT_AT)
    _finish(v1, 1, e + 1, y, x, row, pictures_ptr, out, ok, H, W, NOISE, OVERLAY, CUTOUT, NOISE_AT, OVERLAY_AT,
            CUTOUT_AT)
    _finish(v2, 2, e + 2, y, x, row, pictures_ptr, out, ok, H, W, NOISE, OVERLAY, CUTOUT, NOISE_AT, OVERLAY_AT,
            CUTOUT_AT)


@triton.jit
def gray_kernel(frames_ptr, images_ptr, out_ptr, PIXELS: tl.constexpr, GATHER: tl.constexpr,
                BLOCK_P: tl.constexpr):
    """out[f] = the mean luma of frame f's PIXELS pixels (a stack's frames included)."""
    f = tl.program_id(0).to(tl.int64)
    if GATHER:
        source_frame = tl.load(images_ptr + f).to(tl.int64)
    else:
        source_frame = f
    base = frames_ptr + source_frame * (PIXELS * 3)
    total = tl.zeros([BLOCK_P], dtype=tl.float32)
    for start in range(0, PIXELS, BLOCK_P):
        p = start + tl.arange(0, BLOCK_P)
        ok = p < PIXELS
        r = tl.load(base + p * 3, mask=ok, other=0).to(tl.float32)
        g = tl.load(base + p * 3 + 1, mask=ok, other=0).to(tl.float32)
        b = tl.load(base + p * 3 + 2, mask=ok, other=0).to(tl.float32)
        total += 0.299 * r + 0.587 * g + 0.114 * b
    tl.store(out_ptr + f, tl.sum(total, axis=0) / PIXELS)


def _frames_and_count(frames: torch.Tensor, images: Optional[torch.Tensor]):
    if not frames.is_contiguous():
        frames = frames.contiguous()
    k, b = (images if images is not None else frames).shape[:2]
    return frames, k, b


def apply(frames: torch.Tensor, rows: torch.Tensor, stages: Set[str], slots: Dict[str, Tuple[int, int]],
          pictures: Optional[torch.Tensor], images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """kage.ppo.augment_plan.apply on the GPU: `rows` [F, width] float32 the frames' parameters, `stages` the
    plan's stages, `slots` each stage's (start, width) in a row, `pictures` the overlay's images."""
    frames, k, b = _frames_and_count(frames, images)
    h, w, c = frames.shape[-3:]
    count = k * b
    out = torch.empty((k, b, h, w, c), dtype=torch.uint8, device=frames.device)
    if count:
        plan_kernel[(count, triton.cdiv(h * w * c // 3, BLOCK))](
            frames, images.contiguous() if images is not None else rows, rows,
            pictures if pictures is not None else rows, out,
            H=h, W=w, C=c, ROW_WIDTH=rows.shape[1], GATHER=images is not None,
            REMAP="remap" in stages, CONV="conv" in stages, COLOUR="colour" in stages, NOISE="noise" in stages,
            OVERLAY="overlay" in stages, CUTOUT="cutout" in stages,
            CONV_AT=slots["conv"][0], COLOUR_AT=slots["colour"][0], NOISE_AT=slots["noise"][0],
            OVERLAY_AT=slots["overlay"][0], CUTOUT_AT=slots["cutout"][0], BLOCK_T=BLOCK, num_warps=4)
    return out


def gray_means(frames: torch.Tensor, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """kage.ppo.augment_plan.gray_means on the GPU."""
    frames, k, b = _frames_and_count(frames, images)
    h, w, c = frames.shape[-3:]
    out = torch.empty((k, b), dtype=torch.float32, device=frames.device)
    if k * b:
        gray_kernel[(k * b,)](frames, images.contiguous() if images is not None else out, out,
                              PIXELS=h * w * c // 3, GATHER=images is not None, BLOCK_P=GRAY_BLOCK, num_warps=4)
    return out
