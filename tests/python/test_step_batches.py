"""kage.step_batches: a list of batches stepped by rows of one actions array in one call equals each batch stepped
alone with its row, byte for byte (observations, rewards, flags, info and final info, across autoresets, a mixture
among them); every misuse is refused before any batch steps, and a bad action found in a later row names its batch."""
import numpy as np
import pytest
import torch

import kage
from support import CONFIGS, NEAR_GOAL, SIMPLEST, policy

NEAR_GOAL_RED = str(CONFIGS / "near_goal_red.yaml")
N = 6


def make(config, seed):
    return kage.make_vec(config, N, seed=seed)


def snapshot(env):
    obs, reward, terminated, truncated, info = env.outputs()
    flat = {"obs": obs, "reward": reward, "terminated": terminated, "truncated": truncated}
    flat.update({f"info/{k}": v for k, v in info.items() if k not in ("final_info", "final_obs")})
    flat.update({f"final_info/{k}": v for k, v in info["final_info"].items()})
    flat["final_obs"] = info["final_obs"]
    return {k: np.array(v, copy=True) for k, v in flat.items()}


def batches():
    # NEAR_GOAL's episodes end within a few steps, so 60 steps cross many autoresets; the last is a mixture.
    return [make(NEAR_GOAL, 1), make(SIMPLEST, 2), make(NEAR_GOAL, 3), make([NEAR_GOAL, NEAR_GOAL_RED], 4)]


@pytest.mark.parametrize("as_tensor", [False, True])
def test_rows_stepped_in_one_call_equal_each_batch_stepped_alone(as_tensor):
    together, alone = batches(), batches()
    for env in together + alone:
        env.reset()
    steps = 60
    actions = np.stack([policy(seed, N, steps) for seed in range(len(together))], axis=1)  # [steps, batches, N]
    finished = 0
    for step in range(steps):
        rows = torch.from_numpy(actions[step]) if as_tensor else actions[step]
        kage.step_batches(together, rows)
        for env, row in zip(alone, actions[step]):
            env.step(row)
        for a, b in zip(together, alone):
            sa, sb = snapshot(a), snapshot(b)
            assert sa.keys() == sb.keys()
            for key in sa:
                assert np.array_equal(sa[key], sb[key]), (step, key)
        finished += sum(int(np.asarray(env.outputs()[4]["_final"]).sum()) for env in together)
    assert finished > 0  # the comparison covered autoresets


def test_int32_rows_and_a_strided_view_step_as_int64_rows():
    a, b = batches()[:2], batches()[:2]
    for env in a + b:
        env.reset()
    rows = policy(7, 2 * N, 1)[0].reshape(2, N)
    wide = np.zeros((2, 2 * N), dtype=np.int64)
    wide[:, ::2] = rows
    kage.step_batches(a, rows.astype(np.int32))
    kage.step_batches(b, wide[:, ::2])  # every other column: strided rows
    for x, y in zip(a, b):
        assert np.array_equal(snapshot(x)["obs"], snapshot(y)["obs"])


@pytest.mark.parametrize("envs, actions, error, text", [
    (lambda e: [], np.zeros((0, N), np.int64), TypeError, "non-empty list of kage.VecEnv"),
    (lambda e: [e[0], "env"], np.zeros((2, N), np.int64), TypeError, "non-empty list of kage.VecEnv"),
    (lambda e: [e[0], e[0]], np.zeros((2, N), np.int64), ValueError, "a batch appears twice"),
    (lambda e: e[:2], np.zeros((3, N), np.int64), ValueError, "expected (2, 6): a row of one action per environment"),
    (lambda e: e[:2], np.zeros(2 * N, np.int64), ValueError, "expected (2, 6)"),
    (lambda e: e[:2], np.zeros((2, N), np.float32), ValueError, "expected an integer dtype"),
    (lambda e: [e[0], kage.make_vec(NEAR_GOAL, N + 1)], np.zeros((2, N), np.int64), ValueError,
     "batch 1 has 7 environments, batch 0 has 6: step batches of one size together"),
    (lambda e: e[:2], np.full((2, N), 8, np.int64), ValueError,
     "action 8 for environment 0: an action is an integer in 0..7"),
    (lambda e: e[:2], np.array([[0] * N, [0, 0, 2**64 - 1, 0, 0, 0]], np.uint64), ValueError,
     "batch 1 (none stepped): action 18446744073709551615 for environment 2: an action is an integer in 0..7"),
])
def test_misuse_is_refused_before_any_batch_steps(envs, actions, error, text):
    made = batches()
    for env in made:
        env.reset()
    before = [snapshot(env)["obs"] for env in made]
    with pytest.raises(error) as raised:
        kage.step_batches(envs(made), actions)
    assert text in str(raised.value)
    for env, obs in zip(made, before):
        assert np.array_equal(snapshot(env)["obs"], obs)


@pytest.mark.parametrize("dtype", [np.int32, np.int64])
def test_a_bad_host_action_in_a_later_row_names_its_batch_and_steps_none(dtype):
    made = batches()
    for env in made:
        env.reset()
    rows = policy(9, 4 * N, 1)[0].reshape(4, N).astype(dtype)
    rows[2, 3] = 8
    before = [snapshot(env) for env in made]
    with pytest.raises(ValueError) as raised:
        kage.step_batches(made, rows)
    assert "batch 2 of 4 (none stepped): action 8 for environment 3: an action is an integer in 0..7" in \
        str(raised.value)
    for env, state in zip(made, before):
        after = snapshot(env)
        assert all(np.array_equal(after[key], state[key]) for key in state)
    rows[2, 3] = 1  # the batches step on as if the bad call had not been made
    kage.step_batches(made, rows)


def test_a_closed_batch_is_refused():
    a, b = batches()[:2]
    b.close()
    with pytest.raises(RuntimeError, match="this environment is closed"):
        kage.step_batches([a, b], np.zeros((2, N), np.int64))
