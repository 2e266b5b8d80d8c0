"""Paths and a deterministic policy shared by the Python tests (tests/python, tests/gpu)."""
import os
import pathlib

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
CONFIGS = pathlib.Path(__file__).resolve().parent / "configs"
SIMPLEST = str(ROOT / "configs/throughput/simplest.yaml")
LONG_EPISODE = str(CONFIGS / "long_episode.yaml")
NEAR_GOAL = str(CONFIGS / "near_goal.yaml")
# A config with a stochastic filter, sprites and short episodes.
NOISY_SKELETON = str(CONFIGS / "noisy_short.yaml")
# Two runs of a pack (kage.ppo.train.Args fields): each trains on one near-goal config and evaluates on the other.
NEAR_GOAL_RUNS = [dict(train_config_path=str(CONFIGS / "near_goal.yaml"),
                       eval_config_path=str(CONFIGS / "near_goal_red.yaml"), seed=3),
                  dict(train_config_path=str(CONFIGS / "near_goal_red.yaml"),
                       eval_config_path=str(CONFIGS / "near_goal.yaml"), seed=8)]


def policy(seed: int, num_envs: int, steps: int) -> np.ndarray:
    """[steps, num_envs] actions, mostly right and right+jump, so that the agent travels and lands."""
    rng = np.random.default_rng(seed)
    return rng.choice(np.array([2, 6, 2, 6, 0, 1, 4, 7], dtype=np.int64), size=(steps, num_envs))

# kage.bench runs that finish in seconds on one CPU core: one iteration of 2 x 32 steps, evaluated before
# and after it on 2 episodes.
TINY_TRAINING = ["--total-timesteps", "64", "--num-envs", "2", "--num-steps", "32", "--num-minibatches", "2",
                 "--update-epochs", "1", "--run-eval-every", "1", "--eval-episodes", "2", "--eval-num-envs", "2",
                 "--device", "cpu", "--threads", "1"]


def dead_pid() -> int:
    """A process id that no process has now."""
    pid = 2**22 - 1
    while True:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return pid
        except PermissionError:
            pass
        pid -= 1
