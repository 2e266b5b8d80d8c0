"""A killed training run resumes from its checkpoint and ends exactly as an uninterrupted one: the same
log rows (no gap, no duplicate), the same parameters, the same summary (CPU, one thread)."""
import json
import os
import signal
import subprocess
import sys
import time

import torch

from kage.ppo import checkpoint
from support import CONFIGS

TIMING = {"charts/SPS", "charts/SPS_update", "seconds"}
FLAGS = ["--train-config-path", str(CONFIGS / "near_goal.yaml"),
         "--eval-config-path", str(CONFIGS / "near_goal_red.yaml"),
         "--seed", "3", "--device", "cpu", "--threads", "1", "--total-timesteps", "192", "--num-envs", "2",
         "--num-steps", "16", "--num-minibatches", "2", "--update-epochs", "2", "--run-eval-every", "2",
         "--eval-episodes", "2", "--eval-num-envs", "2", "--save-checkpoint-every", "1"]


def train(out, **popen):
    return subprocess.Popen([sys.executable, "-m", "kage.ppo.train", *FLAGS, "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, **popen)


def rows(out):
    with open(os.path.join(out, "metrics.jsonl")) as f:
        return [{k: v for k, v in json.loads(line).items() if k not in TIMING} for line in f]


def test_killed_run_resumes_exactly(tmp_path):
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    assert train(whole).wait(timeout=600) == 0

    child = train(killed)
    log = killed / "metrics.jsonl"
    deadline = time.time() + 600
    while time.time() < deadline and child.poll() is None:
        if log.exists() and sum(1 for line in open(log) if '"kind": "train"' in line) >= 3:
            break
        time.sleep(0.05)
    assert child.poll() is None, "the run ended before it could be killed"
    child.send_signal(signal.SIGKILL)
    child.wait()
    assert not (killed / "summary.json").exists()
    interrupted_at = checkpoint.load(killed / "checkpoints/latest.pt")["iteration"]
    assert 1 <= interrupted_at < 6

    resumed = train(killed)
    output = resumed.communicate(timeout=600)[0].decode()
    assert resumed.returncode == 0, output
    assert f"resuming {killed} after iteration {interrupted_at}" in output

    got, want = rows(killed), rows(whole)
    assert [(r["kind"], r["iteration"]) for r in got] == [(r["kind"], r["iteration"]) for r in want]
    assert [r["iteration"] for r in got if r["kind"] == "train"] == [1, 2, 3, 4, 5, 6]
    assert [r["iteration"] for r in got if r["kind"] == "eval"] == [0, 2, 4, 6]
    assert got == want
    a = checkpoint.load(whole / "checkpoints/latest.pt")
    b = checkpoint.load(killed / "checkpoints/latest.pt")
    assert a["agent"].keys() == b["agent"].keys()
    for name in a["agent"]:
        assert torch.equal(a["agent"][name], b["agent"][name]), name
    assert a["env_state"] == b["env_state"]
    assert json.loads((whole / "summary.json").read_text()) == json.loads((killed / "summary.json").read_text())


def test_finished_run_is_left_alone_and_changed_configs_are_refused(tmp_path):
    out = tmp_path / "run"
    assert train(out).wait(timeout=600) == 0
    summary = (out / "summary.json").read_bytes()
    again = train(out)
    assert again.wait(timeout=60) == 0 and b"nothing to do" in again.stdout.read()
    assert (out / "summary.json").read_bytes() == summary

    run = json.loads((out / "run.json").read_text())
    run["configs"]["train"]["spec_sha256"] = "0" * 64  # as if near_goal.yaml had changed since
    (out / "run.json").write_text(json.dumps(run))
    (out / "summary.json").unlink()
    refused = train(out)
    message = refused.communicate(timeout=60)[0].decode()
    assert refused.returncode != 0 and "near_goal.yaml" in message and "changed since" in message
