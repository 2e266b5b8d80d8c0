"""A plug-in agent for the tests (--agent lone_agent:make): a plain one-run network without `packable`,
so kage.bench run --pack trains its runs one at a time."""
import torch
import torch.nn as nn


class TinyNet(nn.Module):
    def __init__(self, observation_shape, num_actions: int):
        super().__init__()
        height, width, channels = observation_shape
        self.torso = nn.Sequential(nn.Conv2d(channels, 8, 8, stride=8), nn.ReLU(), nn.Flatten(),
                                   nn.Linear(8 * (height // 8) * (width // 8), 32), nn.ReLU())
        self.actor, self.critic = nn.Linear(32, num_actions), nn.Linear(32, 1)

    def forward(self, obs: torch.Tensor):
        hidden = self.torso(obs.permute(0, 3, 1, 2).float() / 255.0)
        return self.actor(hidden), self.critic(hidden).squeeze(-1)


def make(observation_shape, num_actions, seeds, device):
    return TinyNet(observation_shape, num_actions).to(device)


def wrong_shape(observation_shape, num_actions, seeds, device):
    """A network whose logits miss the batch axis: refused with the expected shapes."""
    net = make(observation_shape, num_actions, seeds, device)
    forward = net.forward
    net.forward = lambda obs: (forward(obs)[0][0], forward(obs)[1])
    return net
