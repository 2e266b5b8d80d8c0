"""kage.ppo.fast.augment_kernel (the standard augmentations' GPU pass) on the CPU under Triton's interpreter,
against kage.ppo.augment_plan.reference, which defines it: every stage alone and the stages together, frames
given as a batch and read at a minibatch's indices of a rollout buffer, single and stacked frames. Integer
stages (remap, cutout) agree exactly; the others within one code of rounding (the kernel may fuse a multiply and
an add where torch rounds twice), on at most 1 % of the values. The GPU checks the same on the device
(tests/gpu/test_augment_gpu.py).

TRITON_INTERPRET is read when triton.jit decorates a kernel, so this module sets it before importing triton
(CTest runs each test file in its own process)."""
import os

os.environ["TRITON_INTERPRET"] = "1"

import pytest  # noqa: E402
import torch  # noqa: E402
from triton.runtime.interpreter import InterpretedFunction  # noqa: E402

from kage.ppo import augment  # noqa: E402
from kage.ppo import augment_plan  # noqa: E402
from kage.ppo.augment_plan import Plan, reference  # noqa: E402
from kage.ppo.fast import augment_kernel  # noqa: E402


def on_kernel(frames, plan, images=None):
    """augment_kernel.apply on a plan, as augment_plan.apply calls it on the GPU."""
    count = images.numel() if images is not None else frames.shape[0] * frames.shape[1]
    return augment_kernel.apply(frames, plan.rows(count, frames.device), set(plan.stages()), augment_plan.SLOTS,
                                plan.images, images)


@pytest.fixture(autouse=True)
def interpreted():
    if not isinstance(augment_kernel.plan_kernel, InterpretedFunction):
        pytest.fail("kage.ppo.fast.augment_kernel was imported before TRITON_INTERPRET=1 was set: run this file in "
                    "its own pytest process (as CTest does)")


def frames(shape, seed=0):
    return torch.randint(0, 256, shape, dtype=torch.uint8, generator=torch.Generator().manual_seed(seed))


def plan_of(stages, count, height, width, seed=1):
    """A plan of `stages` for `count` frames with random parameters in each stage's range."""
    g = torch.Generator().manual_seed(seed)
    u = lambda *shape: torch.rand(shape, generator=g)  # noqa: E731
    plan = Plan()
    if "remap" in stages:
        window = torch.stack([torch.randint(height // 2, height + 1, (count,), generator=g),
                              torch.randint(width // 2, width + 1, (count,), generator=g)], 1)
        origin = torch.stack([torch.randint(-3, 4, (count,), generator=g) + height - window[:, 0],
                              torch.randint(-3, 4, (count,), generator=g)], 1)
        plan.remap = torch.cat([origin, window], 1).float()
    if "conv" in stages:
        plan.conv = torch.randn((count, 81), generator=g) * 0.2
    if "colour" in stages:
        plan.colour = torch.cat([torch.randn((count, 9), generator=g) * 0.5 + torch.eye(3).reshape(9),
                                 u(count, 3) * 40 - 20], 1)
    if "noise" in stages:
        plan.noise = torch.cat([u(count, 1) * 30, torch.floor(u(count, 2) * (1 << 24))], 1)
    if "overlay" in stages:
        plan.images = frames((5, height, width, 3), seed=seed + 1)
        plan.overlay = torch.cat([torch.floor(u(count, 1) * 5), u(count, 1)], 1)
    if "cutout" in stages:
        y0, x0 = torch.floor(u(count, 1) * height), torch.floor(u(count, 1) * width)
        plan.cutout = torch.cat([y0, x0, y0 + 1 + torch.floor(u(count, 1) * 6), x0 + 1 + torch.floor(u(count, 1) * 6),
                                 torch.floor(u(count, 3) * 256)], 1)
    return plan


def check(got: torch.Tensor, want: torch.Tensor, exact: bool) -> None:
    assert got.dtype == torch.uint8 and got.shape == want.shape
    difference = (got.int() - want.int()).abs()
    if exact:
        assert int(difference.max()) == 0
    else:
        assert int(difference.max()) <= 1 and float((difference > 0).float().mean()) <= 0.01, \
            (int(difference.max()), float((difference > 0).float().mean()))


STAGE_SETS = [("remap",), ("conv",), ("colour",), ("noise",), ("overlay",), ("cutout",), ("remap", "conv"),
              ("remap", "colour", "noise", "overlay", "cutout"), ("remap", "conv", "colour", "noise", "overlay", "cutout")]


@pytest.mark.parametrize("stages", STAGE_SETS, ids=lambda s: "+".join(s))
@pytest.mark.parametrize("channels", [3, 12])
def test_the_kernel_follows_the_reference_on_a_batch(stages, channels):
    batch = frames((2, 3, 9, 11, channels))
    plan = plan_of(stages, 6, 9, 11)
    check(on_kernel(batch, plan), reference(batch, plan), exact=set(stages) <= {"remap", "cutout"})


@pytest.mark.parametrize("stages", STAGE_SETS, ids=lambda s: "+".join(s))
def test_the_kernel_reads_a_minibatch_where_the_rollout_stored_it(stages):
    buffer = frames((3, 2, 4, 9, 11, 3))  # [T, K, N, H, W, C]
    images = torch.tensor([[0, 5, 23], [17, 17, 2]])
    plan = plan_of(stages, 6, 9, 11, seed=4)
    check(on_kernel(buffer, plan, images), reference(buffer, plan, images),
          exact=set(stages) <= {"remap", "cutout"})


@pytest.mark.parametrize("channels", [3, 12])
def test_gray_means_follow_the_reference(channels):
    buffer = frames((3, 2, 4, 9, 11, channels))
    images = torch.tensor([[0, 5, 23], [17, 17, 2]])
    want = augment_plan.gray_means(buffer.reshape(-1, 9, 11, channels)[images])  # the CPU's path
    assert torch.allclose(augment_kernel.gray_means(buffer, images), want, rtol=1e-5)


def test_each_standard_augmentation_runs_as_a_kernel(monkeypatch):
    """The standard set through the kernels (as on the GPU) equals its CPU path."""
    from kage.ppo.counter_random import CounterRandom
    from kage.ppo.plugins import augment_draws
    batch = frames((2, 3, 16, 16, 3))
    for name, fn in sorted(augment.STANDARD.items()):
        draws = lambda: augment_draws(CounterRandom([1, 2], "cpu"), 3, torch.zeros((), dtype=torch.int64), 0)  # noqa
        on_cpu = fn(batch, draws())
        monkeypatch.setattr(augment_plan, "apply", on_kernel)
        monkeypatch.setattr(augment_plan, "gray_means", lambda f, i=None: augment_kernel.gray_means(f, i))
        monkeypatch.setattr(augment, "apply", augment_plan.apply)
        monkeypatch.setattr(augment, "gray_means", augment_plan.gray_means)
        check(fn(batch, draws()), on_cpu, exact=name in ("random_shift", "random_crop", "cutout_color"))
        monkeypatch.undo()
