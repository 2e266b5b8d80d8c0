"""The compiled extensions (``kage._kage``, and ``kage._kage_jax`` for kage.jax), loaded where they are first
needed, so that the modules which do not need them (the network, the statistics, the reports) import without a
build."""
import importlib
from types import ModuleType
from typing import Dict

_loaded: Dict[str, ModuleType] = {}


def load_extension(name: str, missing: str) -> ModuleType:
    """The extension `name`, loaded once and told where the runtime headers and NVRTC are; ImportError with
    `missing` (what to do) where it is absent or cannot load."""
    if name not in _loaded:
        try:
            module = importlib.import_module(name)
        except ImportError as e:
            raise ImportError(f"{missing} ({name}: {e})") from e
        from kage import resources  # pure Python: where the runtime headers and NVRTC are

        resources.configure_native(module)
        _loaded[name] = module
    return _loaded[name]


def native() -> ModuleType:
    """``kage._kage`` with the package's exception classes installed; raises ImportError naming the fix."""
    first = "kage._kage" not in _loaded
    module = load_extension("kage._kage", "kage: the compiled extension kage._kage is missing or cannot load; "
                                          "install the package with `pip install .` from the repository (see README, "
                                          "Install)")
    if first:
        from kage import errors  # errors.py is pure Python: no cycle

        module.set_errors(errors.ConfigError, FileNotFoundError, errors.DeviceUnavailableError, ValueError,
                          RuntimeError)
    return module
