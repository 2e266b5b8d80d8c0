"""kage.bench on a real Slurm: a single-node cluster on this machine (slurm_cluster.LocalSlurm, as root),
a 2-task job array of tiny CPU runs submitted with `kage.bench slurm --submit`, its results and merged
report; then a task cancelled with scancel while it trains, resubmitted, and resumed from its checkpoint
rather than restarted. Every wait is bounded; a failure shows the daemons' logs and the tasks' logs."""
import json
import subprocess
import sys
import time

from slurm_cluster import ClusterError, LocalSlurm
from support import ROOT, TINY_TRAINING

ENDED = {"COMPLETED", "FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY", "PREEMPTED", "BOOT_FAIL",
         "DEADLINE"}


def with_flags(flags, **changes):
    """TINY_TRAINING with some values changed: with_flags(TINY_TRAINING, total_timesteps=640)."""
    out = list(flags)
    for name, value in changes.items():
        flag = "--" + name.replace("_", "-")
        if flag in out:
            out[out.index(flag) + 1] = str(value)
        else:
            out += [flag, str(value)]
    return out


def bench(slurm, *args):
    return subprocess.run([sys.executable, "-m", "kage.bench", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=300, env=slurm.env)


def submit(slurm, out, pairs, training) -> str:
    result = bench(slurm, "slurm", "suites/kage_bench.yaml", "--pairs", *pairs, "--seeds", "1", "--out", str(out),
                   "--time", "20:00", *training, "--submit")
    if result.returncode != 0:
        raise ClusterError(f"kage.bench slurm --submit failed:\n{result.stderr}\n{slurm.logs()}")
    return result.stdout.strip()


def task_logs(out) -> str:
    logs = sorted((out / "slurm").glob("task_*.log")) + sorted((out / "runs").rglob("train.log"))
    return "\n".join(f"---- {p} ----\n{p.read_text(errors='replace')[-3000:]}" for p in logs)


def wait_until(ready, what: str, timeout: float, logs) -> None:
    deadline = time.monotonic() + timeout
    while not ready():
        if time.monotonic() > deadline:
            raise ClusterError(f"timed out after {timeout:.0f} s waiting for {what}\n{logs()}")
        time.sleep(0.2)


def test_job_array_on_a_local_slurm(tmp_path):
    with LocalSlurm() as slurm:
        # A 2-task array: both runs finish, and one report merges them.
        out = tmp_path / "array"
        pairs = ["background/1", "agent_appearance/1"]
        job = submit(slurm, out, pairs, TINY_TRAINING)
        states = slurm.wait_job(job, lambda s: set(s) == {"0", "1"} and set(s.values()) <= ENDED,
                                "the 2-task array to end", timeout=900)
        assert states == {"0": "COMPLETED", "1": "COMPLETED"}, f"{states}\n{task_logs(out)}"
        for pair in pairs:
            summary = out / "runs" / pair / "seed_1" / "summary.json"
            assert summary.exists(), task_logs(out)
            state = json.loads((summary.parent / "bench_state.json").read_text())
            assert state["slurm_job"] == job and state["state"] == "done"
        reported = bench(slurm, "report", str(out))
        assert reported.returncode == 0, reported.stderr
        report = json.loads((out / "report" / "report.json").read_text())
        assert {p["pair"]: p["n_seeds"] for p in report["levels"]["pairs"]} == {p: 1 for p in pairs}
        status = bench(slurm, "status", str(out))
        assert "2 runs: 2 done, 0 running, 0 failed" in status.stdout, status.stdout

        # A task cancelled while it trains resumes from its checkpoint when submitted again.
        out = tmp_path / "resume"
        run_dir = out / "runs" / "background" / "1" / "seed_1"
        longer = with_flags(TINY_TRAINING, total_timesteps=64 * 40, run_eval_every=100, save_checkpoint_every=1)
        job = submit(slurm, out, ["background/1"], longer)

        def checkpointed() -> int:
            try:
                return json.loads((run_dir / "checkpoints" / "latest.json").read_text())["iteration"]
            except (OSError, ValueError):
                return 0
        wait_until(lambda: checkpointed() >= 2, "the run's second checkpoint", 600,
                   lambda: task_logs(out) + slurm.logs())
        status = bench(slurm, "status", str(out))
        assert "1 run: 0 done, 1 running" in status.stdout, status.stdout
        slurm.command("scancel", job)
        slurm.wait_job(job, lambda s: set(s.values()) <= ENDED, "the cancelled task to end", timeout=120)
        wait_until(lambda: json.loads((run_dir / "bench_state.json").read_text())["state"] == "stopped",
                   "the runner to record the stop", 60, lambda: task_logs(out))
        stopped_at = checkpointed()
        assert 2 <= stopped_at < 40 and not (run_dir / "summary.json").exists()
        status = bench(slurm, "status", str(out))
        assert "1 interrupted" in status.stdout and f"checkpoint at iteration {stopped_at}" in status.stdout

        job = submit(slurm, out, ["background/1"], longer)
        states = slurm.wait_job(job, lambda s: set(s) == {"0"} and set(s.values()) <= ENDED,
                                "the resubmitted task to end", timeout=900)
        assert states == {"0": "COMPLETED"}, f"{states}\n{task_logs(out)}"
        log = (run_dir / "train.log").read_text()
        assert f"kage.ppo.train: resuming {run_dir} after iteration {stopped_at}" in log, log
        rows = [json.loads(line) for line in open(run_dir / "metrics.jsonl")]
        assert [r["iteration"] for r in rows if r["kind"] == "train"] == list(range(1, 41))  # no iteration twice
        assert (run_dir / "summary.json").exists()
