"""examples/jax_ppo.py at a tiny size on the CPU: two agents vmapped, two iterations, each one jit."""
import json
import math
import os
import subprocess
import sys

import pytest

pytest.importorskip("jax", reason="examples/jax_ppo.py needs JAX (pip install jax); CI installs it")
from support import ROOT, SIMPLEST  # noqa: E402


def test_two_seeds_train_two_iterations():
    command = [sys.executable, str(ROOT / "examples/jax_ppo.py"), "--config", SIMPLEST, "--num-envs", "8",
               "--num-steps", "16", "--num-seeds", "2", "--total-timesteps", "256", "--num-minibatches", "2",
               "--update-epochs", "1"]
    done = subprocess.run(command, capture_output=True, text=True, timeout=900, env=dict(os.environ))
    assert done.returncode == 0, done.stderr[-3000:]
    lines = [json.loads(line) for line in done.stdout.splitlines()]
    assert [(r["iteration"], r["global_step"]) for r in lines] == [(1, 128), (2, 256)]
    for record in lines:
        for key in ("loss", "policy_loss", "value_loss", "entropy", "approx_kl", "clipfrac", "episodes"):
            assert len(record[key]) == 2 and all(math.isfinite(v) for v in record[key]), (key, record)
        # 16 steps of 500-step episodes: none ends, so there is nothing to average.
        assert record["episodes"] == [0, 0] and record["success_once"] == [None, None]
        # An untrained policy over 8 actions is near uniform: entropy near ln 8.
        assert all(abs(h - math.log(8)) < 0.1 for h in record["entropy"])
    # The last minibatch of each iteration follows an optimiser step, so its policy differs from the one
    # that collected the data; and the two agents are different agents.
    assert all(kl > 0 for record in lines for kl in record["approx_kl"])
    assert all(record["loss"][0] != record["loss"][1] for record in lines)
