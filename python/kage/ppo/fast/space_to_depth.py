"""Space-to-depth: a convolution whose kernel and stride are multiples of s, rewritten as the equal
stride-1 convolution over s x s blocks of the input (more channels, fewer positions). --fused-input runs
conv1 (8x8, stride 4) this way, --triton-conv conv2 (4x4, stride 2; its conv1 strides over the frames).
Pure torch, so the CPU
tests check the formulas the GPU kernels rely on."""
from typing import Optional

import torch


def space_to_depth(x: torch.Tensor, s: int, dtype: Optional[torch.dtype] = None) -> torch.Tensor:
    """[K, B, H, W, C] -> [K, B, H // s, W // s, C * s * s], channel (c, p, q) of block (i, j) holding
    x[.., s * i + p, s * j + q, c] (the trainer's fused-input order); rows and columns past the last whole
    block are dropped (a stride-s convolution whose kernel is a multiple of s never reads them). A dtype
    converts in the same copy (uint8 frames)."""
    k, b, h, w, c = x.shape
    h, w = h // s * s, w // s * s
    blocks = x[:, :, :h, :w].reshape(k, b, h // s, s, w // s, s, c).permute(0, 1, 2, 4, 6, 3, 5)
    if dtype is not None:
        blocks = blocks.to(dtype, memory_format=torch.contiguous_format)
    return blocks.reshape(k, b, h // s, w // s, c * s * s)


def weight_space_to_depth(weight: torch.Tensor, s: int) -> torch.Tensor:
    """The grouped layout's weight [K * Cout, C, kh, kw] -> [K * Cout, C * s * s, kh // s, kw // s] for
    space_to_depth's input: filter row s * a + p, column s * b + q meets channel (c, p, q) at offset (a, b)."""
    o, c, kh, kw = weight.shape
    assert kh % s == 0 and kw % s == 0, (weight.shape, s)
    blocks = weight.reshape(o, c, kh // s, s, kw // s, s).permute(0, 1, 3, 5, 2, 4)
    return blocks.reshape(o, c * s * s, kh // s, kw // s)
