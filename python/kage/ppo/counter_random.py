"""Counter-based random numbers for the trainer: each value is a pure function of (run key, stream,
counter, index), computed with integer tensor operations on the device.

Why not torch.Generator: K packed runs need K independent streams, and K generators mean K launches per
draw; these draw for all K runs in one set of elementwise operations. A run draws the same numbers
alone or packed with others, resumes without saving a generator state (the counter is a function of
the iteration), and a draw can sit inside a captured CUDA graph (the counter is a device tensor).

The mixing function is a 32-bit integer hash (two rounds of xor-shift-multiply, constant 0x45d9f3b)
applied to the key, the stream and counter, then the element index; every product stays below 2**59, so
int64 arithmetic never overflows.
"""
from typing import Sequence

import numpy as np
import torch

_MASK = 0xFFFFFFFF
_MULTIPLIER = 0x45D9F3B
_GOLDEN = 0x9E3779B9


def mix32(x: torch.Tensor) -> torch.Tensor:
    """A bijective hash of int64 values in [0, 2**32)."""
    x = (((x >> 16) ^ x) * _MULTIPLIER) & _MASK
    x = (((x >> 16) ^ x) * _MULTIPLIER) & _MASK
    return (x >> 16) ^ x


class CounterRandom:
    """Independent streams for a batch of runs (or of evaluations), one key each from a seed."""

    def __init__(self, seeds: Sequence[int], device):
        words = np.array([np.random.SeedSequence(s).generate_state(2, dtype=np.uint32) for s in seeds], dtype=np.int64)
        self.keys = torch.as_tensor(words, device=device)  # [K, 2]
        self.device = torch.device(device)

    def bits(self, stream: int, counter: torch.Tensor, shape: Sequence[int]) -> torch.Tensor:
        """[K, *shape] int64 values in [0, 2**32) for `stream` at `counter` (a 0-d int64 tensor)."""
        base = mix32(self.keys[:, 0] ^ mix32((counter & _MASK) ^ ((stream * _GOLDEN) & _MASK)))
        base = mix32(base ^ self.keys[:, 1] ^ ((counter >> 32) & _MASK))
        count = int(np.prod(shape))
        index = torch.arange(count, device=self.device, dtype=torch.int64)
        return mix32(mix32(base[:, None] ^ index) ^ base[:, None]).view(-1, *shape)

    def uniform(self, stream: int, counter: torch.Tensor, shape: Sequence[int]) -> torch.Tensor:
        """[K, *shape] float32 in (0, 1): 24 random bits, centred in their interval."""
        return ((self.bits(stream, counter, shape) >> 8).float() + 0.5) * (1.0 / (1 << 24))

    def permutation(self, stream: int, counter: torch.Tensor, n: int) -> torch.Tensor:
        """[K, n] int64: one random permutation of range(n) per key (ties broken by the index)."""
        assert n <= 1 << 20, "the sort keys hold 20 index bits"
        keys = (self.bits(stream, counter, (n,)) << 20) | torch.arange(n, device=self.device, dtype=torch.int64)
        return torch.argsort(keys, dim=1)
