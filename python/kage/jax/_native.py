"""The extension ``kage._kage_jax``, loaded on first use and told where the runtime headers and NVRTC are (as
``kage._kage`` is, by kage._native)."""
from types import ModuleType

from kage._native import load_extension


def module() -> ModuleType:
    """``kage._kage_jax``; raises ImportError naming the fix."""
    return load_extension("kage._kage_jax", "kage.jax: the extension kage._kage_jax is missing or cannot load; it is "
                                            "built only where the build's Python can import JAX: install jax, then "
                                            "build or install kage again (pip install . from the repository; see "
                                            "README, JAX)")
