"""Checkpoints are written on a thread while training goes on (kage.ppo.checkpoint_writer): a checkpoint holds the
runs as they were when it was asked for, however long its writing takes, and a write that fails stops training
with the file named. CPU, one thread."""
import errno
import threading

import pytest
import torch

from kage.ppo import checkpoint, rundir, train
from kage.ppo.checkpoint_writer import CheckpointWriter
from support import NEAR_GOAL_RUNS

HOLD_TIMEOUT_S = 120  # far longer than an iteration of this pack on a loaded CPU machine
FLAGS = ["--device", "cpu", "--threads", "1", "--total-timesteps", "160", "--num-envs", "2", "--num-steps", "16",
         "--num-minibatches", "2", "--update-epochs", "2", "--run-eval-every", "2", "--eval-episodes", "2",
         "--eval-num-envs", "2", "--save-checkpoint-every", "1", "--normalize-reward"]


def pack_args(out, iterations_flags=()):
    return [train.parse_args(FLAGS + list(iterations_flags) + [
        "--train-config-path", run["train_config_path"], "--eval-config-path", run["eval_config_path"],
        "--seed", str(run["seed"]), "--out", str(out / f"seed_{run['seed']}")]) for run in NEAR_GOAL_RUNS]


def same_state(a: dict, b: dict, where: str = "") -> None:
    """Every tensor, byte string and number of checkpoint `a` equals `b`'s (the log, its timings and the run
    directory aside)."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), where
        for key in a:
            if key not in ("history", "log", "train_seconds", "identity"):  # identity: its --out
                same_state(a[key], b[key], f"{where}/{key}")
    elif isinstance(a, torch.Tensor):
        assert torch.equal(a, b), where
    else:
        assert a == b, where


def test_a_checkpoint_holds_the_runs_as_they_were_when_asked_for(tmp_path, monkeypatch):
    # A pack of two runs stopped after iteration 2: its last checkpoint is written once training has ended.
    train.train(pack_args(tmp_path / "stopped"), stop_after=2)
    stopped = [checkpoint.load(tmp_path / f"stopped/seed_{run['seed']}/checkpoints/latest.pt") for run in NEAR_GOAL_RUNS]
    assert [c["iteration"] for c in stopped] == [2, 2]

    # The same pack to the end, iteration 2's checkpoint held until the pack has logged iteration 3: a writer that
    # held up training would wait out the timeout and fail the test, not hang it.
    encode, log, written = checkpoint.encode, rundir.RunDir.log, {}
    iteration_3_logged, trained_meanwhile = threading.Event(), []

    def held_encode(state):
        if state["iteration"] == 2:
            trained_meanwhile.append(iteration_3_logged.wait(timeout=HOLD_TIMEOUT_S))
        data = encode(state)
        written.setdefault(state["agent_spec"]["seed"], {})[state["iteration"]] = data
        return data

    def watched_log(self, row):
        if row["iteration"] >= 3:
            iteration_3_logged.set()
        return log(self, row)

    monkeypatch.setattr(rundir.checkpoint, "encode", held_encode)
    monkeypatch.setattr(rundir.RunDir, "log", watched_log)
    train.train(pack_args(tmp_path / "whole"))
    assert trained_meanwhile == [True, True], "iteration 2's checkpoint was not written while training went on"
    for run, reference in zip(NEAR_GOAL_RUNS, stopped):
        assert sorted(written[run["seed"]]) == [1, 2, 3, 4, 5]
        at_2 = tmp_path / f"seed_{run['seed']}_iteration_2.pt"
        at_2.write_bytes(written[run["seed"]][2])
        same_state(reference, checkpoint.load(at_2))
        assert checkpoint.load(tmp_path / f"whole/seed_{run['seed']}/checkpoints/latest.pt")["iteration"] == 5
        assert (tmp_path / f"whole/seed_{run['seed']}/summary.json").exists()


def test_a_checkpoint_that_cannot_be_written_stops_training_with_the_file_named(tmp_path, monkeypatch):
    atomic_write = rundir.atomic_write

    def full_disk(path, data):
        if path.endswith("latest.pt"):
            raise OSError(errno.ENOSPC, "No space left on device", path)
        atomic_write(path, data)

    monkeypatch.setattr(rundir, "atomic_write", full_disk)
    with pytest.raises(OSError) as error:
        train.train(pack_args(tmp_path / "full"))
    assert error.value.errno == errno.ENOSPC
    assert error.value.filename == str(tmp_path / "full/seed_3/checkpoints/latest.pt")
    assert not (tmp_path / "full/seed_3/summary.json").exists()


def test_batches_land_in_order_and_an_error_is_raised_in_the_caller():
    writer, landed = CheckpointWriter(), []
    release = threading.Event()
    writer.submit([lambda: release.wait(5), lambda: landed.append("first")])
    release.set()
    writer.submit([lambda: landed.append("second")])  # waits for the first batch
    writer.wait()
    assert landed == ["first", "second"]

    writer.submit([lambda: (_ for _ in ()).throw(OSError(errno.EIO, "I/O error", "x/latest.pt"))])
    with pytest.raises(OSError, match="x/latest.pt"):
        writer.wait()
    writer.wait()  # the error is raised once


def test_an_error_on_its_way_out_is_not_hidden_by_a_write_that_failed(capsys):
    with pytest.raises(KeyError, match="first"):
        with CheckpointWriter() as writer:
            writer.submit([lambda: (_ for _ in ()).throw(OSError(errno.EIO, "I/O error", "x/latest.pt"))])
            raise KeyError("first")
    assert "also, a checkpoint could not be written" in capsys.readouterr().err
