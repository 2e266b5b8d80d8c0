"""Mixtures: one batch whose environments run several configs (``kage.make_vec([a, b, ...], num_envs,
weights=...)``, ``kage.jax.make_env`` alike). The configs must run one hidden game and render one observation
shape, differing only on visual axes: kagec certifies that (``kage.front_end.certify_mixture``, ``kagec diff
--mixture``) before anything is made.

How the batch is split: config k gets ``floor(N * w_k / W)`` environments (N the batch size, W the sum of the
weights); the ``N - sum(floors)`` environments left over go one each to the configs with the largest remainders
``N * w_k / W - floor(N * w_k / W)``, a tie to the earlier config (the largest-remainder method). The arithmetic
is exact (each weight is the exact value of its float, as ``fractions.Fraction`` reads it), so the split is the
same on every machine. The environments are numbered config by config: config 0's first, then config 1's, and
so on; ``info["config"]`` gives each environment's config index. A config of positive weight that the split
leaves without environments (a batch smaller than its weights ask) runs nowhere: that is warned of (UserWarning).
"""
import math
import os
import warnings
from fractions import Fraction
from typing import List, Sequence, Tuple

import numpy as np


def _number(value) -> bool:
    """A real number that is not a bool (numpy scalars and 0-d arrays too)."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


class WeightsError(ValueError):
    """Weights that are not a mixture's; `index` is the weight at fault, or None where the list as a whole is."""

    def __init__(self, message: str, index=None):
        super().__init__(message)
        self.index = index


def _shown(value, width: int = 40) -> str:
    text = repr(value)
    return text if len(text) <= width else text[:width - 3] + "..."


def _finite(w) -> bool:
    try:
        return math.isfinite(float(w))
    except OverflowError:  # an int beyond float's range
        return False


def weights_of(weights, num_configs: int) -> List[Fraction]:
    """The weights as exact fractions: None gives every config weight 1; else `num_configs` finite
    non-negative numbers, not all zero. WeightsError naming the first that is not."""
    if weights is None:
        return [Fraction(1)] * num_configs
    if isinstance(weights, (str, bytes)) or not hasattr(weights, "__len__"):
        raise WeightsError(f"weights={weights!r:.80}: a list of {num_configs} non-negative numbers, one per config")
    values = list(np.asarray(weights, dtype=object).reshape(-1)) if isinstance(weights, np.ndarray) else list(weights)
    if len(values) != num_configs:
        raise WeightsError(f"weights: {len(values)} given for {num_configs} configs: one weight per config")
    exact = []
    for i, w in enumerate(values):
        if not _number(w):
            raise WeightsError(f"weights[{i}]={_shown(w)}: a number (int or float), one per config", i)
        if not _finite(w) or w < 0:
            raise WeightsError(f"weights[{i}]={_shown(w)}: a finite number >= 0", i)
        exact.append(Fraction(int(w)) if isinstance(w, (int, np.integer)) else Fraction(float(w)))
    if sum(exact) == 0:
        raise WeightsError("weights: all zero; give at least one config a positive weight")
    return exact


def split(num_envs: int, weights: Sequence[Fraction]) -> Tuple[int, ...]:
    """Each config's number of environments (the module's rule): floors of the exact shares, then the rest one
    each by largest remainder, a tie to the earlier config."""
    total = sum(weights)
    shares = [num_envs * w / total for w in weights]
    counts = [math.floor(s) for s in shares]
    left = num_envs - sum(counts)
    by_remainder = sorted(range(len(shares)), key=lambda k: (-(shares[k] - counts[k]), k))
    for k in by_remainder[:left]:
        counts[k] += 1
    return tuple(counts)


def unrun(counts: Sequence[int], weights: Sequence[Fraction]) -> List[int]:
    """The configs of positive weight that a split gave no environment: they would not run at all, which a batch
    too small for its weights does without failing."""
    return [k for k, (n, w) in enumerate(zip(counts, weights)) if n == 0 and w > 0]


def split_warned(num_envs: int, weights: Sequence[Fraction], configs: Sequence[str], caller: str) -> Tuple[int, ...]:
    """split(), warning (UserWarning, at the caller's caller) of the configs it leaves unrun."""
    counts = split(num_envs, weights)
    unrun_configs = unrun(counts, weights)
    if unrun_configs:
        names = ", ".join(f"configs[{k}] {configs[k]!r} (weight {float(weights[k]):g})" for k in unrun_configs)
        warnings.warn(f"{caller}: {num_envs} environments split as {list(counts)} leave {names} none, so "
                      f"{'it runs' if len(unrun_configs) == 1 else 'they run'} nowhere; give more environments or a "
                      "larger weight (kage.mixture gives the rule)", UserWarning, stacklevel=3)
    return counts


def config_index(counts: Sequence[int]) -> np.ndarray:
    """int32 [sum(counts)]: environment i's config (config 0's environments first)."""
    return np.repeat(np.arange(len(counts), dtype=np.int32), counts)


def config_list(configs) -> List[str]:
    """A list of configs as paths (str or os.PathLike each); ValueError for an empty list."""
    values = list(configs)
    if not values:
        raise ValueError("configs: an empty list; give at least one config")
    for i, c in enumerate(values):
        if not isinstance(c, (str, bytes, os.PathLike)):
            raise TypeError(f"configs[{i}]={c!r:.80}: a path (str or os.PathLike) to a YAML config, or a shipped "
                            "config's name")
    return [os.fsdecode(os.fspath(c)) for c in values]


def yaml_configs(paths: Sequence[str]) -> List[str]:
    """`paths` (resolved) when none is a kagec compile directory, which holds no config to certify: ValueError."""
    for p in paths:
        if os.path.isdir(p) and os.path.isfile(os.path.join(p, "manifest.json")):
            raise ValueError(f"{p} is a kagec compile directory: a mixture is certified from its configs' YAML, so give "
                             "the YAML configs it was compiled from")
        if os.path.isdir(p):
            raise ValueError(f"{p} is a directory, not a YAML config: name the config file in it")
    return list(paths)
