"""The environment API refuses what it would otherwise coerce or misread: reset masks that are not booleans,
seeds that are not non-negative integers, a step or a saved state before any reset, sizes beyond the binding's integers or
the machine's memory, and a config that is not UTF-8 (reported as kagec's located error, not a Python
decoding error)."""
import math

import numpy as np
import pytest

import kage
from support import SIMPLEST


@pytest.fixture
def env():
    with kage.make_vec(SIMPLEST, 4, threads=1) as e:
        e.reset(seed=0)
        yield e


@pytest.mark.parametrize("mask, match", [
    ([0.5, 0.5, 0.5, 0.5], "float64"),
    (np.array([1.0, 0.0, 1.0, 0.0]), "float64"),
    ([256, 0, 0, 0], "256"),
    ([2, 0, 1, 0], "2"),
    ([-1, 0, 0, 0], "-1"),
    ([math.nan, 0, 0, 0], "float64"),
    (["yes", "no", "no", "no"], "<U3"),
])
def test_reset_masks_that_are_not_booleans_are_refused(env, mask, match):
    with pytest.raises(ValueError, match=match):
        env.reset(seed=1, options={"reset_mask": mask})


@pytest.mark.parametrize("mask", [[True, False, True, False], np.array([1, 0, 1, 0], dtype=np.uint8),
                                  np.array([1, 0, 1, 0], dtype=np.int64)])
def test_boolean_and_zero_one_masks_reset_the_masked_environments(env, mask):
    env.step(np.full(4, 2))
    _, info = env.reset(seed=1, options={"reset_mask": mask})
    assert info["timestep"].tolist() == [0, 1, 0, 1]


@pytest.mark.parametrize("seed", [1.5, 1.0, np.float64(2.0), True, "3", -1, np.array(1.5), [1, 2, 3, 1.5], [1, 2, 3, -4]])
def test_seeds_that_are_not_non_negative_integers_are_refused(env, seed):
    with pytest.raises(ValueError, match="seed"):
        env.reset(seed=seed)


@pytest.mark.parametrize("seed", [1.5, -2, "0", None])
def test_make_vec_seed_must_be_a_non_negative_integer(seed):
    with pytest.raises(ValueError, match="seed"):
        kage.make_vec(SIMPLEST, 2, seed=seed)


def test_integer_seeds_of_every_kind_agree(env):
    first = env.reset(seed=7)[0].copy()
    for same in (np.int64(7), np.uint8(7), np.array(7)):
        assert np.array_equal(env.reset(seed=same)[0], first)


def test_step_before_reset_raises():
    with kage.make_vec(SIMPLEST, 3, threads=1) as env:
        with pytest.raises(RuntimeError, match="reset"):
            env.step(np.zeros(3, dtype=np.int64))
        with pytest.raises(RuntimeError, match="reset"):
            env.reset(seed=1, options={"reset_mask": [True, False, True]})
        env.reset(seed=1)
        env.step(np.zeros(3, dtype=np.int64))


def test_a_state_saved_before_the_first_reset_is_refused():
    """It would restore as a started batch of all-zero episodes, which a step before reset is refused to run."""
    with kage.make_vec(SIMPLEST, 2) as env:
        with pytest.raises(RuntimeError, match=r"save_state before reset: .* reset it first"):
            env.save_state()
        env.reset(seed=0)
        assert len(env.save_state()) > 0


def test_a_loaded_state_counts_as_a_reset():
    with kage.make_vec(SIMPLEST, 3, threads=1) as a, kage.make_vec(SIMPLEST, 3, threads=1) as b:
        a.reset(seed=4)
        b.load_state(a.save_state())
        b.step(np.zeros(3, dtype=np.int64))


@pytest.mark.parametrize("kwargs, match", [
    ({"num_envs": 2**31}, "num_envs"),
    ({"num_envs": 2**64}, "num_envs"),
    ({"num_envs": 2, "threads": 2**31}, "threads"),
    ({"num_envs": 2, "threads": 1.5}, "threads"),
    ({"num_envs": 2.0}, "num_envs"),
    ({"num_envs": 2, "asset_root": 3}, "asset_root"),
    ({"num_envs": 2, "asset_root": ["assets"]}, "asset_root"),
])
def test_arguments_the_binding_cannot_take_are_value_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        kage.make_vec(SIMPLEST, **kwargs)


def test_an_asset_root_that_is_no_directory_is_named(tmp_path):
    """It was taken as the base of the config's relative asset paths anyway: a config without assets ignored it,
    one with assets reported its YAML's paths as missing, without naming asset_root."""
    for root in (tmp_path / "nonexistent", tmp_path / "a_file"):
        if root.name == "a_file":
            root.write_text("")
        with pytest.raises(FileNotFoundError, match=f"asset_root='{root}': no such directory; it replaces the "
                                                    "config's own folder"):
            kage.make_vec(SIMPLEST, 2, asset_root=root)


def test_a_batch_larger_than_the_machine_is_refused_before_allocating():
    with pytest.raises(ValueError, match="more than half of this machine's") as e:
        kage.make_vec(SIMPLEST, 2**30, threads=1)
    assert "use fewer environments" in str(e.value)
    # Two environments on a million threads: the threads' render scratch is what does not fit.
    with pytest.raises(ValueError, match="on 1000000 threads.*the threads' render scratch.*use fewer threads"):
        kage.make_vec(SIMPLEST, 2, threads=10**6)


def test_a_config_that_is_not_utf8_gives_a_located_config_error(tmp_path):
    config = tmp_path / "latin1.yaml"
    config.write_bytes(open(SIMPLEST, "rb").read() + b"\n# caf\xe9\nbogus_key\xff: 1\n")
    for call in (lambda: kage.make_vec(str(config), 2), lambda: kage.front_end.resolve(str(config))):
        with pytest.raises(kage.ConfigError) as caught:
            call()
        assert str(config) in str(caught.value)
        assert caught.value.errors, str(caught.value)
