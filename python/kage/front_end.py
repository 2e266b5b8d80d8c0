"""kagec's front end from Python: a config resolved to its Spec, a train/eval pair certified, a suite's
report. Each returns the JSON that ``kagec resolve``, ``kagec diff --certify`` and ``kagec suite`` print,
parsed, and raises ``kage.ConfigError`` with kagec's located diagnostics when the input has errors."""
import json
import os
from typing import Optional, Union

from kage._native import native

Path = Union[str, os.PathLike]


def resolve(config: Path, asset_root: Optional[str] = None) -> dict:
    """The canonical Spec of ``config`` (``{"config": {...}, "sha256": ...}``, as ``kagec resolve``)."""
    return json.loads(native().resolve(os.fspath(config), asset_root or ""))


def certify(train: Path, eval: Path, asset_root: Optional[str] = None) -> dict:
    """The isolation certificate of a train/eval pair (``kagec diff --certify``)."""
    return json.loads(native().certify(os.fspath(train), os.fspath(eval), asset_root or ""))


def suite_report(manifest: Path) -> dict:
    """A suite manifest's pairs, axes and certificates (``kagec suite``'s report)."""
    return json.loads(native().suite_report(os.fspath(manifest)))
