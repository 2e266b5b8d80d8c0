"""kage.ppo.fast.space_to_depth: a stride-s convolution equals the stride-1 convolution of the input's s x s blocks
with the rearranged weight, for conv1's shape (8x8, stride 4, 3 channels) and conv2's (4x4, stride 2,
32 channels, an odd side whose last row and column no window reads). --fused-input and the GPU-only
--triton-conv rely on these formulas; here they are checked on the CPU against torch's own strided
convolution, run by run of a pack of two (float32: the same products summed in another order)."""
import pytest
import torch
import torch.nn.functional as F

from kage.ppo.fast.space_to_depth import space_to_depth, weight_space_to_depth


@pytest.mark.parametrize("side, channels, kernel, stride", [(44, 3, 8, 4), (31, 32, 4, 2)])
def test_blocked_convolution_equals_the_strided_one(side, channels, kernel, stride):
    runs, out = 2, 16
    generator = torch.Generator().manual_seed(side)
    x = torch.rand(runs, 3, side, side, channels, generator=generator)
    weight = torch.randn(runs * out, channels, kernel, kernel, generator=generator)
    blocks, blocked_weight = space_to_depth(x, stride), weight_space_to_depth(weight, stride)
    for k in range(runs):
        w = weight[k * out:(k + 1) * out]
        reference = F.conv2d(x[k].permute(0, 3, 1, 2), w, stride=stride)
        got = F.conv2d(blocks[k].permute(0, 3, 1, 2), blocked_weight[k * out:(k + 1) * out])
        assert got.shape == reference.shape
        assert torch.allclose(got, reference, rtol=1e-5, atol=1e-4)


def test_conversion_in_the_same_copy():
    frames = torch.randint(0, 256, (2, 3, 20, 20, 3), dtype=torch.uint8)
    assert torch.equal(space_to_depth(frames, 4, torch.float32), space_to_depth(frames.float(), 4))
