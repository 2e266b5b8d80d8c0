"""The PPO-CNN baseline's network and action distribution (kage-ppo-baseline.md §1), for a pack of K runs
(K = 1 for a lone run): each run owns one group of every grouped convolution and one matrix of every
batched linear layer, so one pass per layer evaluates all K."""
import math
from typing import List, Optional

import torch
import torch.nn as nn
import torch.nn.functional as F

from kage.ppo.fast.space_to_depth import weight_space_to_depth


def orthogonal(out_features: int, in_features: int, gain: float, device) -> torch.Tensor:
    """An orthogonal [out, in] matrix with gain `gain` (§1.3), drawn from torch's generator of `device`."""
    weight = torch.empty(out_features, in_features, device=device)
    nn.init.orthogonal_(weight, gain)
    return weight


def frames_at(frames: torch.Tensor, images: Optional[torch.Tensor]) -> torch.Tensor:
    """uint8 frames [..., H, W, C] at int64 images [K, B] -> [K, B, H, W, C] (frames as they are without images)."""
    return frames if images is None else frames.reshape(-1, *frames.shape[-3:])[images]


class Agent(nn.Module):
    """K agents (a pack; K = 1 for a lone run): NatureCNN torsos without padding, a 512-unit layer and two
    linear heads each (§1.2). Run k owns the k-th group of every grouped convolution and the k-th matrix of
    every batched linear layer, so one pass per layer evaluates all K."""

    # forward(frames, images) reads a minibatch where the rollout stored it (kage.ppo.plugins).
    takes_frame_indices = True

    def __init__(self, seeds: List[int], channels: int = 3, height: int = 128, width: int = 128, device="cpu",
                 num_actions: int = 8, *, bf16: bool = False, channels_last: bool = False, fused_input: bool = False,
                 triton_conv: bool = False):
        """The speed modes (--bf16, --channels-last, --fused-input, --triton-conv) change how the same parameters
        are computed with, never the parameters: a checkpoint loads under any of them."""
        super().__init__()
        k = self.runs = len(seeds)
        self.conv1 = nn.Conv2d(k * channels, k * 32, 8, stride=4, groups=k, device=device)
        self.conv2 = nn.Conv2d(k * 32, k * 64, 4, stride=2, groups=k, device=device)
        self.conv3 = nn.Conv2d(k * 64, k * 64, 3, stride=1, groups=k, device=device)
        conv_h, conv_w = ((height - 8) // 4 + 1 - 4) // 2 + 1 - 2, ((width - 8) // 4 + 1 - 4) // 2 + 1 - 2
        self.conv3_positions = conv_h * conv_w
        self.flat = 64 * self.conv3_positions
        self.fc_weight = nn.Parameter(torch.empty(k, self.flat, 512, device=device))
        self.fc_bias = nn.Parameter(torch.zeros(k, 1, 512, device=device))
        self.actor_weight = nn.Parameter(torch.empty(k, 512, num_actions, device=device))
        self.actor_bias = nn.Parameter(torch.zeros(k, 1, num_actions, device=device))
        self.critic_weight = nn.Parameter(torch.empty(k, 512, 1, device=device))
        self.critic_bias = nn.Parameter(torch.zeros(k, 1, 1, device=device))
        self.input_dtype = torch.bfloat16 if bf16 else torch.float32
        # The torso's one implementation for this network: cuDNN on the frames, cuDNN on 4x4 blocks (--fused-input),
        # or kage.ppo.fast.triton_conv's kernels on 4x4 blocks (--triton-conv, which needs --fused-input).
        self._torso = self._torso_triton if triton_conv else self._torso_blocks if fused_input else self._torso_frames
        self._fc_weight = self._fc_weight_positions_first if triton_conv else lambda: self.fc_weight
        with torch.no_grad():
            for run, seed in enumerate(seeds):
                self._initialise(run, seed, channels)
        if channels_last:
            self.to(memory_format=torch.channels_last)

    def _initialise(self, run: int, seed: int, channels: int) -> None:
        """§1.3: orthogonal weights (gain sqrt 2 in the torso, 0.01 actor, 1 critic), zero biases; from the
        run's seed, so a run starts the same alone or packed."""
        torch.manual_seed(seed)
        for conv, in_channels in ((self.conv1, channels), (self.conv2, 32), (self.conv3, 64)):
            out, _, kh, kw = conv.weight.shape
            out //= self.runs
            group = conv.weight.view(self.runs, out, in_channels, kh, kw)[run]
            group.copy_(orthogonal(out, in_channels * kh * kw, math.sqrt(2), group.device).view_as(group))
            conv.bias.view(self.runs, out)[run].zero_()
        for weight, gain in ((self.fc_weight, math.sqrt(2)), (self.actor_weight, 0.01), (self.critic_weight, 1.0)):
            weight[run].copy_(orthogonal(weight.shape[2], weight.shape[1], gain, weight.device).T)

    def forward(self, obs: torch.Tensor, images: Optional[torch.Tensor] = None):
        """uint8 [K, B, H, W, C] frames -> logits [K, B, A] and values [K, B]; with int64 images [K, B], run k's
        b-th frame is obs.reshape(-1, H, W, C)[images[k, b]] (a minibatch of the rollout buffer: --triton-conv
        reads it there, the other torsos gather it). The first operation is the conversion to float32 divided
        by 255 (§1.1); the runs' frames meet as channel groups (under --triton-conv as a batch index)."""
        hidden = F.relu(torch.baddbmm(self.fc_bias, self._torso(obs, images), self._fc_weight()))
        # The heads always in float32, even under --bf16: values reach thousands (an untrained episode
        # returns about -3,900), where bfloat16's spacing is 16, more than a step's reward; rounded values
        # would bury the advantages in noise.
        with torch.autocast(hidden.device.type, enabled=False):
            hidden = hidden.float()
            logits = torch.baddbmm(self.actor_bias, hidden, self.actor_weight)
            value = torch.baddbmm(self.critic_bias, hidden, self.critic_weight).squeeze(-1)
        return logits, value

    def _torso_frames(self, obs: torch.Tensor, images: Optional[torch.Tensor]) -> torch.Tensor:
        """The three convolutions on the frames, the runs as channel groups: [K, B, H, W, C] -> [K, B, flat]."""
        obs = frames_at(obs, images)
        k, b, h, w, c = obs.shape
        x = F.relu(self.conv1(self._input(obs.permute(1, 2, 3, 0, 4).reshape(b, h, w, k * c))))
        return self._conv2_conv3(x, k, b)

    def _torso_blocks(self, obs: torch.Tensor, images: Optional[torch.Tensor]) -> torch.Tensor:
        """As _torso_frames, conv1 on the frames cut into 4x4 blocks (--fused-input)."""
        obs = frames_at(obs, images)
        k, b = obs.shape[:2]
        return self._conv2_conv3(F.relu(self._conv1_space_to_depth(obs)), k, b)

    def _conv2_conv3(self, x: torch.Tensor, k: int, b: int) -> torch.Tensor:
        x = F.relu(self.conv3(F.relu(self.conv2(x))))
        return x.reshape(b, k, self.flat).transpose(0, 1)  # each run's (channel, row, column) flatten

    def _input(self, frames: torch.Tensor) -> torch.Tensor:
        """uint8 [B, H, W, C'] -> [B, C', H, W] / 255 in the input dtype, channels last when the weights are.
        Under --bf16 the conversion goes straight to bfloat16: uint8 values are exact there, and x / 255
        rounds to the bfloat16 that autocast would make of the float32 quotient (one pass, half the bytes)."""
        x = frames.permute(0, 3, 1, 2)
        if not self.conv1.weight.is_contiguous(memory_format=torch.channels_last):
            x = x.contiguous()
        return x.to(self.input_dtype).div_(255.0)

    def _conv1_space_to_depth(self, obs: torch.Tensor) -> torch.Tensor:
        """conv1 (8x8, stride 4, C channels) as the equal 2x2, stride-1 convolution of the frames cut into
        4x4 blocks of 16 C channels: the same products and sums (row 4a + p, column 4b + q of a filter
        meets channel (c, p, q) at offset (a, b)), but 48 channels a group instead of 3, which the
        convolution kernels use far better. The rearrangement is the same single copy the frames need
        anyway (--fused-input)."""
        k, b, h, w, c = obs.shape
        h, w = h // 4 * 4, w // 4 * 4  # rows and columns past the last whole block are never read
        blocks = obs[:, :, :h, :w].reshape(k, b, h // 4, 4, w // 4, 4, c).permute(1, 2, 4, 0, 6, 3, 5)
        x = self._input(blocks.reshape(b, h // 4, w // 4, k * c * 16))
        weight = weight_space_to_depth(self.conv1.weight, 4)
        if self.conv1.weight.is_contiguous(memory_format=torch.channels_last):
            weight = weight.contiguous(memory_format=torch.channels_last)
        return F.conv2d(x, weight, self.conv1.bias, stride=1, groups=k)

    def _torso_triton(self, obs: torch.Tensor, images: Optional[torch.Tensor]) -> torch.Tensor:
        """The three convolutions on kage.ppo.fast.triton_conv's kernels (--triton-conv): the runs as a batch index
        instead of channel groups, activations [K, B, H, W, C], the same parameters; conv1 on the minibatch's
        uint8 frames gathered into 4 x 4 blocks, the 1 / 255 in its weight. Returns [K, B, flat] in each run's
        (row, column, channel) order, as conv3's kernel stores it (_fc_weight_positions_first matches it)."""
        from kage.ppo.fast import triton_conv  # here, not at the top: triton is needed only under the flag
        if images is None:
            images = torch.arange(obs.shape[0] * obs.shape[1], device=obs.device).view(obs.shape[:2])
        k, b = images.shape
        x = triton_conv.packed_conv_frames(obs, images, self.conv1.weight, self.conv1.bias, 4, self.input_dtype,
                                           relu=True)
        x = triton_conv.packed_conv(x, self.conv2.weight, self.conv2.bias, stride=2, relu=True)
        x = triton_conv.packed_conv(x, self.conv3.weight, self.conv3.bias, relu=True)
        return x.reshape(k, b, self.flat)

    def _fc_weight_positions_first(self) -> torch.Tensor:
        """fc_weight [K, flat, 512] with its rows in the (row, column, channel) order of _torso_triton's output,
        in the compute dtype: the parameter keeps each run's (channel, row, column) flatten order (checkpoints
        do not change), and this one copy of the weight, which is also the cast that autocast would make,
        replaces a copy of the activations forward and another of their gradient backward."""
        k, _, units = self.fc_weight.shape
        rows = self.fc_weight.view(k, 64, self.conv3_positions, units).transpose(1, 2)
        copy = torch.empty(rows.shape, dtype=self.input_dtype, device=rows.device).copy_(rows)  # one pass
        return copy.view(k, self.flat, units)

    def run_view(self, tensor: torch.Tensor) -> torch.Tensor:
        """A tensor shaped like a parameter (the parameter, its gradient, an Adam moment) as [K, ...]: the
        leading axis split into the runs' parts, whatever the memory format."""
        return tensor.unflatten(0, (self.runs, -1))


def nature_cnn(observation_shape, num_actions: int, seeds: List[int], device, **speed) -> Agent:
    """The baseline's network as a kage.ppo.plugins agent factory (the default of --agent); `speed`: the
    keyword arguments of Agent's speed modes."""
    height, width, channels = observation_shape
    return Agent(seeds, channels, height, width, device, num_actions, **speed)


nature_cnn.packable = True
