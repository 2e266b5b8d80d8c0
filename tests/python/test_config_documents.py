"""make_vec reads a config through kagec's front end: a file of two YAML documents, or with a tag the
original's loader refuses, raises ConfigError at the place, instead of silently using the first."""
import pytest

import kage
from support import SIMPLEST


def test_two_documents_are_refused_at_the_second(tmp_path):
    config = tmp_path / "two.yaml"
    config.write_text(f"extends: {SIMPLEST}\n---\nH: 32\n")
    with pytest.raises(kage.ConfigError) as info:
        kage.make_vec(str(config), 2)
    (diag,) = info.value.errors
    assert (diag.file, diag.line, diag.col) == (str(config), 2, 1)
    assert "a second YAML document starts here" in diag.message and "[yaml-multiple-documents]" in diag.message


def test_a_python_object_tag_is_refused(tmp_path):
    config = tmp_path / "tagged.yaml"
    config.write_text(f"extends: {SIMPLEST}\nphysics:\n  gravity: !!python/object/apply:os.system [ls]\n")
    with pytest.raises(kage.ConfigError) as info:
        kage.make_vec(str(config), 2)
    assert any(d.line == 3 and "[yaml-tag]" in d.message for d in info.value.errors)
