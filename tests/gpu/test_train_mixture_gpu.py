"""The trainer on a mixture on the GPU, with the table's speed flags and each run's environments on a stream of
their own (kage.ppo.streams): a pack of runs on a mixture of one config twice trains as the same pack on that
config, log row for log row and parameter for parameter; a run stopped before or after a schedule's stage
boundary resumes to the uninterrupted run's end. cuDNN's deterministic algorithms make bit equality the test."""
import dataclasses
import pathlib

import pytest
import torch

from kage.ppo import checkpoint, train
from support import ROOT
from test_packing import compare_values, rows
from test_train_mixture import write_schedule

DEVICE = "cuda"
BENCH = ROOT / "configs/kage_bench"
BASE, FILTERED = str(BENCH / "bases/image_skeleton.yaml"), str(BENCH / "filters/5-eval.yaml")
FLAGS = dict(device=DEVICE, bf16=True, fused_input=True, cuda_graph=True, triton_conv=True, total_timesteps=2048,
             num_envs=8, num_steps=64, num_minibatches=2, update_epochs=2, run_eval_every=2, eval_episodes=4,
             eval_num_envs=4, save_checkpoint_every=1)


def assert_same_runs(a: train.Args, b: train.Args) -> None:
    """Run b logged what run a did and ended with its parameters."""
    ra, rb = rows(pathlib.Path(a.out)), rows(pathlib.Path(b.out))
    assert [(r["kind"], r["iteration"]) for r in ra] == [(r["kind"], r["iteration"]) for r in rb]
    for x, y in zip(ra, rb):
        compare_values(x, y, f"{b.out}:{x['kind']}:{x['iteration']}")
    ca, cb = (checkpoint.load(f"{args.out}/checkpoints/latest.pt") for args in (a, b))
    for name, p in ca["agent"].items():
        assert torch.equal(cb["agent"][name], p), f"{name}: max difference {(cb['agent'][name] - p).abs().max()}"


def test_a_pack_on_one_config_twice_trains_as_that_pack(tmp_path, deterministic):
    alone = [train.Args(**FLAGS, train_config_path=BASE, eval_config_path=FILTERED, seed=seed,
                        out=str(tmp_path / f"alone{seed}")) for seed in (3, 4)]
    twice = [dataclasses.replace(a, train_config_path="", train_config_paths=[BASE, BASE],
                                 out=str(tmp_path / f"twice{a.seed}")) for a in alone]
    train.train(alone)
    train.train(twice)
    for a, b in zip(alone, twice):
        assert_same_runs(a, b)


@pytest.mark.parametrize("stop_after", [2, 3])
def test_a_pack_resumes_exactly_across_a_stage_boundary(tmp_path, deterministic, stop_after):
    schedule = write_schedule(tmp_path / "curriculum.yaml", [(1, [BASE], None), (3, [BASE, FILTERED], [3, 1])])
    whole = [train.Args(**dict(FLAGS, run_eval_every=1), train_schedule=schedule, eval_config_path=FILTERED,
                        seed=seed, out=str(tmp_path / f"whole{seed}")) for seed in (5, 6)]
    stopped = [dataclasses.replace(a, out=str(tmp_path / f"stopped{a.seed}")) for a in whole]
    train.train(whole)
    train.train(stopped, stop_after=stop_after)
    assert checkpoint.load(f"{stopped[0].out}/checkpoints/latest.pt")["iteration"] == stop_after
    train.train(stopped)
    for a, b in zip(whole, stopped):
        assert_same_runs(a, b)
        assert checkpoint.load(f"{a.out}/checkpoints/latest.pt")["env_state"] == \
            checkpoint.load(f"{b.out}/checkpoints/latest.pt")["env_state"]
