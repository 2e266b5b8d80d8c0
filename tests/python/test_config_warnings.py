"""A config's warnings reach Python: make_vec gives kagec's located warnings as one kage.ConfigWarning, and the
shipped configs give none (their deliberate inert settings and quirks are silenced in the files)."""
import pathlib
import warnings

import pytest

import kage
from support import ROOT

INERT = """background:
  mode: black
  parallax_factor: 0.8
"""


def opened_warnings(config, **kwargs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        kage.make_vec(config, 2, **kwargs).close()
    return [w for w in caught if issubclass(w.category, kage.ConfigWarning)]


def test_a_configs_warning_is_given_located_with_its_rule(tmp_path):
    config = tmp_path / "inert.yaml"
    config.write_text(INERT)
    caught = opened_warnings(config)
    assert len(caught) == 1
    text = str(caught[0].message)
    assert f"{config}:3:3: warning: 'background.parallax_factor' has no effect" in text
    assert "[inert-setting]" in text
    assert caught[0].filename == __file__  # attributed to the caller of make_vec, not to kage


def test_a_disable_comment_silences_it(tmp_path):
    config = tmp_path / "inert.yaml"
    config.write_text(INERT.replace("parallax_factor: 0.8", "parallax_factor: 0.8  # kagec: disable=inert-setting"))
    assert opened_warnings(config) == []


def test_a_mixture_gives_each_configs_warnings(tmp_path):
    clean = tmp_path / "clean.yaml"
    clean.write_text("background:\n  mode: black\n")
    inert = tmp_path / "inert.yaml"
    inert.write_text(INERT)
    caught = opened_warnings([clean, inert])
    assert len(caught) == 1 and f"{inert}:3:3: warning:" in str(caught[0].message)


def test_warnings_can_be_ignored_by_category(tmp_path):
    config = tmp_path / "inert.yaml"
    config.write_text(INERT)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", category=kage.ConfigWarning)
        kage.make_vec(config, 2).close()


SHIPPED = ROOT / "configs"


@pytest.mark.parametrize("config", sorted(str(p.relative_to(SHIPPED)) for p in SHIPPED.rglob("*.yaml")))
def test_shipped_configs_give_no_warning(config):
    assert [str(w.message) for w in opened_warnings(SHIPPED / config)] == []
