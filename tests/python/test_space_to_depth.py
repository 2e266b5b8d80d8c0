"""kage.ppo.fast.space_to_depth: a stride-s convolution equals the stride-1 convolution of the input's s x s blocks
with the rearranged weight, for conv1's shape (8x8, stride 4, 3 channels, a side whose last rows no window
reads) and a 4x4 stride-2 one over 32 channels; and --fused-input's conv1 (Agent._conv1_space_to_depth, which
cuts the frames into blocks itself) equals the plain strided conv1. Checked on the CPU against torch's own
strided convolution, run by run of a pack of two (float32: the same products summed in another order)."""
import pytest
import torch
import torch.nn.functional as F

from kage.ppo.agent import Agent
from kage.ppo.fast.space_to_depth import weight_space_to_depth


def blocks_of(x: torch.Tensor, s: int) -> torch.Tensor:
    """[B, H, W, C] -> [B, C * s * s, H // s, W // s]: channel (c, p, q) of block (i, j) holds x[s * i + p,
    s * j + q, c] (the formula written out, independently of the code under test)."""
    b, h, w, c = x.shape
    out = torch.empty(b, c * s * s, h // s, w // s)
    for ch in range(c):
        for p in range(s):
            for q in range(s):
                out[:, (ch * s + p) * s + q] = x[:, p:h // s * s:s, q:w // s * s:s, ch]
    return out


@pytest.mark.parametrize("side, channels, kernel, stride", [(46, 3, 8, 4), (31, 32, 4, 2)])
def test_blocked_convolution_equals_the_strided_one(side, channels, kernel, stride):
    runs, out = 2, 16
    generator = torch.Generator().manual_seed(side)
    x = torch.rand(runs, 3, side, side, channels, generator=generator)
    weight = torch.randn(runs * out, channels, kernel, kernel, generator=generator)
    blocked_weight = weight_space_to_depth(weight, stride)
    for k in range(runs):
        reference = F.conv2d(x[k].permute(0, 3, 1, 2), weight[k * out:(k + 1) * out], stride=stride)
        got = F.conv2d(blocks_of(x[k], stride), blocked_weight[k * out:(k + 1) * out])
        assert got.shape == reference.shape
        assert torch.allclose(got, reference, rtol=1e-5, atol=1e-4)


def test_fused_input_conv1_equals_the_strided_one():
    seeds, side = [5, 6], 46
    plain, fused = Agent(seeds, height=side, width=side), Agent(seeds, height=side, width=side, fused_input=True)
    frames = torch.randint(0, 256, (len(seeds), 3, side, side, 3), dtype=torch.uint8,
                           generator=torch.Generator().manual_seed(0))
    reference = plain.conv1(plain._input(frames.permute(1, 2, 3, 0, 4).reshape(3, side, side, -1)))
    got = fused._conv1_space_to_depth(frames)
    assert got.shape == reference.shape
    assert torch.allclose(got, reference, rtol=1e-5, atol=1e-4)
