"""examples/jax_ppo.py: its GAE and optimiser step against hand-computed values, and the whole learner at a tiny
size on the CPU (two agents vmapped, two iterations, each one jit), and its refusals."""
import importlib.util
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

jax = pytest.importorskip("jax", reason="examples/jax_ppo.py needs JAX (pip install jax); CI installs it")
import jax.numpy as jnp  # noqa: E402

from support import ROOT, SIMPLEST  # noqa: E402


def example():
    spec = importlib.util.spec_from_file_location("jax_ppo", ROOT / "examples/jax_ppo.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_gae_on_three_steps():
    # gamma = lambda = 0.5; o_2 starts an episode (dones[2] = 1), so step 1 is an episode's last.
    # t=2: delta = 2 + 0.5 * 4 - 3 = 1,            A = 1
    # t=1: delta = 0 - 2 = -2 (no bootstrap),      A = -2
    # t=0: delta = 1 + 0.5 * 2 - 1 = 1,            A = 1 + 0.25 * (-2) = 0.5
    column = lambda *v: jnp.asarray(v, jnp.float32)[:, None]
    advantages, returns = example().gae(column(1, 2, 3), column(1, 0, 2), column(0, 0, 1) > 0,
                                        jnp.asarray([4.0]), jnp.asarray([False]), 0.5, 0.5)
    np.testing.assert_allclose(np.asarray(advantages)[:, 0], [0.5, -2.0, 1.0])
    np.testing.assert_allclose(np.asarray(returns)[:, 0], [1.5, 0.0, 4.0])


def test_adam_step_clips_the_global_norm_first():
    ppo = example()
    args = ppo.Args(learning_rate=0.1, adam_eps=0.1, max_grad_norm=0.5)
    params = {"a": jnp.float32(1.0), "b": jnp.float32(1.0)}
    # |(3, 4)| = 5 > 0.5: the gradients become (0.3, 0.4). Adam's first step with bias correction moves each
    # parameter by lr * g / (|g| + eps): 0.1 * 0.3 / 0.4 = 0.075 and 0.1 * 0.4 / 0.5 = 0.08.
    new, opt = ppo.adam_step(params, {"a": jnp.float32(3.0), "b": jnp.float32(4.0)}, ppo.adam_init(params), args)
    np.testing.assert_allclose([float(new["a"]), float(new["b"])], [1 - 0.075, 1 - 0.08], rtol=1e-6)
    assert int(opt["count"]) == 1


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


@pytest.mark.parametrize("flags, message", [
    (["--total-timesteps", "10"], "--total-timesteps 10 is less than one iteration"),
    (["--num-envs", "8", "--num-steps", "32", "--num-minibatches", "3"],
     "--num-minibatches 3 does not divide the batch (--num-envs * --num-steps = 256) into equal minibatches: choose "
     "one of 1, 2, 4, 8, 16, 32, 64"),
    (["--norm-adv", "flase"], "argument --norm-adv: 'flase': true or false"),
    (["--num-envs", "0"], "--num-envs 0: a positive number"),
    (["--config", "nothere.yaml"], "jax_ppo.py: --config: config 'nothere.yaml' is neither a path nor a shipped"),
])
def test_a_run_it_cannot_make_is_refused_in_one_line(flags, message):
    done = subprocess.run([sys.executable, str(ROOT / "examples/jax_ppo.py"), *flags], capture_output=True, text=True,
                          timeout=300, env=dict(os.environ))
    assert done.returncode != 0 and message in done.stderr, done.stderr[-2000:]
    assert "Traceback" not in done.stderr
