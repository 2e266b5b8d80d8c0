"""Packed runs (kage.bench run --pack K) follow the same algorithm as lone runs: two runs trained together
end with the logs and parameters of the same two runs trained alone (CPU, float32).

Tolerance, from the arithmetic: a pack evaluates its runs with grouped convolutions and batched matrix
products, a lone run with the ungrouped ones; both compute the same sums, possibly in another order, so
activations and gradients may differ by a few float32 roundings (relative 1e-7 per operation, about
1e-6 after a 9,216-term product). A sampled action changes only if two Gumbel-perturbed logits lie within
that distance, which these few hundred draws do not meet: the environments' states and every episode
metric must agree exactly. Losses agree to 1e-4 relative. Adam divides each step by the root of the
gradient's second moment, so an element whose gradient is itself at rounding level can step by up to the
learning rate either way: element-wise, parameters can differ by at most 2 x lr x (optimizer steps), and
such elements are few, so each tensor's difference stays below 1e-2 of its norm."""
import dataclasses
import json

import pytest

from kage.ppo import checkpoint, train
from support import NEAR_GOAL_RUNS as RUNS

FLAGS = dict(device="cpu", threads=1, total_timesteps=192, num_envs=2, num_steps=16, num_minibatches=2, update_epochs=2,
             run_eval_every=3, eval_episodes=2, eval_num_envs=2, save_checkpoint_every=3)
EXACT_PREFIXES = ("train/avg_", "charts/learning_rate", "charts/entropy_coef")


def rows(path):
    with open(path / "metrics.jsonl") as f:
        return [json.loads(line) for line in f]


def compare_values(a, b, where):
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for key in a:
            compare_values(a[key], b[key], f"{where}/{key}")
    elif isinstance(a, float) and where.split("/")[-1].startswith(("SPS", "seconds")):
        return  # timings
    elif isinstance(a, float) and "losses/" in where or "explained_variance" in where:
        assert b == pytest.approx(a, rel=1e-4, abs=1e-6), where
    else:
        assert a == b, where


def test_a_pack_of_two_equals_two_lone_runs(tmp_path):
    lone, packed = [], []
    for i, run in enumerate(RUNS):
        lone.append(train.Args(**FLAGS, **run, out=str(tmp_path / f"lone{i}")))
        packed.append(dataclasses.replace(lone[-1], out=str(tmp_path / f"packed{i}")))
    for args in lone:
        train.train([args])
    train.train(packed)
    for a, b in zip(lone, packed):
        ra, rb = rows(tmp_path / a.out.split("/")[-1]), rows(tmp_path / b.out.split("/")[-1])
        assert [(r["kind"], r["iteration"]) for r in ra] == [(r["kind"], r["iteration"]) for r in rb]
        assert any("train/avg_passed_distance" in r for r in ra), "episodes ended during training"
        for x, y in zip(ra, rb):
            compare_values(x, y, f"{a.out}:{x['kind']}:{x['iteration']}")
        ca = checkpoint.load(f"{a.out}/checkpoints/latest.pt")
        cb = checkpoint.load(f"{b.out}/checkpoints/latest.pt")
        assert ca["env_state"] == cb["env_state"], "the environments saw the same actions"
        steps = ca["optimizer_steps"]
        for name in ca["agent"]:
            difference = ca["agent"][name] - cb["agent"][name]
            assert difference.abs().max() <= 2 * a.learning_rate * steps, name
            assert difference.norm() <= 1e-2 * ca["agent"][name].norm(), name
