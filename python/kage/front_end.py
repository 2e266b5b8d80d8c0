"""kagec's front end from Python: a config linted or resolved to its Spec, a train/eval pair certified, a mixture
certified, a suite's report. ``lint`` returns ``kagec lint``'s text; the others return the JSON that ``kagec
resolve``, ``kagec diff --certify``, ``kagec diff --mixture`` and ``kagec suite`` print, parsed, and raise
``kage.ConfigError`` with kagec's located diagnostics when the input has errors."""
import json
import os
from typing import Optional, Sequence, Union

from kage._native import native

Path = Union[str, os.PathLike]


def resolve(config: Path, asset_root: Optional[str] = None) -> dict:
    """The canonical Spec of ``config`` (``{"config": {...}, "sha256": ...}``, as ``kagec resolve``)."""
    return json.loads(native().resolve(os.fspath(config), asset_root or ""))


def lint(config: Path, asset_root: Optional[str] = None) -> str:
    """``kagec lint``'s diagnostics of ``config`` as text (warnings and errors, located, with their source
    lines), or ``""`` when it is clean."""
    return native().lint(os.fspath(config), asset_root or "")


def certify(train: Path, eval: Path, asset_root: Optional[str] = None) -> dict:
    """The isolation certificate of a train/eval pair (``kagec diff --certify``)."""
    return json.loads(native().certify(os.fspath(train), os.fspath(eval), asset_root or ""))


def certify_mixture(configs: Sequence[Path], asset_root: Optional[str] = None) -> dict:
    """The certificate of a mixture (``kagec diff --mixture``): ``{"certified": true, "configs": [{"name",
    "spec_sha256"}, ...], "axes": [...]}``. Raises ``kage.ConfigError`` when a config has errors, or when the
    configs differ on a latent key or in observation shape (one located error naming the first such key and
    both files)."""
    return json.loads(native().certify_mixture([os.fspath(c) for c in configs], asset_root or ""))


def mixture_hash(spec_hashes: Sequence[str], counts: Sequence[int]) -> str:
    """The spec hash of a mixture batch: of its configs' Spec hashes and environment counts, in order."""
    return native().mixture_hash(list(spec_hashes), [int(c) for c in counts])


def suite_report(manifest: Path) -> dict:
    """A suite manifest's pairs, axes and certificates (``kagec suite``'s report)."""
    return json.loads(native().suite_report(os.fspath(manifest)))
