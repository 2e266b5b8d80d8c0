"""The standard augmentations' GPU pass (kage.ppo.fast.augment_kernel, compiled for the device) against their
definition, kage.ppo.augment_plan.reference, run on the same GPU tensors: each augmentation of the standard set
on frames of the trainer's shape (128 x 128 RGB, and a stack of 4), on a batch and on a minibatch read at
indices of a rollout buffer. Integer stages agree exactly; the others within one code on at most 1 % of the
values (the kernel may fuse a multiply and an add where torch rounds twice)."""
import pytest
import torch

from kage.ppo import augment, augment_plan, plugins
from kage.ppo.counter_random import CounterRandom

EXACT = ("random_shift", "random_crop", "cutout_color")


def draws():
    return plugins.augment_draws(CounterRandom([1, 2, 3], "cuda"), 3, torch.zeros((), dtype=torch.int64,
                                                                                  device="cuda"), 0)


def on_reference(monkeypatch):
    """kage.ppo.augment through the torch definition instead of the kernels."""
    monkeypatch.setattr(augment, "apply", augment_plan.reference)
    monkeypatch.setattr(augment, "gray_means", lambda frames, images=None: augment_plan.gray_means(
        (frames if images is None else frames.reshape(-1, *frames.shape[-3:])[images]).cpu()).to(frames.device))


def check(got, want, exact):
    assert got.dtype == torch.uint8 and got.shape == want.shape and got.is_cuda
    difference = (got.int() - want.int()).abs()
    if exact:
        assert int(difference.max()) == 0
    else:
        share = float((difference > 0).float().mean())
        assert int(difference.max()) <= 1 and share <= 0.01, (int(difference.max()), share)


@pytest.mark.parametrize("name", sorted(augment.STANDARD))
@pytest.mark.parametrize("channels", [3, 12])
def test_kernel_equals_reference_on_the_gpu(monkeypatch, name, channels):
    fn = augment.STANDARD[name]
    generator = torch.Generator("cuda").manual_seed(7)
    buffer = torch.randint(0, 256, (4, 3, 64, 128, 128, channels), dtype=torch.uint8, device="cuda",
                           generator=generator)
    images = torch.randint(0, 4 * 3 * 64, (3, 256), device="cuda", generator=generator)
    batch = buffer[0]
    got_batch, got_minibatch = fn(batch, draws()), fn(buffer, draws(), images=images)
    on_reference(monkeypatch)
    check(got_batch, fn(batch, draws()), name in EXACT)
    check(got_minibatch, fn(buffer, draws(), images=images), name in EXACT)


@pytest.mark.parametrize("name", sorted(augment.STANDARD))
def test_the_rollouts_graph_replays_the_eager_augmentation(name):
    """--augment-mode rollout under --cuda-graph: the captured augmentation of a step's frames equals the eager one
    at every position (iteration, step, final frame)."""
    from kage.ppo.train import RolloutAugment
    fn = augment.STANDARD[name]
    shape = (3, 64, 128, 128, 3)
    random = CounterRandom([1, 2, 3], "cuda")
    graphed = RolloutAugment(fn, name, random, 128, shape, torch.device("cuda"), cuda_graph=True)
    eager = RolloutAugment(fn, name, random, 128, shape, torch.device("cuda"), cuda_graph=False)
    assert graphed.graph is not None, "the standard set must be capturable"
    generator = torch.Generator("cuda").manual_seed(3)
    for iteration, step, final in ((1, 0, False), (1, 5, True), (7, 128, False)):
        frames = torch.randint(0, 256, shape, dtype=torch.uint8, device="cuda", generator=generator)
        assert torch.equal(graphed(frames, iteration, step, final).clone(), eager(frames, iteration, step, final))
