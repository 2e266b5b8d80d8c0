"""make_vec's result: shapes, dtypes, spaces, metadata, seeding, subset reset and copy=True."""
import subprocess

import numpy as np
import pytest

import kage
from support import NEAR_GOAL, SIMPLEST, policy


def test_shapes_and_dtypes():
    with kage.make_vec(SIMPLEST, 3) as env:
        obs, info = env.reset(seed=0)
        assert obs.shape == (3, 128, 128, 3) and obs.dtype == np.uint8
        obs, reward, terminated, truncated, info = env.step(np.array([2, 6, 0]))
        assert reward.shape == (3,) and reward.dtype == np.float32
        assert terminated.dtype == bool and truncated.dtype == bool
        expected = {name: dtype for name, dtype, _ in kage.INFO_FIELDS}
        assert set(expected) == {"x", "y", "vx", "vy", "vx_mean", "vy_mean", "timestep", "passed_distance",
                                 "progress", "success", "success_once", "jump_count", "return", "length"}
        for name, dtype in expected.items():
            assert info[name].shape == (3,) and info[name].dtype == dtype, name
        assert info["final_obs"].shape == (3, 128, 128, 3)
        assert set(info["final_info"]) == set(expected) | {"config"}  # the runtime's fields and the batch's
        assert info["config"].dtype == np.int32 and info["config"].tolist() == [0, 0, 0]
        assert info["_final"].dtype == bool and not info["_final"].any()
        assert info["timestep"].tolist() == [1, 1, 1] and info["length"].tolist() == [1, 1, 1]
        assert obs.any(), "the frame is not blank"


def test_spaces_and_metadata():
    with kage.make_vec(SIMPLEST, 2) as env:
        assert env.num_envs == 2
        assert env.metadata["autoreset_mode"].value == "SameStep"  # gymnasium.vector.AutoresetMode.SAME_STEP
        assert env.single_observation_space.shape == (128, 128, 3)
        assert env.single_observation_space.dtype == np.uint8
        assert env.single_action_space.n == 8
        assert len(env.spec_hash) == 64 and int(env.spec_hash, 16) >= 0


def test_seeds_give_distinct_levels_and_repeat():
    with kage.make_vec(SIMPLEST, 4) as a, kage.make_vec(SIMPLEST, 4) as b:
        oa = a.reset(seed=3)[0].copy()
        ob, _ = b.reset(seed=3)
        assert np.array_equal(oa, ob)
        assert len({oa[i].tobytes() for i in range(4)}) == 4, "each environment has its own level"
        ob, _ = b.reset(seed=4)
        assert not np.array_equal(oa, ob)
        explicit, _ = b.reset(seed=kage.env_seeds(3, 4).tolist())
        assert np.array_equal(oa, explicit)


def test_reset_without_seed_follows_make_vec_seed():
    with kage.make_vec(SIMPLEST, 2, seed=9) as a, kage.make_vec(SIMPLEST, 2) as b:
        first = a.reset()[0].copy()
        assert np.array_equal(first, b.reset(seed=9)[0])
        second, _ = a.reset()
        assert not np.array_equal(second, first), "a later reset() starts other levels"


def test_reset_mask_resets_only_masked_envs():
    actions = policy(1, 3, 20)
    with kage.make_vec(NEAR_GOAL, 3) as env:
        env.reset(seed=5)
        for a in actions:
            env.step(a)
        before_x = env.step(actions[0])[4]["x"].copy()
        obs, info = env.reset(seed=[11, 12, 13], options={"reset_mask": np.array([False, True, False])})
        assert info["timestep"].tolist() == [21, 0, 21]
        assert info["x"][0] == before_x[0] and info["x"][2] == before_x[2]
        with kage.make_vec(NEAR_GOAL, 3) as fresh:
            fresh_obs, _ = fresh.reset(seed=[11, 12, 13])
            assert np.array_equal(obs[1], fresh_obs[1]), "the masked environment starts episode 0 of its new seed"


def test_context_manager_closes():
    with kage.make_vec(SIMPLEST, 1) as env:
        env.reset(seed=0)
    assert env.closed
    with pytest.raises(RuntimeError, match="closed"):
        env.step(np.zeros(1, dtype=np.int64))
    with pytest.raises(RuntimeError, match="closed"):
        env.reset()
    env.close()  # a second close is harmless


def test_a_batch_is_neither_pickled_nor_copied():
    """A copy would share the runtime's batch (closing one closes both): the way across is save_state."""
    import copy
    import pickle
    with kage.make_vec(SIMPLEST, 1) as env:
        for attempt in (pickle.dumps, copy.copy, copy.deepcopy):
            with pytest.raises(TypeError, match=r"cannot be pickled or copied: .*save_state\(\) and load_state\(\)"):
                attempt(env)


def test_a_bytes_path_is_read_as_a_path():
    with kage.make_vec(SIMPLEST.encode(), 1) as env:
        assert env.config == SIMPLEST and env.configs == (SIMPLEST,)


def test_views_outlive_close():
    env = kage.make_vec(SIMPLEST, 2)
    obs, _ = env.reset(seed=0)
    expected = obs.copy()
    env.close()
    assert np.array_equal(obs, expected), "an output view keeps the runtime's memory alive"


def test_a_compile_directorys_resolved_spec_is_its_spec_json(tmp_path, kagec):
    """It raised "holds no Spec" although the directory holds spec.json, the Spec it was compiled from."""
    compiled = tmp_path / "simplest"
    subprocess.run([kagec, "compile", SIMPLEST, "-o", str(compiled), "--no-gpu"], check=True, capture_output=True)
    with kage.make_vec(str(compiled), 2) as env:
        assert env.resolved_spec == kage.front_end.resolve(SIMPLEST)


def test_copy_true_returns_arrays_the_next_step_leaves_alone():
    with kage.make_vec(SIMPLEST, 4, copy=True) as env, kage.make_vec(SIMPLEST, 4) as views:
        kept = [env.reset(seed=3)]
        views.reset(seed=3)
        expected = [[a.copy() for a in (views.outputs()[0], views.outputs()[4]["x"])]]
        for _ in range(3):
            kept.append(env.step(np.full(4, 6)))
            views.step(np.full(4, 6))
            expected.append([views.outputs()[0].copy(), views.outputs()[4]["x"].copy()])
        for outputs, (obs, x) in zip(kept, expected):
            assert np.array_equal(outputs[0], obs) and np.array_equal(outputs[-1]["x"], x)
        assert not np.array_equal(kept[1][-1]["x"], kept[3][-1]["x"])  # they moved: the copies differ
        assert not np.shares_memory(kept[1][-1]["final_info"]["return"], kept[2][-1]["final_info"]["return"])


@pytest.mark.parametrize("kwargs, match", [({"copy": 1}, r"copy=1: True or False"),
                                           ({"copy": True, "device": "cuda"}, r"copy=True copies host arrays")])
def test_copy_is_checked(kwargs, match):
    with pytest.raises(ValueError, match=match):
        kage.make_vec(SIMPLEST, 2, **kwargs)
