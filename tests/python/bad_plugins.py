"""Plug-ins that break the contract (kage.ppo.plugins), each refused before the trainer writes anything
(tests/python/test_checks_before_writing.py), or, drawing from a global random generator, warned of
(tests/python/test_plugins.py); one fails only on real frames, in training (a run that stops before its first
checkpoint, started over when rerun with another augmentation)."""
import numpy as np
import torch
import torch.nn as nn


def float_frames(obs, uniform):
    return obs.float() / 255  # frames in [0, 1]: the network would divide by 255 twice


def nothing(obs, uniform):
    return None


def wrong_shape(obs, uniform):
    return obs[..., :64, :, :]


def fewer_rows(obs, uniform):
    return obs[:, :1]


def other_device(obs, uniform):
    return obs.to("meta")


def raises(obs, uniform):
    raise RuntimeError("this augmentation is broken")


def exits(obs, uniform):
    raise SystemExit(3)


def ignores_images(obs, uniform, images=None):
    return obs  # the frame store itself, not the frames at `images`


ignores_images.takes_frame_indices = True


def raises_on_real_frames(obs, uniform):
    """Passes the check on blank frames, then fails in the first update."""
    if obs.any():
        raise ValueError("not on real frames")
    return obs


class NoParameters(nn.Module):
    def forward(self, obs):
        return torch.zeros((*obs.shape[:-3], 8)), torch.zeros(obs.shape[:-3])


def no_parameters(observation_shape, num_actions, seeds, device):
    return NoParameters()


def integer_logits(observation_shape, num_actions, seeds, device):
    """A network whose outputs are integers: refused, as PPO needs floating-point logits and values."""
    class Net(nn.Module):
        def __init__(self):
            super().__init__()
            self.w = nn.Parameter(torch.zeros(()))

        def forward(self, obs):
            return torch.zeros((obs.shape[0], num_actions), dtype=torch.long), torch.zeros(obs.shape[0], dtype=torch.long)
    return Net()


def global_torch_noise(obs, uniform):
    """Draws from torch's global generator, not `uniform`: accepted, with a warning that it will not reproduce."""
    return (obs.float() + torch.rand(obs.shape) * 8).clamp(0, 255).to(torch.uint8)


def global_numpy_flip(obs, uniform):
    return obs.flip(-2) if np.random.rand() < 0.5 else obs
