"""The standard image augmentations of pixel RL, each a function with the trainer's --augment contract
(kage.ppo.plugins): fn(obs, uniform) -> obs, uint8 [K, B, H, W, C] in and out, every random choice drawn
from `uniform` (each run's counter-based stream), so a run draws the same numbers alone, packed or resumed.
Each also takes `images=` (int64 [K, B]: run k's b-th frame is obs.reshape(-1, H, W, C)[images[k, b]]), so
the trainer reads a minibatch where the rollout stored it: the gather and the augmentation are one pass
(`takes_frame_indices`). A stack of frames (C = 12) shares one draw per observation.

Each draws its frames' parameters here (a few numbers a frame) and applies them in one pass over the pixels
(kage.ppo.augment_plan: a Triton kernel on the GPU, torch on the CPU). The README's table gives what each
targets and where its parameters come from.

    random_shift    pad 4 pixels, crop back at a random offset (DrQ, Kostrikov et al. 2020; RAD)
    random_crop     a random 84 % window, resized back by nearest neighbour (RAD, Laskin et al. 2020: 84 of 100)
    color_jitter    brightness, contrast, saturation 0.4, hue 0.5 (RAD's and DrAC's ColorJitter settings)
    grayscale       luma in all channels with probability 0.3 (RAD)
    random_conv     a random 3x3 convolution, Xavier-normal weights (Lee et al. 2020, network randomization)
    cutout_color    one box of 10-29 / 84 of the side in a random colour (RAD's cutout-color)
    gaussian_noise  additive N(0, 25.5) per pixel, 10 % of the range (our setting; no single source)
    overlay         alpha 0.5 blend with a random shipped background image (SVEA, Hansen et al. 2021)
"""
import functools
import math
from typing import Callable, Optional

import torch

from kage.ppo.augment_plan import LUMA, Plan, apply, gray_means

PAD = 4  # random_shift: pixels of shift at most, each way
CROP = 0.84  # random_crop: the window's side over the frame's (RAD: 84 of 100)
JITTER = {"brightness": 0.4, "contrast": 0.4, "saturation": 0.4, "hue": 0.5}
GRAYSCALE_P = 0.3
CUTOUT_SIDES = (10 / 84, 30 / 84)  # of the frame's side
NOISE_SIGMA = 25.5
OVERLAY_ALPHA = 0.5
# bg-1 is the IMAGE_* bases' training background and bg-128 the held-out eval background of background/6, 7,
# 9 and 10; background/5 evaluates on all 128, so the pool overlaps that pair's eval config.
OVERLAY_POOL = [f"bg-{i}.jpeg" for i in range(2, 128)]


def takes_frame_indices(fn: Callable) -> Callable:
    fn.takes_frame_indices = True
    return fn


# No tensor is made from Python values on the device per call: such a copy from pageable memory waits for the
# stream's queued work, which would stall the rollout at every step. Constants are made once per device.
@functools.lru_cache(maxsize=8)
def _constants(device: torch.device) -> dict:
    yiq = torch.tensor([[0.299, 0.587, 0.114], [0.596, -0.274, -0.322], [0.211, -0.523, 0.312]], dtype=torch.float64)
    return {"luma": torch.tensor(LUMA).to(device), "eye": torch.eye(3).to(device),
            "yiq": yiq.float().to(device), "yiq_inverse": torch.linalg.inv(yiq).float().to(device)}


def _integers(u: torch.Tensor, n) -> torch.Tensor:
    """Uniforms in (0, 1) -> integers in [0, n) (n a number or a float32 tensor of them), as float32."""
    if torch.is_tensor(n):
        return torch.minimum(torch.floor(u * n), n - 1)
    return torch.floor(u * n).clamp(max=n - 1)


def _pair(k: int, b: int, first: float, second: float, device) -> torch.Tensor:
    """[K, B, 2] float32 holding (first, second) in every row."""
    return torch.stack([torch.full((k, b), float(first), device=device), torch.full((k, b), float(second),
                                                                                     device=device)], -1)


