"""kage with the real Gymnasium 1.x: the registered vector and single environments, Gymnasium's own spaces, its
vector wrappers, its autoreset mode, its environment checker on the single environment, and bool flags and masks that index as
masks. Gymnasium's checks that do not apply are listed in README ("Gymnasium")."""
import subprocess
import sys

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode

import kage
from support import NOISY_SKELETON, SIMPLEST


def test_make_vec_returns_the_project_vector_environment():
    env = gymnasium.make_vec("kage/KAGE-v0", num_envs=3, vectorization_mode="vector_entry_point", config=SIMPLEST)
    try:
        assert isinstance(env, kage.VecEnv) and env.num_envs == 3
        assert env.metadata["autoreset_mode"] is AutoresetMode.SAME_STEP
        assert env.spec is not None and env.spec.id == "kage/KAGE-v0" and env.spec.kwargs["config"] == SIMPLEST
        assert isinstance(env.single_observation_space, gymnasium.spaces.Box)
        assert isinstance(env.single_action_space, gymnasium.spaces.Discrete) and env.single_action_space.n == 8
        obs, info = env.reset(seed=5)
        assert obs.shape == (3, *env.single_observation_space.shape)
        assert all(env.single_observation_space.contains(o) for o in obs)
        obs, reward, terminated, truncated, info = env.step(np.array([1, 2, 4]))
        assert reward.dtype == np.float32 and terminated.dtype == bool and truncated.dtype == bool
        assert info["_final"].dtype == bool and not info["_final"].any()
    finally:
        env.close()


def test_gymnasiums_vector_wrappers_take_the_vector_environment():
    """It was no gymnasium.vector.VectorEnv: RecordEpisodeStatistics, NormalizeReward and the like refused it, and
    it had no batched action_space to sample."""
    env = gymnasium.wrappers.vector.RecordEpisodeStatistics(kage.make_vec(NOISY_SKELETON, 3))
    try:
        assert isinstance(env.unwrapped, gymnasium.vector.VectorEnv) and isinstance(env.unwrapped, kage.VecEnv)
        assert env.action_space == gymnasium.spaces.MultiDiscrete([8, 8, 8])
        assert env.observation_space.shape == (3, *env.single_observation_space.shape)
        env.reset(seed=1)
        env.action_space.seed(0)
        for step in range(1, 41):
            *_, info = env.step(env.action_space.sample())
            if "episode" in info:
                break
        # NOISY_SKELETON's episodes end at 40 steps; the wrapper sums the rewards of each.
        assert step == 40 and info["_episode"].all() and info["episode"]["l"].tolist() == [40, 40, 40]
        assert np.allclose(info["episode"]["r"], info["final_info"]["return"])
    finally:
        env.close()


