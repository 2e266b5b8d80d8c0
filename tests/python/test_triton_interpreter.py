"""kage.ppo.fast.triton_conv's kernels (--triton-conv) on the CPU under Triton's interpreter, in float32, against
torch's grouped convolutions (F.conv2d(groups=K), the plain layers) on the same values, the NatureCNN's layers as
the trainer runs them, under each autotuning config of every kernel, K = 2 runs of B = 2 or 3 frames:
- the gather of a minibatch's uint8 frames from a rollout buffer into 4 x 4 blocks;
- conv1 on those blocks, the frames at a minibatch's shuffled indices of a rollout buffer, output and weight and
  bias gradients;
- conv2 (4x4, stride 2, over conv1's 31 x 31 x 32 output) and conv3 (3x3), output and input, weight and bias
  gradients, alone and with the fused ReLU;
- the weight and bias gradients' split into partial sums;
- the Agent's --triton-conv torso against its plain one, forward and parameter gradients, on a batch and on a
  minibatch read from a rollout buffer.

The interpreter computes tl.dot in full float32 (no TF32), so the kernels must agree with torch to float32
rounding. bfloat16 is checked on the GPU only (tests/gpu/test_triton_conv.py): the interpreter does not emulate
bf16 tl.dot. A missing triton fails this file: CI installs it (scripts/constraints.txt).

TRITON_INTERPRET is read when triton.jit decorates a kernel, so this module sets it before importing triton or
kage.ppo.fast.triton_conv; CTest runs each test file in its own process. In a pytest process that imported
triton_conv earlier without it, the tests fail with a message saying so.
"""
import os

os.environ["TRITON_INTERPRET"] = "1"

import pytest  # noqa: E402
import torch  # noqa: E402
import torch.nn.functional as F  # noqa: E402
from triton.runtime.interpreter import InterpretedFunction  # noqa: E402

from kage.ppo.agent import Agent  # noqa: E402
from kage.ppo.fast import triton_conv as tc  # noqa: E402

KERNELS = (tc.forward_kernel, tc.dgrad_kernel, tc.wgrad_kernel)
# NatureCNN's convolutions after conv1 (which reads the frames: test_conv1_reads_frames_in_place): (name, input
# side, in channels, out channels, kernel, stride).
LAYERS = [("conv2", 31, 32, 64, 4, 2), ("conv3", 14, 64, 64, 3, 1)]
# max |got - want| / max |want|: float32 rounding of sums over up to 1,024 products, in another order.
TOLERANCE = 1e-5


@pytest.fixture(autouse=True)
def interpreted():
    if not all(isinstance(kernel.fn, InterpretedFunction) for kernel in KERNELS):
        pytest.fail("kage.ppo.fast.triton_conv was imported before TRITON_INTERPRET=1 was set: run this file in "
                    "its own pytest process (as CTest does)")


def use_config(index: int, monkeypatch) -> None:
    """Each kernel restricted to its index-th autotuning config (its last where it has fewer): with one config
    the autotuner runs it without benchmarking (which needs a GPU driver), and each config's tile sizes meet the
    masks differently."""
    for kernel in KERNELS:
        monkeypatch.setattr(kernel, "configs", [kernel.configs[min(index, len(kernel.configs) - 1)]])


def relative_error(got: torch.Tensor, want: torch.Tensor) -> float:
    assert got.shape == want.shape, (got.shape, want.shape)
    return ((got.double() - want.double()).abs().max() / want.double().abs().max()).item()


def grouped_layer(x: torch.Tensor, weight: torch.Tensor, bias: torch.Tensor, stride: int) -> torch.Tensor:
    """The plain layer: x [K, B, H, W, C] as K channel groups of [B, K * C, H, W] through F.conv2d(groups=K),
    the result back as [K, B, OH, OW, Cout]."""
    k, b, h, w, c = x.shape
    y = F.conv2d(x.permute(1, 0, 4, 2, 3).reshape(b, k * c, h, w), weight, bias, stride=stride, groups=k)
    return y.reshape(b, k, -1, *y.shape[2:]).permute(1, 0, 3, 4, 2)


# The trainer's fused ReLU under every config; the plain convolution under the first (the same kernels with the
# ReLU's code compiled out), to keep the interpreter's time down.
@pytest.mark.parametrize("config, relu", [(0, False), (0, True), (1, True), (2, True), (3, True), (4, True)],
                         ids=["config0", "config0_relu", "config1_relu", "config2_relu", "config3_relu",
                              "config4_relu"])
