"""GPU kernels compiled ahead of the batches that run them: ``kage.compile_kernels(configs)``.

A config's kernels are generated for it and compiled by NVRTC, tens of seconds a config, when its first GPU batch
opens, one config after another; the kernel cache keeps them for every later batch and process. A learner that
opens batches of many configs at once (a pack of runs evaluated on ten configs) compiles them side by side first.
"""
import os
from typing import Dict, Optional, Sequence, Union

from kage import resources
from kage._native import native


def compile_kernels(configs: Sequence[Union[str, os.PathLike]], asset_root: Optional[str] = None) -> Dict[str, int]:
    """Compiles the GPU kernels of ``configs`` (YAML configs, or shipped configs' names) for this machine's GPU into
    the kernel cache (``$KAGE_CACHE_DIR``, else ``~/.cache/kagec``), several configs at once (one per core, up to
    16), so that ``kage.make_vec(..., device="cuda")`` then opens their batches from the cache. A config named
    twice is compiled once; ``kagec compile`` directories are left out (their batches load their own files).
    ``asset_root`` resolves the configs as ``make_vec`` does.

    Returns ``{"compiled": n, "cached": m}``: how many configs NVRTC compiled and how many the cache held. Every
    config is read before anything compiles: raises ``kage.ConfigError`` (kagec's located diagnostics) for a
    config with errors, ``FileNotFoundError`` for a missing one, then ``RuntimeError`` without a usable GPU."""
    if isinstance(configs, (str, bytes, os.PathLike)):
        raise TypeError(f"compile_kernels(configs={configs!r:.80}): a list of configs, e.g. [path] for one")
    paths = [resources.config_path(os.fspath(c)) for c in configs]
    if asset_root is not None:
        asset_root = os.fsdecode(asset_root)
    compiled, cached = native().compile_kernels([p for p in paths if not os.path.isdir(p)], asset_root or "")
    return {"compiled": compiled, "cached": cached}
