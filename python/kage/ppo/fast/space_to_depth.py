"""Space-to-depth: a convolution whose kernel and stride are multiples of s, rewritten as the equal
stride-1 convolution over s x s blocks of the input (more channels, fewer positions). --fused-input runs
conv1 (8x8, stride 4) this way (kage.ppo.agent.Agent cuts the frames into blocks). Pure torch, so the CPU
tests check the formula."""
import torch


def weight_space_to_depth(weight: torch.Tensor, s: int) -> torch.Tensor:
    """The grouped layout's weight [K * Cout, C, kh, kw] -> [K * Cout, C * s * s, kh // s, kw // s] for an input
    cut into s x s blocks whose channel (c, p, q) holds pixel (s * i + p, s * j + q) channel c of block (i, j):
    filter row s * a + p, column s * b + q meets channel (c, p, q) at offset (a, b)."""
    o, c, kh, kw = weight.shape
    assert kh % s == 0 and kw % s == 0, (weight.shape, s)
    blocks = weight.reshape(o, c, kh // s, s, kw // s, s).permute(0, 1, 3, 5, 2, 4)
    return blocks.reshape(o, c * s * s, kh // s, kw // s)
