"""The binding returns the bytes the C++ API returns, for the same seeds and actions."""
import subprocess

import numpy as np
import pytest

import kage
from support import NEAR_GOAL, NOISY_SKELETON

STEPS = 45  # past near_goal's 40-step episodes: one automatic reset


def python_trace(config: str, num_envs: int, threads: int) -> bytes:
    """The same records as kage_api_trace, through the Python package."""
    chunks = []
    seeds = [1000 + 7919 * i for i in range(num_envs)]

    def record(obs, reward, terminated, truncated, info):
        # Outputs are views that the next step overwrites: keep their bytes now.
        arrays = [obs, reward, terminated, truncated] + [info[name] for name, _, _ in kage.INFO_FIELDS]
        arrays += [info["_final"], info["final_obs"]] + [info["final_info"][name] for name, _, _ in kage.INFO_FIELDS]
        chunks.extend(a.tobytes() for a in arrays)

    with kage.make_vec(config, num_envs, threads=threads) as env:
        obs, info = env.reset(seed=seeds)
        record(obs, *[env._handle.output(k) for k in ("reward", "terminated", "truncated")], info)
        for t in range(1, STEPS + 1):
            actions = np.array([(5 * t + 3 * i) % 8 for i in range(num_envs)], dtype=np.int32)
            record(*env.step(actions))
    return b"".join(chunks)


@pytest.mark.parametrize("config", [NEAR_GOAL, NOISY_SKELETON])
def test_binding_matches_cpp_api(api_trace, tmp_path, config):
    out = tmp_path / "trace.bin"
    subprocess.run([api_trace, config, "3", str(STEPS), "2", str(out)], check=True)
    cpp = out.read_bytes()
    py = python_trace(config, 3, 2)
    assert len(cpp) == len(py) > 3 * 128 * 128 * 3 * STEPS
    assert cpp == py
