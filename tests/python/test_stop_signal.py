"""SIGTERM (a scheduler's preemption, `timeout`) stops a run without losing work: kage.bench run passes it
to its training process, which finishes the iteration, checkpoints it (even with periodic checkpoints off)
and exits; kage.bench run exits 143 (130 for Ctrl-C) and the same command then resumes, and the run ends exactly as an
uninterrupted one."""
import json
import signal
import subprocess
import sys
import time

from support import ROOT

TINY = ["--total-timesteps", "512", "--num-envs", "2", "--num-steps", "32", "--num-minibatches", "2",
        "--update-epochs", "1", "--run-eval-every", "4", "--eval-episodes", "2", "--eval-num-envs", "2",
        "--device", "cpu", "--threads", "1", "--save-checkpoint-every", "0"]
TIMING = {"charts/SPS", "charts/SPS_update", "seconds"}


def bench_run(out):
    return subprocess.Popen([sys.executable, "-m", "kage.bench", "run", "suites/kage_bench.yaml", "--pairs",
                             "background/1", "--seeds", "1", "--out", str(out), *TINY],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def rows(run_dir):
    with open(run_dir / "metrics.jsonl") as f:
        return [{k: v for k, v in json.loads(line).items() if k not in TIMING} for line in f]


def train_rows(run_dir):
    if not (run_dir / "metrics.jsonl").exists():
        return 0
    return sum(1 for line in open(run_dir / "metrics.jsonl") if '"kind": "train"' in line)


def stopped_run(out, signum, after_rows):
    """kage.bench run into `out`, sent `signum` once its run has logged `after_rows` training rows: (the runner's
    exit code, its output, the run's directory)."""
    run_dir = out / "runs" / "background" / "1" / "seed_1"
    child = bench_run(out)
    deadline = time.time() + 600
    while time.time() < deadline and child.poll() is None and train_rows(run_dir) < after_rows:
        time.sleep(0.05)
    assert child.poll() is None, "the run ended before it could be stopped"
    child.send_signal(signum)
    output = child.communicate(timeout=300)[0]
    return child.returncode, output, run_dir


def test_sigterm_checkpoints_and_resumes(tmp_path):
    whole, stopped = tmp_path / "whole", tmp_path / "stopped"
    first = bench_run(whole)
    assert first.wait(timeout=900) == 0, first.stdout.read()

    code, output, run_dir = stopped_run(stopped, signal.SIGTERM, 2)
    assert code == 128 + signal.SIGTERM, output
    assert "kage.bench run: stopped background/1 seed 1; run again (or requeue) to resume" in output
    log = (run_dir / "train.log").read_text()
    assert "kage.ppo.train: stopped after iteration" in log
    checkpointed = json.loads((run_dir / "checkpoints" / "latest.json").read_text())["iteration"]
    assert checkpointed == train_rows(run_dir) >= 2  # no finished iteration lost
    assert checkpointed < 8 and not (run_dir / "summary.json").exists()

    resumed = bench_run(stopped)
    output = resumed.communicate(timeout=900)[0]
    assert resumed.returncode == 0, output
    assert f"after iteration {checkpointed}" in (run_dir / "train.log").read_text()
    assert rows(run_dir) == rows(whole / "runs" / "background" / "1" / "seed_1")


def test_ctrl_c_stops_the_runner_with_the_shells_code_for_sigint(tmp_path):
    code, output, _ = stopped_run(tmp_path, signal.SIGINT, 1)
    assert code == 128 + signal.SIGINT, output  # 130, as the trainer's own Ctrl-C
    assert "kage.bench run: stopped background/1 seed 1; run again (or requeue) to resume" in output
