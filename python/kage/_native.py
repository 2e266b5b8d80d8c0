"""The compiled extension ``kage._kage``, loaded where it is first needed, so that the modules which do not
need it (the network, the statistics, the reports) import without a build."""
import importlib
from types import ModuleType
from typing import Optional

_module: Optional[ModuleType] = None


def native() -> ModuleType:
    """``kage._kage`` with the package's exception classes installed; raises ImportError naming the fix."""
    global _module
    if _module is None:
        try:
            module = importlib.import_module("kage._kage")
        except ImportError as e:
            raise ImportError(f"kage: the compiled extension kage._kage is missing or cannot load ({e}); install "
                              "the package with `pip install .` from the repository (see README, Install)") from e
        from kage import errors  # errors.py is pure Python: no cycle

        module.set_errors(errors.ConfigError, FileNotFoundError, errors.DeviceUnavailableError, ValueError,
                          RuntimeError)
        from kage import resources  # pure Python: where the runtime headers and NVRTC are

        resources.configure_native(module)
        _module = module
    return _module
