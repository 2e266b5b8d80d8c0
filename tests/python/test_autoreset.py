"""Same-step autoreset: the finished episode's last frame and info, the next episode's first frame,
truncation at episode_length.

The reference for "what a step without reset would have shown" is the same config with 1000-step
episodes (tests/python/configs/long_episode.yaml): the same seeds and actions give the same first 500
steps, and at step 500 it shows the frame and info that the 500-step config moves to final_*."""
import numpy as np

import kage
from support import LONG_EPISODE, NEAR_GOAL, SIMPLEST, policy

SEEDS = [21, 22, 23]


def test_final_obs_and_info_are_the_unreset_step():
    actions = policy(7, 3, 500)
    with kage.make_vec(SIMPLEST, 3) as short, kage.make_vec(LONG_EPISODE, 3) as long:
        so, _ = short.reset(seed=SEEDS)
        lo, _ = long.reset(seed=SEEDS)
        assert np.array_equal(so, lo)
        for t, a in enumerate(actions, start=1):
            so, sr, sterm, strunc, sinfo = short.step(a)
            lo, lr, lterm, ltrunc, linfo = long.step(a)
            assert np.array_equal(sr, lr)
            if t < 500:
                assert not strunc.any() and not sinfo["_final"].any(), f"step {t}"
                assert np.array_equal(so, lo), f"step {t}"
        assert strunc.tolist() == [1, 1, 1] and not sterm.any()
        assert not ltrunc.any()
        assert sinfo["_final"].tolist() == [1, 1, 1]
        assert np.array_equal(sinfo["final_obs"], lo)
        for name, _, _ in kage.INFO_FIELDS:
            assert np.array_equal(sinfo["final_info"][name], linfo[name]), name
        assert sinfo["final_info"]["length"].tolist() == [500, 500, 500]
        assert linfo["x"].max() > linfo["x"].min() or linfo["passed_distance"].any(), "the agents moved"

        # The new episode: its first frame and a fresh info.
        assert sinfo["timestep"].tolist() == [0, 0, 0] and sinfo["return"].tolist() == [0, 0, 0]
        assert sinfo["passed_distance"].tolist() == [0, 0, 0]
        assert not np.array_equal(so, sinfo["final_obs"])
        state = short.save_state()
        rerendered, _ = short.load_state(state)
        assert np.array_equal(so, rerendered), "the returned frame is the render of the new episode's state"

        so, _, _, strunc, sinfo = short.step(actions[0])
        assert sinfo["timestep"].tolist() == [1, 1, 1] and not sinfo["_final"].any() and not strunc.any()


def test_truncation_falls_at_episode_length():
    with kage.make_vec(NEAR_GOAL, 2) as env:
        env.reset(seed=0)
        ends = []
        for t in range(1, 130):
            _, _, terminated, truncated, info = env.step(np.array([2, 6]))
            assert not terminated.any()
            assert np.array_equal(truncated, info["_final"])
            if truncated.any():
                assert truncated.all()
                ends.append(t)
                assert info["final_info"]["timestep"].tolist() == [40, 40]
        assert ends == [40, 80, 120]