def _normals(uniform, shape) -> torch.Tensor:
    """Standard normals [K, *shape] by Box-Muller from two draws."""
    u = uniform((2, *shape))
    return torch.sqrt(-2.0 * torch.log(u[:, 0])) * torch.cos(2 * math.pi * u[:, 1])


def _frame_shape(obs: torch.Tensor, images: Optional[torch.Tensor]):
    """(K, B, H, W) of the frames an augmentation returns."""
    k, b = (images if images is not None else obs).shape[:2]
    return k, b, obs.shape[-3], obs.shape[-2]


@takes_frame_indices
def random_shift(obs: torch.Tensor, uniform, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """Each frame shifted by its own offset in [-PAD, PAD] per axis, the border pixel repeated into the vacated
    rows and columns (replicate padding, then the crop)."""
    k, b, h, w = _frame_shape(obs, images)
    offsets = (uniform((b, 2)) * (2 * PAD + 1)).long().clamp(max=2 * PAD) - PAD  # [K, B, 2]
    return apply(obs, Plan(remap=torch.cat([offsets.float(), _pair(k, b, h, w, obs.device)], -1)), images)


@takes_frame_indices
def random_crop(obs: torch.Tensor, uniform, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """A window of CROP of each side at a random position, resized back to the frame by nearest neighbour."""
    k, b, h, w = _frame_shape(obs, images)
    window = _pair(k, b, round(CROP * h), round(CROP * w), obs.device)
    origin = _integers(uniform((b, 2)), _pair(k, b, h, w, obs.device) - window + 1)
    return apply(obs, Plan(remap=torch.cat([origin, window], -1)), images)


def _hue_matrices(angle: torch.Tensor) -> torch.Tensor:
    """[..., 3, 3] rotations of the chroma plane of YIQ by `angle` (radians), in RGB: a hue shift that keeps luma
    and maps grey to itself."""
    constants = _constants(angle.device)
    rotation = torch.zeros((*angle.shape, 3, 3), device=angle.device)
    cos, sin = torch.cos(angle), torch.sin(angle)
    rotation[..., 0, 0] = 1
    rotation[..., 1, 1], rotation[..., 1, 2], rotation[..., 2, 1], rotation[..., 2, 2] = cos, -sin, sin, cos
    return constants["yiq_inverse"] @ rotation @ constants["yiq"]


@takes_frame_indices
def color_jitter(obs: torch.Tensor, uniform, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """Brightness b, contrast c, saturation s, each in [1 - 0.4, 1 + 0.4], then a hue rotation of up to half a
    turn either way (JITTER), in that order and as one affine colour map with one final clamp: b x, then
    c x + (1 - c) times the frame's mean luma, then s x + (1 - s) luma(x), then the chroma rotated in YIQ."""
    k, b, _, _ = _frame_shape(obs, images)
    u = uniform((b, 4))
    bright, contrast, saturation = (1 + JITTER[name] * (2 * u[..., i] - 1)
                                    for i, name in enumerate(("brightness", "contrast", "saturation")))
    angle = 2 * math.pi * JITTER["hue"] * (2 * u[..., 3] - 1)
    constants = _constants(obs.device)
    saturate = saturation[..., None, None] * constants["eye"] + \
        (1 - saturation)[..., None, None] * constants["luma"].expand(3, 3)
    matrix = _hue_matrices(angle) @ saturate * (contrast * bright)[..., None, None]
    # Saturation and hue map grey to grey, so the contrast's pivot passes through them unchanged.
    offset = ((1 - contrast) * bright * gray_means(obs, images))[..., None].expand(k, b, 3)
    return apply(obs, Plan(colour=torch.cat([matrix.reshape(k, b, 9), offset], -1)), images)


@takes_frame_indices
def grayscale(obs: torch.Tensor, uniform, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """With probability GRAYSCALE_P a frame's luma in all three channels, else the frame as it is."""
    k, b, _, _ = _frame_shape(obs, images)
    gray = (uniform((b,)) < GRAYSCALE_P).float()[..., None, None]
    constants = _constants(obs.device)
    matrix = gray * constants["luma"].expand(3, 3) + (1 - gray) * constants["eye"]
    colour = torch.cat([matrix.reshape(k, b, 9), torch.zeros((k, b, 3), device=obs.device)], -1)
    return apply(obs, Plan(colour=colour), images)


@takes_frame_indices
def random_conv(obs: torch.Tensor, uniform, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """A 3x3 convolution from RGB to RGB with zero padding, its weights drawn anew for each frame from a normal
    of Xavier's standard deviation sqrt(2 / (fan_in + fan_out)) = sqrt(2 / 54); the result clamped to uint8."""
    k, b, _, _ = _frame_shape(obs, images)
    weights = _normals(uniform, (b, 81)) * math.sqrt(2 / 54)
    return apply(obs, Plan(conv=weights), images)


@takes_frame_indices
def cutout_color(obs: torch.Tensor, uniform, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """One box per frame, each side in [low, high) of CUTOUT_SIDES of the frame's (RAD's randint: 10 to 29 of 84
    pixels), at a random position inside the frame, filled with a random colour."""
    k, b, h, w = _frame_shape(obs, images)
    u = uniform((b, 7))
    side = _pair(k, b, h, w, obs.device)
    low, high = torch.round(CUTOUT_SIDES[0] * side), torch.round(CUTOUT_SIDES[1] * side)
    size = low + _integers(u[..., 0:2], high - low)
    origin = _integers(u[..., 2:4], side - size + 1)
    colour = _integers(u[..., 4:7], 256)
    return apply(obs, Plan(cutout=torch.cat([origin, origin + size, colour], -1)), images)


@takes_frame_indices
def gaussian_noise(obs: torch.Tensor, uniform, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """Additive Gaussian noise of standard deviation NOISE_SIGMA (pixel units) on every channel of every pixel;
    each frame's two drawn keys and the pixel's index make its value (kage.ppo.augment_plan.normal_hash)."""
    k, b, _, _ = _frame_shape(obs, images)
    keys = _integers(uniform((b, 2)), 1 << 24)
    return apply(obs, Plan(noise=torch.cat([torch.full((k, b, 1), NOISE_SIGMA, device=obs.device), keys], -1)),
                 images)


@takes_frame_indices
def overlay(obs: torch.Tensor, uniform, images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """Each frame blended with OVERLAY_ALPHA of a random image of OVERLAY_POOL (the shipped backgrounds), in
    every frame of a stack."""
    k, b, h, w = _frame_shape(obs, images)
    pictures = overlay_images(str(obs.device), h, w)
    index = _integers(uniform((b, 1)), len(pictures))
    plan = Plan(overlay=torch.cat([index, torch.full((k, b, 1), OVERLAY_ALPHA, device=obs.device)], -1),
                images=pictures.to(obs.device))
    return apply(obs, plan, images)


@functools.lru_cache(maxsize=4)
def overlay_images(device: str, height: int, width: int) -> torch.Tensor:
    """OVERLAY_POOL as uint8 [M, height, width, 3] on `device`, resized (bilinear) where its size differs."""
    from PIL import Image  # Pillow: the train extra's (pyproject.toml), needed by this augmentation only

    from kage import resources
    folder = resources.data_root() / "assets" / "backgrounds"
    pictures = []
    for name in OVERLAY_POOL:
        with Image.open(folder / name) as image:
            image = image.convert("RGB")
            if image.size != (width, height):
                image = image.resize((width, height), Image.BILINEAR)
            pictures.append(torch.frombuffer(bytearray(image.tobytes()), dtype=torch.uint8).view(height, width, 3))
    return torch.stack(pictures).to(device)


STANDARD = {fn.__name__: fn for fn in (random_shift, random_crop, color_jitter, grayscale, random_conv, cutout_color,
                                       gaussian_noise, overlay)}
__all__ = list(STANDARD)  # what --augment names here: not the helpers beside them
