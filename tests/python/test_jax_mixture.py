"""kage.jax's mixture against make_vec's, byte for byte, inside one jitted lax.scan with automatic resets; vmap
over seeds; the action record numbered in the whole batch; the refusals of make_vec's mixture."""
import numpy as np
import pytest

jax = pytest.importorskip("jax", reason="kage.jax needs JAX (pip install jax); CI installs it")
import jax.numpy as jnp  # noqa: E402

import kage  # noqa: E402
import kage.jax  # noqa: E402
from kage.vector import INFO_NAMES  # noqa: E402
from support import CONFIGS, NEAR_GOAL, SIMPLEST, policy  # noqa: E402

MIX = [NEAR_GOAL, str(CONFIGS / "near_goal_red.yaml"), str(CONFIGS / "near_goal_noisy.yaml")]
KEYS = ("obs", "reward", "terminated", "truncated", "_final", "final_obs")


def outputs(obs, reward, terminated, truncated, info):
    return {"obs": obs, "reward": reward, "terminated": terminated, "truncated": truncated, "_final": info["_final"],
            "final_obs": info["final_obs"], **{k: info[k] for k in INFO_NAMES},
            **{"final_info/" + k: info["final_info"][k] for k in INFO_NAMES}}


def vec_rollout(configs, num_envs, weights, seed, actions):
    with kage.make_vec(configs, num_envs, weights=weights, threads=2) as env:
        obs, info = env.reset(seed=seed)
        first = {"obs": obs.copy(), **{k: info[k].copy() for k in INFO_NAMES}}
        steps = [{k: np.array(v, copy=True) for k, v in outputs(*env.step(a)).items()} for a in actions]
    return first, {k: np.stack([s[k] for s in steps]) for k in steps[0]}


def jax_rollout(env):
    def run(seed, actions):
        state, obs, info = env.reset(seed)

        def body(state, a):
            state, *out = env.step(state, a)
            return state, outputs(*out)

        state, steps = jax.lax.scan(body, state, actions)
        return {"obs": obs, **{k: info[k] for k in INFO_NAMES}}, steps, state
    return run


def test_the_jax_mixture_equals_make_vecs_mixture():
    n, steps, seed, weights = 7, 130, 3, [2, 1, 1]  # 40-step episodes: three automatic resets
    actions = policy(seed, n, steps).astype(np.int32)
    first_vec, vec = vec_rollout(MIX, n, weights, seed, actions)
    env = kage.jax.make_env(MIX, n, weights=weights)
    assert isinstance(env, kage.jax.JaxMixture) and env.counts == (3, 2, 2) and env.num_envs == n
    with kage.make_vec(MIX, n, weights=weights) as vec_env:
        assert env.spec_hash == vec_env.spec_hash
    first, got, state = jax.jit(jax_rollout(env))(jnp.uint32(seed), jnp.asarray(actions))
    for k in first_vec:
        assert np.asarray(first[k]).tobytes() == first_vec[k].tobytes(), f"reset {k}"
    assert set(got) == set(vec)
    for k in vec:
        g = np.asarray(got[k])
        assert g.dtype == vec[k].dtype and g.shape == vec[k].shape, k
        assert g.tobytes() == vec[k].tobytes(), k
    assert np.asarray(got["config"])[0].tolist() == [0, 0, 0, 1, 1, 2, 2]
    assert int(np.asarray(got["_final"]).sum()) == 3 * n
    env.check(state)


def test_vmap_over_seeds_equals_separate_resets():
    env = kage.jax.make_env(MIX, 4)
    seeds = jnp.asarray([1, 2], jnp.uint32)
    states, obs, info = jax.jit(jax.vmap(env.reset))(seeds)
    for b, s in enumerate((1, 2)):
        _, one, _ = env.reset(s)
        assert np.asarray(obs[b]).tobytes() == np.asarray(one).tobytes()
    step = jax.jit(jax.vmap(env.step, in_axes=(0, None)))
    states, obs, *_ = step(states, jnp.asarray([2, 6, 0, 1], jnp.int32))
    assert obs.shape == (2, 4, 128, 128, 3) and info["config"].shape == (2, 4)


def test_an_action_outside_the_range_is_named_by_its_place_in_the_whole_batch():
    env = kage.jax.make_env(MIX, 5, weights=[1, 1, 3])  # counts (1, 1, 3): environment 3 runs config 2
    state, _, _ = env.reset(0)
    state = jax.jit(env.step)(state, jnp.asarray([0, 0, 0, 9, 0], jnp.int32))[0]
    with pytest.raises(ValueError, match="the actions of step 1 held 9 for environment 3:"):
        env.check(state)


def test_refusals_are_make_vecs():
    with pytest.raises(kage.ConfigError, match="certify-mixture-latent"):
        kage.jax.make_env([SIMPLEST, str(CONFIGS / "long_episode.yaml")], 2)
    with pytest.raises(ValueError, match=r"^weights\[0\]=-2: a finite number >= 0$"):
        kage.jax.make_env(MIX, 2, weights=[-2, 1, 1])
    with pytest.raises(ValueError, match="weights= splits a mixture"):
        kage.jax.make_env(NEAR_GOAL, 2, weights=[1])
    with pytest.raises(TypeError, match="expected the MixtureState"):
        env = kage.jax.make_env(MIX, 3)
        env.step(kage.jax.make_env(NEAR_GOAL, 3).reset(0)[0], jnp.zeros(3, jnp.int32))


def test_a_config_the_split_leaves_without_environments_is_warned_of():
    with pytest.warns(UserWarning, match=r"kage.jax.make_env: 2 environments split as \[1, 1, 0\] leave configs\[2\]"):
        kage.jax.make_env(MIX, 2)
