"""The baseline's optional observation and reward wrappers (kage-ppo-baseline.md §1.1, §2.2; the original's
FrameStackWrapper and RewardNormalizeWrapper), as batched device tensors. Both are off by default."""
import torch


class FrameStack:
    """The last 4 frames on the channel axis, oldest first; refilled with the new frame at reset and
    wherever an episode ended (§1.1)."""

    def __init__(self, frame: torch.Tensor, frames: int = 4):
        """`frame`: [..., H, W, C] uint8."""
        self.frames = frames
        self.stack = self._refill(frame)

    def _refill(self, frame: torch.Tensor) -> torch.Tensor:
        return frame.repeat(*[1] * (frame.dim() - 1), self.frames)

    def restart(self, index: int, frame: torch.Tensor) -> None:
        """Refills stack `index` (of the leading axis) with `frame`: its environments start anew."""
        self.stack[index] = self._refill(frame)

    def push(self, frame: torch.Tensor, done: torch.Tensor) -> torch.Tensor:
        """Appends `frame`; `done` ([...], 0/1) marks the environments whose episode just ended."""
        c = frame.shape[-1]
        self.stack = torch.cat([self.stack[..., c:], frame], dim=-1)
        self.stack = torch.where(done.bool()[..., None, None, None], self._refill(frame), self.stack)
        return self.stack


class RewardNormalizer:
    """Per-environment running return statistics, as RewardNormalizeWrapper(gamma=0.999) (§2.2, kage-env
    10.4): ret = ret * gamma * (1 - done) + r, Welford-style mean/var, emits r / (sqrt(var) + 1e-8)."""

    def __init__(self, shape, gamma: float, device):
        """`shape`: the reward's, one statistic per environment."""
        self.gamma = gamma
        self.ret = torch.zeros(shape, device=device)
        self.mean = torch.zeros(shape, device=device)
        self.var = torch.ones(shape, device=device)
        self.count = torch.full(shape, 1e-4, device=device)

    def __call__(self, reward: torch.Tensor, done: torch.Tensor) -> torch.Tensor:
        self.ret = self.ret * self.gamma * (1 - done) + reward
        delta = self.ret - self.mean
        count = self.count + 1
        mean = self.mean + delta / count
        self.var = (self.var * self.count + delta * (self.ret - mean)) / count
        self.mean, self.count = mean, count
        return reward / (torch.sqrt(self.var) + 1e-8)

    def state_dict(self) -> dict:
        return {k: getattr(self, k) for k in ("ret", "mean", "var", "count")}

    def load_state_dict(self, state: dict) -> None:
        for k, v in state.items():
            setattr(self, k, v)
