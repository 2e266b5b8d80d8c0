"""Where the shipped files are: configs, suites, assets, schemas and the runtime headers that NVRTC
compiles kernels against, and where NVRTC's library is. Pure Python (no torch, no extension).

The shipped files live under one data root with the repository's layout (``configs/``, ``suites/``,
``assets/``, ``schemas/``, ``runtime/``):
- installed (``pip install``): ``<prefix>/share/kagec``, found through the ``kagec`` distribution's file
  list, so a ``--user`` or conda install finds its own;
- imported from a build tree (``PYTHONPATH=build/python``): the source tree the build was made from
  (``_build_info.py``, which CMake writes there and never installs).

A shipped config or suite is addressable by name from any directory: ``throughput/simplest`` is
``configs/throughput/simplest.yaml``, ``kage_bench`` is ``suites/kage_bench.yaml``.
"""
import difflib
import functools
import importlib.metadata
import os
from pathlib import Path
from typing import List, Optional

DISTRIBUTION = "kagec"
# A file every data root has: the runtime's top header.
_MARKER = ("runtime", "kage_hd.h")


def source_root() -> Optional[Path]:
    """The source tree of the build this package was imported from, or None for an installed package."""
    try:
        from kage import _build_info  # written by python/CMakeLists.txt into the build tree only
    except ImportError:
        return None
    return Path(_build_info.source_root)


@functools.lru_cache(maxsize=None)
def data_root() -> Path:
    """The folder holding configs/, suites/, assets/, schemas/ and runtime/; FileNotFoundError naming
    the fix when there is none."""
    root = source_root()
    if root is not None:
        if not root.joinpath(*_MARKER).is_file():
            raise FileNotFoundError(f"kage: this build's source tree {root} is gone (no {'/'.join(_MARKER)}); "
                                    "install the package with pip (README, Install) or rebuild")
        return root
    try:
        dist = importlib.metadata.distribution(DISTRIBUTION)
    except importlib.metadata.PackageNotFoundError:
        raise FileNotFoundError(f"kage: the '{DISTRIBUTION}' distribution is not installed, so its shipped files "
                                "(configs, runtime headers) cannot be found: `pip install .` from the repository "
                                "(README, Install)") from None
    wanted = ("share", "kagec") + _MARKER
    for f in dist.files or []:
        if tuple(f.parts[-len(wanted):]) == wanted:
            return Path(dist.locate_file(f)).resolve().parents[1]
    raise FileNotFoundError(f"kage: the installed '{DISTRIBUTION}' {dist.version} lists no "
                            f"share/kagec/{'/'.join(_MARKER)}: reinstall it (pip install --force-reinstall)")


def runtime_include_dir() -> str:
    """The folder whose runtime/ holds the headers generated kernels include (kagec's include root)."""
    return str(data_root())


def _names(folder: Path) -> List[str]:
    return sorted(p.relative_to(folder).with_suffix("").as_posix() for p in folder.rglob("*.yaml"))


def _shipped(kind: str, value: str) -> str:
    """`value` if it names an existing file or folder, else the shipped kind/<value>.yaml."""
    if os.path.exists(value):
        return value
    folder = data_root() / kind
    name = value[:-5] if value.endswith(".yaml") else value
    if name.startswith(f"{kind}/"):  # "configs/throughput/simplest" from another directory
        name = name[len(kind) + 1:]
    path = folder / f"{name}.yaml"
    if path.is_file():
        return str(path)
    if name and (folder / name).is_dir():  # a folder of shipped ones: name one of them
        inside = [f"{name}/{n}" for n in _names(folder / name)]
        raise FileNotFoundError(f"{kind[:-1]} '{value}' is a folder of shipped {kind}, not one: name one of them "
                                f"({', '.join(inside[:8])}{', ...' if len(inside) > 8 else ''})")
    names = _names(folder)
    near = difflib.get_close_matches(name, names, n=5, cutoff=0.5)
    hint = f"; near names: {', '.join(near)}" if near else f"; shipped {kind}: {', '.join(names[:8])}, ..."
    raise FileNotFoundError(f"{kind[:-1]} '{value}' is neither a path nor a shipped {kind[:-1]} name "
                            f"(looked in {folder}){hint}")


def config_path(value: str) -> str:
    """A config given as a path (YAML file or kagec compile folder), or as a shipped config's name
    (``throughput/simplest``, ``kage_bench/bases/shape_black``): the path to open."""
    return _shipped("configs", os.fspath(value))


def suite_path(value: str) -> str:
    """A suite manifest given as a path or as a shipped suite's name (``kage_bench``): the path to open."""
    return _shipped("suites", os.fspath(value))


def nvrtc_dirs() -> List[str]:
    """The library folders of an installed nvidia-cuda-nvrtc wheel (libnvrtc.so.*), searched before the
    system's CUDA toolkit; empty without the wheel."""
    try:
        dist = importlib.metadata.distribution("nvidia-cuda-nvrtc")
    except importlib.metadata.PackageNotFoundError:
        return []
    dirs = {str(Path(dist.locate_file(f)).parent) for f in dist.files or [] if f.name.startswith("libnvrtc.so")}
    return sorted(dirs)


def configure_native(module) -> None:
    """Tells the extension ``kage._kage`` where the runtime headers and NVRTC are: it lives in
    site-packages, away from both."""
    module.set_runtime_include_dir(runtime_include_dir())
    module.set_nvrtc_dirs(nvrtc_dirs())
