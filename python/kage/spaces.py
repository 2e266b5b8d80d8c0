"""The observation and action spaces, the autoreset mode and the vector environment's base class: Gymnasium's
when it is importable (so that its vector wrappers take a kage.VecEnv), else objects with the same ``shape``,
``dtype``, ``n``/``nvec``, ``low``, ``high``, ``sample()`` and ``contains()``, the mode's value and ``object``."""
from typing import Optional, Tuple

import numpy as np

try:  # pragma: no cover - depends on the interpreter
    from gymnasium import spaces as _gym_spaces
    from gymnasium.vector import AutoresetMode, VectorEnv as VectorEnvBase
    from gymnasium.vector.utils import batch_space as _gym_batch_space
except ImportError:
    _gym_spaces = AutoresetMode = _gym_batch_space = None
    VectorEnvBase = object

#: VecEnv's autoreset mode: Gymnasium's enum where it is importable, else its value.
SAME_STEP = AutoresetMode.SAME_STEP if AutoresetMode is not None else "SameStep"


class Box:
    """A box of ``dtype`` values between ``low`` and ``high`` (Gymnasium's ``Box``, reduced)."""

    def __init__(self, low: int, high: int, shape: Tuple[int, ...], dtype=np.uint8):
        self.shape = tuple(shape)
        self.dtype = np.dtype(dtype)
        self.low = np.full(self.shape, low, dtype=self.dtype)
        self.high = np.full(self.shape, high, dtype=self.dtype)
        self._rng = np.random.default_rng()

    def seed(self, seed: Optional[int] = None) -> None:
        self._rng = np.random.default_rng(seed)

    def sample(self) -> np.ndarray:
        return self._rng.integers(self.low, self.high, endpoint=True, dtype=self.dtype)

    def contains(self, x) -> bool:
        x = np.asarray(x)
        return x.shape == self.shape and x.dtype == self.dtype and bool(np.all((x >= self.low) & (x <= self.high)))

    def __repr__(self) -> str:
        return f"Box({self.low.flat[0]}, {self.high.flat[0]}, {self.shape}, {self.dtype})"


class Discrete:
    """The integers 0 .. n-1 (Gymnasium's ``Discrete``, reduced)."""

    def __init__(self, n: int):
        self.n = int(n)
        self.shape = ()
        self.dtype = np.dtype(np.int64)
        self._rng = np.random.default_rng()

    def seed(self, seed: Optional[int] = None) -> None:
        self._rng = np.random.default_rng(seed)

    def sample(self) -> int:
        return int(self._rng.integers(self.n))

    def contains(self, x) -> bool:
        return np.ndim(x) == 0 and np.issubdtype(np.asarray(x).dtype, np.integer) and 0 <= int(x) < self.n

    def __repr__(self) -> str:
        return f"Discrete({self.n})"


class MultiDiscrete:
    """A vector of integers, element i in 0 .. nvec[i]-1 (Gymnasium's ``MultiDiscrete``, reduced): a batch's
    actions."""

    def __init__(self, nvec):
        self.nvec = np.asarray(nvec, dtype=np.int64)
        self.shape = self.nvec.shape
        self.dtype = np.dtype(np.int64)
        self._rng = np.random.default_rng()

    def seed(self, seed: Optional[int] = None) -> None:
        self._rng = np.random.default_rng(seed)

    def sample(self) -> np.ndarray:
        return self._rng.integers(self.nvec)

    def contains(self, x) -> bool:
        x = np.asarray(x)
        return x.shape == self.shape and np.issubdtype(x.dtype, np.integer) and bool(np.all((x >= 0) & (x < self.nvec)))

    def __repr__(self) -> str:
        return f"MultiDiscrete({self.nvec.tolist()})"


def batched(space, num_envs: int):
    """The space of ``num_envs`` draws of ``space`` (Gymnasium's ``batch_space``): a VecEnv's
    ``observation_space`` and ``action_space``."""
    if _gym_batch_space is not None:
        return _gym_batch_space(space, num_envs)
    if isinstance(space, Discrete):
        return MultiDiscrete([space.n] * num_envs)
    return Box(int(space.low.flat[0]), int(space.high.flat[0]), (num_envs, *space.shape), space.dtype)


def observation_space(height: int, width: int):
    """Box(0, 255, (height, width, 3), uint8), spec 10.1."""
    if _gym_spaces is not None:
        return _gym_spaces.Box(0, 255, (height, width, 3), np.uint8)
    return Box(0, 255, (height, width, 3), np.uint8)


def action_space():
    """Discrete(8): bit 0 left, bit 1 right, bit 2 jump (spec 3.2)."""
    return _gym_spaces.Discrete(8) if _gym_spaces is not None else Discrete(8)
