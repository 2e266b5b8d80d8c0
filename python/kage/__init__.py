"""kage: KAGE-Env batches for Python, on the CPU or the GPU, without copies between the runtime and the
learner, and the front end's checks of configs and suites.

The package has four layers, each importing only those below it:
- ``kage.util``: files, locks, signals, tables (the bottom layer);
- ``kage`` (this package): the environment API (``make_vec``, ``VecEnv``, ``compile_kernels``, spaces, errors,
  ``kage.front_end``);
- ``kage.ppo``: the PPO-CNN baseline (``python3 -m kage.ppo.train``, ``python3 -m kage.ppo.evaluate``);
- ``kage.bench``: the benchmark runner (``python3 -m kage.bench run|report|score|status|slurm|speed|compare``).

Importing ``kage`` loads neither torch nor the compiled extension: names below load what they need on
first use. Where Gymnasium is importable, it registers ``kage/KAGE-v0`` with it (``kage.registration``).
"""
import importlib

from kage.registration import register_with_gymnasium

register_with_gymnasium()  # gymnasium.make("kage/KAGE-v0", ...), where Gymnasium is importable

# name -> the module that defines it (loaded on first access, PEP 562).
_LAZY = {
    "ConfigError": "kage.errors",
    "ConfigWarning": "kage.errors",
    "Diagnostic": "kage.errors",
    "DeviceUnavailableError": "kage.errors",
    "INFO_FIELDS": "kage.vector",
    "compile_kernels": "kage.kernels",
    "VecEnv": "kage.vector",
    "env_seeds": "kage.vector",
    "make_vec": "kage.vector",
    "step_batches": "kage.vector",
    "DeviceArray": "kage._native",
    "gpu_backend_built": "kage._native",
    "__version__": "kage._version",  # written by CMake (python/CMakeLists.txt) from project(VERSION)
}

__all__ = sorted(_LAZY)


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'kage' has no attribute '{name}'")
    if module == "kage._native":
        from kage._native import native

        value = getattr(native(), name)
    else:
        value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(list(globals()) + list(_LAZY))
