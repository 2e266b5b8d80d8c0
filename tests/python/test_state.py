"""save_state / load_state and thread-count determinism."""
import numpy as np
import pytest

import kage
from support import NEAR_GOAL, NOISY_SKELETON, SIMPLEST, policy


def run(env, actions):
    """Every output of every step, copied."""
    out = []
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        out.append([obs.copy(), reward.copy(), terminated.copy(), truncated.copy(), info["_final"].copy(),
                    info["final_obs"].copy()] + [info[name].copy() for name, _, _ in kage.INFO_FIELDS])
    return out


def assert_same(a, b):
    assert len(a) == len(b)
    for t, (x, y) in enumerate(zip(a, b)):
        for i, (u, v) in enumerate(zip(x, y)):
            if i == 5:  # final_obs: only the final rows are meaningful
                u, v = u[x[4] == 1], v[y[4] == 1]
            assert np.array_equal(u, v), f"step {t}, output {i}"


@pytest.mark.parametrize("config", [NEAR_GOAL, NOISY_SKELETON])
def test_restored_batch_continues_exactly(config):
    actions = policy(3, 3, 70)
    with kage.make_vec(config, 3) as a, kage.make_vec(config, 3) as b:
        a.reset(seed=8)
        run(a, actions[:25])
        state = a.save_state()
        saved_obs = a._handle.output("obs").copy()
        rest = run(a, actions[25:])
        assert any(step[4].any() for step in rest), "an autoreset happens after the restore point"
        b.reset(seed=99)
        restored_obs, info = b.load_state(state)
        assert np.array_equal(restored_obs, saved_obs)
        assert info["timestep"].tolist() == [25, 25, 25]
        assert_same(run(b, actions[25:]), rest)


def test_state_is_refused_by_another_config_or_size():
    with kage.make_vec(NEAR_GOAL, 2) as a:
        a.reset(seed=1)
        state = a.save_state()
        assert 1000 < len(state) / 2 < 2000, "about 1.4 KB per environment"
        with kage.make_vec(SIMPLEST, 2) as other, pytest.raises(ValueError, match="spec hash"):
            other.load_state(state)
        with kage.make_vec(NEAR_GOAL, 3) as bigger, pytest.raises(ValueError, match="num_envs=2"):
            bigger.load_state(state)
        with pytest.raises(ValueError, match="magic|shorter"):
            a.load_state(b"not a state")


@pytest.mark.parametrize("config", [NEAR_GOAL, NOISY_SKELETON])
def test_any_thread_count_gives_the_same_bytes(config):
    actions = policy(4, 5, 45)
    runs = []
    for threads in (1, 2, 3):
        with kage.make_vec(config, 5, threads=threads) as env:
            env.reset(seed=2)
            runs.append(run(env, actions))
    assert_same(runs[0], runs[1])
    assert_same(runs[0], runs[2])
