"""kage.ppo.augment's standard set on the CPU (the torch path, kage.ppo.augment_plan.reference): each
augmentation on hand-made frames against values worked out by hand, and the contract every one keeps: uint8
frames of the input's shape, the same output for the same draws (and another for other draws), a minibatch read
at indices equal to the gathered one, a stack of frames sharing its frame's draw."""
import math

import numpy as np
import pytest
import torch
from PIL import Image

from kage import resources
from kage.ppo import augment, plugins
from kage.ppo.augment_plan import Plan, reference
from kage.ppo.counter_random import CounterRandom


def fixed(*values):
    """uniform(shape) returning `values` along the last axis (one value: everywhere), for K = 1 run."""
    def uniform(shape):
        row = torch.tensor(values, dtype=torch.float32)
        return row.expand(1, *shape).clone() if len(values) > 1 else torch.full((1, *shape), values[0])
    return uniform


def frame_of(pixels) -> torch.Tensor:
    """[1, 1, H, W, 3] uint8 from an [H, W, 3] array."""
    return torch.tensor(np.asarray(pixels), dtype=torch.uint8)[None, None]


def filled(height, width, rgb) -> torch.Tensor:
    return frame_of(np.broadcast_to(np.array(rgb, dtype=np.uint8), (height, width, 3)))


def draws(seed=1, position=0, runs=2):
    return plugins.augment_draws(CounterRandom(list(range(seed, seed + runs)), "cpu"), 3,
                                 torch.zeros((), dtype=torch.int64), position)


def random_frames(shape, seed=0) -> torch.Tensor:
    return torch.randint(0, 256, shape, dtype=torch.uint8, generator=torch.Generator().manual_seed(seed))


# ---- each augmentation against values worked by hand ----

def test_random_crop_takes_a_window_and_resizes_it_back_by_nearest_neighbour():
    rows = np.arange(8)[:, None, None] * 8 + np.arange(8)[None, :, None] + np.zeros(3, dtype=int)
    out = augment.random_crop(frame_of(rows), fixed(0.75, 0.25))[0, 0, :, :, 0]
    # window round(0.84 * 8) = 7; origin floor(0.75 * 2) = 1 (rows), floor(0.25 * 2) = 0 (columns);
    # output row y reads row 1 + y * 7 // 8: 1, 1, 2, 3, 4, 5, 6, 7; column x reads x * 7 // 8: 0, 0, 1, ..., 6.
    want = np.array([1, 1, 2, 3, 4, 5, 6, 7])[:, None] * 8 + np.array([0, 0, 1, 2, 3, 4, 5, 6])[None, :]
    assert (out.numpy() == want).all()


def test_color_jitter_at_the_middle_draws_is_the_identity():
    frames = random_frames((1, 2, 6, 5, 3))
    assert torch.equal(augment.color_jitter(frames, fixed(0.5, 0.5, 0.5, 0.5)), frames)


@pytest.mark.parametrize("draw, pixel, want", [
    ((0.75, 0.5, 0.5, 0.5), (100, 40, 0), (120, 48, 0)),           # brightness 1.2
    ((0.75, 0.5, 0.5, 0.5), (250, 40, 0), (255, 48, 0)),           # 300 clamps to 255
    ((0.5, 0.5, 0.0, 0.5), (100, 40, 0), (81, 45, 21)),            # saturation 0.6: 0.6 v + 0.4 * 53.38
    ((0.5, 0.5, 0.5, 1.0), (100, 40, 0), (7, 67, 107)),            # hue half a turn: 2 * luma - v
], ids=["brightness", "clamped", "saturation", "hue"])
def test_color_jitter_on_one_colour(draw, pixel, want):
    # luma(100, 40, 0) = 0.299 * 100 + 0.587 * 40 = 53.38; rotating YIQ's chroma by pi negates I and Q, and
    # grey maps to grey, so v -> 2 Y - v.
    out = augment.color_jitter(filled(3, 3, pixel), fixed(*draw))
    assert (out[0, 0].reshape(-1, 3) == torch.tensor(want, dtype=torch.uint8)).all(), out[0, 0, 0, 0]


def test_color_jitter_contrast_pivots_on_the_frame_mean_luma():
    frame = np.zeros((2, 2, 3), dtype=np.uint8)
    frame[0] = 10
    frame[1] = 110  # mean luma 60
    out = augment.color_jitter(frame_of(frame), fixed(0.5, 0.25, 0.5, 0.5))[0, 0]  # contrast 0.8
    assert (out[0] == 20).all() and (out[1] == 100).all(), out  # 0.8 v + 0.2 * 60


def test_grayscale_puts_luma_in_every_channel_with_its_probability():
    pixel = filled(2, 2, (100, 40, 0))
    assert (augment.grayscale(pixel, fixed(0.29))[0, 0] == 53).all()  # draw < 0.3: luma 53.38
    assert torch.equal(augment.grayscale(pixel, fixed(0.31)), pixel)
    share = (augment.grayscale(filled(1, 1, (100, 40, 0)).expand(2, 4000, 1, 1, 3).contiguous(),
                               draws())[..., 1] == 53).float().mean().item()
    assert abs(share - augment.GRAYSCALE_P) < 0.03


