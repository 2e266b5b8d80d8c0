"""Plug-ins for the augmentation modes' tests (tests/python/test_augment_modes.py): an augmentation that marks
the frames it returns, and a packable network that records, for every call, how many frames it saw, how many
carried the mark, and whether a gradient was being taken (an update) or not (a rollout, a bootstrap value or an
evaluation); and one that returns a view of its input."""
import torch
import torch.nn as nn

MARK = torch.tensor([1, 254, 3, 252, 5, 250], dtype=torch.uint8)  # the first row's first 6 bytes of a marked frame
calls = []  # (frames, marked frames, gradient enabled) per forward call


def mark(obs, uniform):
    uniform((obs.shape[1],))  # as an augmentation draws
    out = obs.clone()
    out[..., 0, :2, :3] = MARK.to(obs.device).view(2, 3)
    return out


def transposed(obs, uniform):
    """A valid augmentation (square frames keep their shape) whose result is a view of its input."""
    return obs.transpose(-3, -2)


def is_marked(frames: torch.Tensor) -> torch.Tensor:
    return (frames[..., 0, :2, :3].reshape(*frames.shape[:-3], 6) == MARK.to(frames.device)).all(-1)


class Recorder(nn.Module):
    """K runs of logits = a * m and value = b * m per frame, m the frame's mean byte over 255."""

    takes_frame_indices = False

    def __init__(self, runs: int, num_actions: int):
        super().__init__()
        self.runs = runs
        self.a = nn.Parameter(torch.linspace(-1, 1, num_actions).repeat(runs, 1))
        self.b = nn.Parameter(torch.ones(runs, 1))

    def forward(self, obs):
        calls.append((obs.shape[0] * obs.shape[1], int(is_marked(obs).sum()), torch.is_grad_enabled()))
        m = obs.float().mean((-3, -2, -1)) / 255  # [K, B]
        return m[..., None] * self.a[:, None, :], m * self.b

    def run_view(self, tensor):
        return tensor.unflatten(0, (self.runs, -1))


def make(observation_shape, num_actions, seeds, device):
    return Recorder(len(seeds), num_actions).to(device)


make.packable = True
