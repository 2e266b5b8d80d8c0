"""Shared fixtures of the Python tests: paths and a deterministic policy."""
import os
import pathlib

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
CONFIGS = pathlib.Path(__file__).resolve().parent / "configs"
SIMPLEST = str(ROOT / "configs/throughput/simplest.yaml")
LONG_EPISODE = str(CONFIGS / "long_episode.yaml")
NEAR_GOAL = str(CONFIGS / "near_goal.yaml")
# A config with a stochastic filter, sprites and short episodes.
NOISY_SKELETON = str(CONFIGS / "noisy_short.yaml")


def policy(seed: int, num_envs: int, steps: int) -> np.ndarray:
    """[steps, num_envs] actions, mostly right and right+jump, so that the agent travels and lands."""
    rng = np.random.default_rng(seed)
    return rng.choice(np.array([2, 6, 2, 6, 0, 1, 4, 7], dtype=np.int64), size=(steps, num_envs))


@pytest.fixture
def api_trace() -> str:
    path = os.environ.get("KAGE_API_TRACE")
    if not path or not os.path.exists(path):
        pytest.fail("KAGE_API_TRACE must name the kage_api_trace binary (CTest sets it)")
    return path
