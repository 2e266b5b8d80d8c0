"""The observation and action spaces and the autoreset mode: Gymnasium's when it is importable, else objects
with the same ``shape``, ``dtype``, ``n``, ``low``, ``high``, ``sample()`` and ``contains()``, and the mode's
value."""
from typing import Optional, Tuple

import numpy as np

try:  # pragma: no cover - depends on the interpreter
    from gymnasium import spaces as _gym_spaces
    from gymnasium.vector import AutoresetMode
except ImportError:
    _gym_spaces = AutoresetMode = None

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


def observation_space(height: int, width: int):
    """Box(0, 255, (height, width, 3), uint8), spec 10.1."""
    if _gym_spaces is not None:
        return _gym_spaces.Box(0, 255, (height, width, 3), np.uint8)
    return Box(0, 255, (height, width, 3), np.uint8)


def action_space():
    """Discrete(8): bit 0 left, bit 1 right, bit 2 jump (spec 3.2)."""
    return _gym_spaces.Discrete(8) if _gym_spaces is not None else Discrete(8)
