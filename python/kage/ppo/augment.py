"""The example agent shipped beside the baseline: the baseline's network trained on randomly shifted
frames (`--augment kage.ppo.augment:random_shift`), the common image augmentation for pixel RL (pad by 4
pixels, replicating the border, then crop back to the frame size at a random offset; DrQ, RAD)."""
import torch

PAD = 4  # pixels of shift at most, each way


def random_shift(obs: torch.Tensor, uniform) -> torch.Tensor:
    """uint8 [K, B, H, W, C] -> the same frames, each shifted by its own offset in [-PAD, PAD] per axis.
    A border pixel repeats into the vacated rows and columns (replicate padding, then the crop), written
    as a gather of clamped indices so that no padded copy is made."""
    k, b, h, w, _ = obs.shape
    offsets = (uniform((b, 2)) * (2 * PAD + 1)).long().clamp(max=2 * PAD) - PAD  # [K, B, 2]
    rows = (torch.arange(h, device=obs.device) + offsets[..., 0, None]).clamp(0, h - 1)  # [K, B, H]
    cols = (torch.arange(w, device=obs.device) + offsets[..., 1, None]).clamp(0, w - 1)  # [K, B, W]
    runs = torch.arange(k, device=obs.device)[:, None, None, None]
    batch = torch.arange(b, device=obs.device)[None, :, None, None]
    return obs[runs, batch, rows[..., :, None], cols[..., None, :]]