def test_without_gymnasium_the_spaces_are_its_reduced_ones():
    code = ("import sys; sys.modules['gymnasium'] = None\n"
            "from kage import spaces\n"
            "a = spaces.batched(spaces.action_space(), 3); o = spaces.batched(spaces.observation_space(4, 5), 3)\n"
            "a.seed(0); x = a.sample()\n"
            "print(spaces.VectorEnvBase is object, a, o.shape, x.shape, a.contains(x), a.contains([0, 8, 0]))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[0] == "True MultiDiscrete([8, 8, 8]) (3, 4, 5, 3) (3,) True False"


def test_flags_and_masks_are_bool_and_index_as_masks():
    env = kage.make_vec(NOISY_SKELETON, 4)
    try:
        env.reset(seed=1)
        rng = np.random.default_rng(0)
        for _ in range(10):
            env.step(rng.integers(0, 8, 4))
        # Environments 0 and 2 start again, 10 steps behind 1 and 3, whose episodes (40 steps) end first.
        env.reset(options={"reset_mask": np.array([True, False, True, False])})
        assert not env.outputs()[4]["_final"].any()
        for _ in range(40):
            obs, reward, terminated, truncated, info = env.step(rng.integers(0, 8, 4))
            if info["_final"].any():
                break
        final = info["_final"]
        assert final.dtype == bool and terminated.dtype == bool and truncated.dtype == bool
        assert final.tolist() == [False, True, False, True]
        # A bool mask selects the finished rows; the uint8 0/1 masks of before indexed rows 0 and 1 instead.
        chosen = info["final_obs"][final]
        assert chosen.shape == (int(final.sum()), *env.single_observation_space.shape)
        assert np.array_equal(chosen, info["final_obs"][np.flatnonzero(final)])
        assert np.array_equal(final, terminated | truncated)
    finally:
        env.close()


def test_the_single_environment_passes_gymnasiums_checker():
    env = gymnasium.make("kage/KAGE-v0", config=SIMPLEST)
    try:
        check_env(env.unwrapped, skip_render_check=False)
    finally:
        env.close()


def test_the_single_environment_ends_an_episode_as_gymnasium_says():
    env = gymnasium.make("kage/KAGE-v0", config=SIMPLEST, disable_env_checker=True)
    try:
        obs, info = env.reset(seed=3)
        assert obs.shape == (128, 128, 3) and info["timestep"] == 0
        steps, done = 0, False
        while not done:
            obs, reward, terminated, truncated, info = env.step(2)
            steps += 1
            done = terminated or truncated
        # Episodes end by truncation at episode_length; the step shows the ended episode, not the next start.
        assert truncated and not terminated and steps == 500 and info["timestep"] == 500
        assert np.array_equal(env.render(), obs)
        obs, info = env.reset()
        assert info["timestep"] == 0 and info["return"] == 0
        with pytest.raises(ValueError, match="0..7"):
            env.step(8)
    finally:
        env.close()


def test_a_reset_in_the_middle_of_an_episode_starts_a_new_one():
    """A TimeLimit wrapper truncates where the runtime's episode goes on: reset() used to return that episode's
    current state (timestep 100), and Gymnasium's sync vector environment carried every episode on."""
    env = gymnasium.make("kage/KAGE-v0", config=SIMPLEST, max_episode_steps=100, disable_env_checker=True)
    try:
        env.reset(seed=0)
        for _ in range(100):
            *_, truncated, info = env.step(2)
        assert truncated and info["timestep"] == 100
        obs, info = env.reset()
        assert info["timestep"] == 0 and info["return"] == 0 and info["passed_distance"] == 0
    finally:
        env.close()
    vector = gymnasium.make_vec("kage/KAGE-v0", num_envs=2, vectorization_mode="sync", config=SIMPLEST,
                                max_episode_steps=10)
    try:
        vector.reset(seed=1)
        timesteps = [vector.step(np.array([2, 2]))[4]["timestep"].tolist() for _ in range(12)]
        assert timesteps[9] == [10, 10] and timesteps[10] == [0, 0] and timesteps[11] == [1, 1]
    finally:
        vector.close()


def test_unseeded_single_environments_differ_and_seeded_ones_repeat():
    config = str(kage.resources.config_path("kage_bench/distractors/5-eval"))
    envs = [gymnasium.make("kage/KAGE-v0", config=config, disable_env_checker=True) for _ in range(3)]
    try:
        first = [env.reset()[0] for env in envs]
        assert not np.array_equal(first[0], first[1]) and not np.array_equal(first[1], first[2])
        # Seeded, reset() draws from the env's np_random, which reset(seed=s) seeded: the same episodes again.
        episodes = []
        for env in envs[:2]:
            env.reset(seed=7)
            for _ in range(5):
                env.step(3)
            episodes.append(env.reset()[0])
        assert np.array_equal(episodes[0], episodes[1])
    finally:
        for env in envs:
            env.close()


def test_a_closed_single_environment_names_how_to_make_another():
    env = gymnasium.make("kage/KAGE-v0", config=SIMPLEST, disable_env_checker=True)
    env.reset(seed=0)
    env.close()
    env.close()  # twice is harmless
    for call in (env.reset, lambda: env.step(0), env.render):
        with pytest.raises(RuntimeError, match=r"closed: make a new one with gymnasium\.make\('kage/KAGE-v0', "):
            call()


def test_a_make_without_config_or_with_a_bad_one_names_the_fix():
    """It raised Python's "missing 1 required positional argument: 'config'", "expected str, bytes or
    os.PathLike object, not int", or make_vec's "unexpected keyword argument 'render_mode'"."""
    with pytest.raises(TypeError, match=r"kage/KAGE-v0: config= names the game: .*e\.g\. "
                                        r"gymnasium\.make\('kage/KAGE-v0', config='throughput/simplest'\)"):
        gymnasium.make("kage/KAGE-v0")
    with pytest.raises(TypeError, match=r"config= names the game: .*e\.g\. gymnasium\.make_vec\('kage/KAGE-v0', "
                                        r"num_envs=2, vectorization_mode='vector_entry_point', config="):
        gymnasium.make_vec("kage/KAGE-v0", num_envs=2, vectorization_mode="vector_entry_point")
    with pytest.raises(TypeError, match=r"config=5: a path \(str or os\.PathLike\) to a YAML config"):
        gymnasium.make("kage/KAGE-v0", config=5)
    with pytest.raises(TypeError, match=r"config=\{'a.yaml'\}: a path .*; or a list of YAML configs \(a mixture\)"):
        kage.make_vec({"a.yaml"}, 2)
    with pytest.raises(ValueError, match=r"render_mode='rgb_array': kage/KAGE-v0's vector environment renders no "
                                         r"frames of its own"):
        gymnasium.make_vec("kage/KAGE-v0", num_envs=2, vectorization_mode="vector_entry_point", config=SIMPLEST,
                           render_mode="rgb_array")
    env = gymnasium.make_vec("kage/KAGE-v0", num_envs=2, vectorization_mode="vector_entry_point", config=SIMPLEST,
                             render_mode=None)
    assert env.reset(seed=1)[0].shape[0] == 2
    env.close()
