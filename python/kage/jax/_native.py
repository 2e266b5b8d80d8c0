"""The extension ``kage._kage_jax``, loaded on first use and told where the runtime headers and NVRTC
are (as ``kage._kage`` is)."""
import importlib
from types import ModuleType
from typing import Optional

from kage import resources

_module: Optional[ModuleType] = None


def module() -> ModuleType:
    """``kage._kage_jax``; raises ImportError naming the fix."""
    global _module
    if _module is None:
        try:
            loaded = importlib.import_module("kage._kage_jax")
        except ImportError as e:
            raise ImportError(
                f"kage.jax: the extension kage._kage_jax is missing or cannot load ({e}); it is built only where "
                "the build's Python can import JAX: install jax, then build or install kage again "
                "(pip install . from the repository; see README, JAX)") from e
        resources.configure_native(loaded)
        _module = loaded
    return _module