@pytest.mark.parametrize("layer", LAYERS, ids=[layer[0] for layer in LAYERS])
def test_layer_equals_grouped_conv(layer, config, relu, monkeypatch):
    use_config(config, monkeypatch)
    name, side, cin, cout, ksize, stride = layer
    # K != B once: an index that mixes the two up reads other frames (the formulas are the same under every
    # config); B = 2 under the others, to keep the interpreter's time down.
    k, b = 2, 3 if config == 0 else 2
    generator = torch.Generator().manual_seed(config)
    x = torch.randn(k, b, side, side, cin, generator=generator, requires_grad=True)
    weight = torch.randn(k * cout, cin, ksize, ksize, generator=generator, requires_grad=True)
    bias = torch.randn(k * cout, generator=generator, requires_grad=True)

    y = tc.packed_conv(x, weight, bias, stride, relu=relu)
    dy = torch.randn(y.shape, generator=generator)
    got = (y,) + torch.autograd.grad(y, (x, weight, bias), dy)
    y_ref = grouped_layer(x, weight, bias, stride)
    if relu:
        y_ref = F.relu(y_ref)
        assert 0.2 < (y_ref > 0).double().mean() < 0.8, "both sides of the ReLU are exercised"
    want = (y_ref,) + torch.autograd.grad(y_ref, (x, weight, bias), dy)

    for quantity, g, w in zip(("y", "dx", "dw", "db"), got, want):
        assert g.dtype == torch.float32, quantity
        assert relative_error(g, w) <= TOLERANCE, (name, quantity, relative_error(g, w))


def test_frames_to_blocks_gathers_and_cuts():
    """frames_to_blocks against torch's indexing and the space-to-depth reshape (channel (c, p, q) of block
    (i, j) is pixel (4i + p, 4j + q) channel c), on frames whose side is no multiple of 4 (the last 2 rows and
    columns are dropped) from a [T, K, N] buffer at shuffled indices."""
    generator = torch.Generator().manual_seed(5)
    buffer = torch.randint(0, 256, (2, 2, 3, 66, 66, 3), dtype=torch.uint8, generator=generator)
    images = torch.randperm(12, generator=generator)[:6].view(2, 3)
    got = tc.frames_to_blocks(buffer, images, 4)
    frames = buffer.reshape(-1, 66, 66, 3)[images][:, :, :64, :64]
    want = frames.reshape(2, 3, 16, 4, 16, 4, 3).permute(0, 1, 2, 4, 6, 3, 5).reshape(2, 3, 16, 16, 48)
    assert got.dtype == torch.uint8 and torch.equal(got, want)