def test_the_convolution_stage_pads_with_zeros():
    weights = torch.zeros(3, 3, 3, 3)
    for j in range(3):
        weights[j, j] = 1 / 9  # each channel's 3 x 3 mean
    out = reference(filled(4, 4, (90, 90, 90)), Plan(conv=weights.reshape(1, 81)))[0, 0, :, :, 0]
    # corners see 4 of 9 pixels (40), edges 6 (60), the inside 9 (90)
    want = torch.tensor([[40, 60, 60, 40], [60, 90, 90, 60], [60, 90, 90, 60], [40, 60, 60, 40]], dtype=torch.uint8)
    assert torch.equal(out, want)


def test_random_conv_draws_xavier_normal_weights():
    frames = filled(5, 5, (0, 0, 0))
    frames[..., 2, 2, 0] = 255  # one red pixel: the output around it shows the weights times 255
    outs = []
    for position in range(400):
        out = augment.random_conv(frames.expand(2, 1, 5, 5, 3).contiguous(), draws(position=position)).float()
        outs.append(out[:, 0, 1:4, 1:4, :])  # 27 products per frame, clamped below at 0
    values = torch.stack(outs) / 255  # weights w[j, 0, dy, dx] where positive (clamped to 0 where negative)
    positive = values[values > 0]
    # half-normal of standard deviation sqrt(2 / 54): mean sigma * sqrt(2 / pi), about half the draws positive
    sigma = math.sqrt(2 / 54)
    assert abs(positive.mean().item() - sigma * math.sqrt(2 / math.pi)) < 0.01
    assert abs((values > 0).float().mean().item() - 0.5) < 0.02


def test_cutout_color_fills_one_box():
    frames = filled(84, 84, (7, 8, 9))
    out = augment.cutout_color(frames, fixed(0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5))[0, 0]
    # sides 10 + floor(0.5 * 20) = 20; origin floor(0.5 * (84 - 20 + 1)) = 32; colour floor(0.5 * 256) = 128
    assert (out[32:52, 32:52] == 128).all()
    outside = torch.ones(84, 84, dtype=torch.bool)
    outside[32:52, 32:52] = False
    assert (out[outside] == torch.tensor([7, 8, 9], dtype=torch.uint8)).all()


def test_gaussian_noise_has_its_standard_deviation_and_follows_its_keys():
    frames = filled(64, 64, (128, 128, 128)).expand(2, 1, 64, 64, 3).contiguous()
    out = augment.gaussian_noise(frames, draws()).float() - 128
    assert abs(out.mean().item()) < 0.5
    assert abs(out.std().item() - augment.NOISE_SIGMA) < 0.5
    assert not torch.equal(out[0], out[1])  # each run's own keys
    again = augment.gaussian_noise(frames, draws()).float() - 128
    assert torch.equal(out, again)


def test_overlay_blends_half_of_a_shipped_background():
    frames = filled(128, 128, (200, 0, 100))
    out = augment.overlay(frames, fixed(0.001))[0, 0].int()  # floor(0.001 * 126) = 0: the pool's first, bg-2
    with Image.open(resources.data_root() / "assets" / "backgrounds" / "bg-2.jpeg") as image:
        picture = torch.tensor(np.asarray(image.convert("RGB")), dtype=torch.int32)
    want = torch.floor((torch.tensor([200, 0, 100]) + picture) / 2 + 0.5)  # alpha 0.5
    assert torch.equal(out, want.int())


# ---- the contract, for every augmentation ----

@pytest.fixture(params=sorted(augment.STANDARD))
def named(request):
    return request.param, augment.STANDARD[request.param]


def test_uint8_frames_of_the_input_shape(named):
    name, fn = named
    frames = random_frames((2, 3, 16, 20, 3))
    out = fn(frames, draws())
    assert out.dtype == torch.uint8 and out.shape == frames.shape and out.device == frames.device, name
    assert fn.takes_frame_indices is True


def test_same_draws_same_frames_other_draws_other_frames(named):
    name, fn = named
    frames = random_frames((2, 8, 16, 16, 3))
    first, again, other = fn(frames, draws()), fn(frames, draws()), fn(frames, draws(seed=5))
    assert torch.equal(first, again), name
    assert not torch.equal(first, other), name


def test_a_minibatch_read_at_indices_equals_the_gathered_one(named):
    name, fn = named
    buffer = random_frames((4, 2, 3, 16, 16, 3))  # a rollout buffer [T, K, N, ...]
    images = torch.tensor([[0, 7, 13], [5, 5, 22]])
    gathered = buffer.reshape(-1, 16, 16, 3)[images]
    assert torch.equal(fn(buffer, draws(), images=images), fn(gathered, draws())), name


def test_a_stack_of_frames_shares_its_draw(named):
    name, fn = named
    one = random_frames((2, 3, 16, 16, 3))
    stacked = one.repeat(1, 1, 1, 1, 4)  # four copies of each frame, as --use-frame-stack lays them out
    out = fn(stacked, draws())
    alone = fn(one, draws())
    if name == "gaussian_noise":  # each element's noise is its own, so the stacked frames differ
        assert not torch.equal(out[..., :3], out[..., 3:6])
        return
    assert torch.equal(out, alone.repeat(1, 1, 1, 1, 4)), name


def test_a_run_draws_its_own_numbers_alone_or_packed(named):
    name, fn = named
    frames = random_frames((2, 4, 16, 16, 3))
    packed = fn(frames, draws(seed=1, runs=2))
    second_alone = fn(frames[1:], draws(seed=2, runs=1))
    assert torch.equal(packed[1:], second_alone), name