@pytest.mark.parametrize("config", range(len(tc.wgrad_kernel.configs)))
def test_conv1_reads_frames_in_place(config, monkeypatch):
    """conv1 (8x8, stride 4, ReLU) as the trainer's update runs it: uint8 frames gathered from where a [T, K, N]
    rollout buffer holds them, at a minibatch's shuffled indices, into 4 x 4 blocks read as integers, the
    1 / 255 in the weight. The output and the weight and bias gradients equal the plain layer's on the gathered
    frames / 255."""
    use_config(config, monkeypatch)
    steps, k, envs, side, cout = 2, 2, 3, 128, 32
    generator = torch.Generator().manual_seed(config)
    buffer = torch.randint(0, 256, (steps, k, envs, side, side, 3), dtype=torch.uint8, generator=generator)
    # Run k's j-th minibatch element is element t * N + n of its batch: frame (t * K + k) * N + n of the buffer.
    batch = torch.stack([torch.randperm(steps * envs, generator=generator)[:2] for _ in range(k)])  # [K, B]
    images = (batch // envs * k + torch.arange(k)[:, None]) * envs + batch % envs
    weight = (0.1 * torch.randn(k * cout, 3, 8, 8, generator=generator)).requires_grad_()
    bias = torch.randn(k * cout, generator=generator, requires_grad=True)

    y = tc.packed_conv_frames(buffer, images, weight, bias, 4, torch.float32, relu=True)
    dy = torch.randn(y.shape, generator=generator)
    got = (y,) + torch.autograd.grad(y, (weight, bias), dy)
    gathered = buffer.transpose(0, 1).reshape(k, steps * envs, side, side, 3)[torch.arange(k)[:, None], batch]
    y_ref = F.relu(grouped_layer(gathered.float() / 255, weight, bias, 4))
    assert 0.2 < (y_ref > 0).double().mean() < 0.8, "both sides of the ReLU are exercised"
    want = (y_ref,) + torch.autograd.grad(y_ref, (weight, bias), dy)
    for quantity, g, w in zip(("y", "dw", "db"), got, want):
        assert g.dtype == torch.float32, quantity
        assert relative_error(g, w) <= TOLERANCE, (quantity, relative_error(g, w))


@pytest.mark.parametrize("chunk", [100, 128])
def test_weight_gradient_partial_sums(chunk, monkeypatch):
    """On the GPU, M's rows split into parts of at least 2,048 rows; here conv3's 288 rows of K = 2 runs of
    B = 2 split into 3 parts, the last one short (and a chunk that is no multiple of BLOCK_M: rows masked
    within a part), and the parts' sums must add up to the whole weight and bias gradients, with the ReLU's
    gradient applied."""
    monkeypatch.setattr(tc, "_wgrad_chunk", lambda m, runs: chunk)
    for kernel in KERNELS:
        monkeypatch.setattr(kernel, "configs", kernel.configs[:1])
    k, b, side, cin, cout, ksize = 2, 2, 14, 64, 64, 3
    generator = torch.Generator().manual_seed(chunk)
    x = torch.randn(k, b, side, side, cin, generator=generator)
    weight = torch.randn(k * cout, cin, ksize, ksize, generator=generator, requires_grad=True)
    bias = torch.randn(k * cout, generator=generator, requires_grad=True)
    y = F.relu(grouped_layer(x, weight, bias, 1))
    dy = torch.randn(y.shape, generator=generator)
    dw_ref, db_ref = torch.autograd.grad(y, (weight, bias), dy)

    dw, db = tc._wgrad(x, dy, y.detach().contiguous(), ksize, ksize, 1, relu=True)  # [K, kh, kw, Cin, Cout], [K, Cout]
    assert relative_error(dw, dw_ref.reshape(k, cout, cin, ksize, ksize).permute(0, 3, 4, 2, 1)) <= TOLERANCE
    assert relative_error(db, db_ref.reshape(k, cout)) <= TOLERANCE


def test_agent_triton_torso_equals_plain(monkeypatch):
    """The whole network with --fused-input --triton-conv against the default (cuDNN's path on the GPU, here
    torch's CPU convolutions): the same parameters give the same logits, values and parameter gradients. This
    checks the torso's wiring (blocks, scaling, each run's flatten order), on 64 x 64 frames to keep the
    interpreter's time down: the layer test covers the 128 x 128 frames' shapes and the other configs."""
    for kernel in KERNELS:
        monkeypatch.setattr(kernel, "configs", kernel.configs[:1])
    seeds, frames, side = [3, 4], 3, 64
    plain = Agent(seeds, height=side, width=side)
    fast = Agent(seeds, height=side, width=side, fused_input=True, triton_conv=True)
    for (name, p), q in zip(plain.named_parameters(), fast.parameters()):
        assert torch.equal(p, q), f"{name}: the two agents must start from the same parameters"
    generator = torch.Generator().manual_seed(0)
    obs = torch.randint(0, 256, (len(seeds), frames, side, side, 3), dtype=torch.uint8, generator=generator)
    weights = torch.randn(len(seeds), frames, 8, generator=generator)

    # The same frames as a minibatch of a rollout buffer [T = 2, K, N = 2]: run k's b-th frame at images[k, b].
    buffer = torch.randint(0, 256, (2, len(seeds), 2, side, side, 3), dtype=torch.uint8, generator=generator)
    images = torch.tensor([[6, 1, 4], [3, 7, 2]])
    buffer.view(-1, side, side, 3)[images] = obs

    results = []
    for agent, inputs in ((plain, (obs,)), (fast, (obs,)), (plain, (buffer, images)), (fast, (buffer, images))):
        logits, value = agent(*inputs)
        loss = (logits * weights).sum() + value.square().sum()  # every output reaches the gradients
        results.append((logits, value, torch.autograd.grad(loss, list(agent.parameters()))))
    logits, value, grads = results[0]
    for fast_logits, fast_value, fast_grads in results[1:]:
        assert relative_error(fast_logits, logits) <= TOLERANCE
        assert relative_error(fast_value, value) <= TOLERANCE
        for (name, _), g, fast_g in zip(plain.named_parameters(), grads, fast_grads):
            assert relative_error(fast_g, g) <= TOLERANCE, (name, relative_error(fast_g, g))
