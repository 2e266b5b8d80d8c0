"""kage.bench slurm without a cluster: the job array covers every run of the suite exactly once, a task
resolves its configs from whichever directory it starts in, and kage.bench status reports a failed task's
error."""
import json
import os
import re
import subprocess
import sys

from support import ROOT, TINY_TRAINING


def bench(*args, cwd=ROOT, env=None):
    return subprocess.run([sys.executable, "-m", "kage.bench", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=600, env=env)


def test_the_benchmark_array_covers_each_run_once(tmp_path):
    result = bench("slurm", "suites/kage_bench.yaml", "--seeds", "1-10", "--pack", "8", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    script = result.stdout
    assert script == (tmp_path / "slurm" / "kage_bench.sbatch").read_text()
    table = re.findall(r"^# task (\d+): (.*)$", script, re.M)
    assert [int(i) for i, _ in table] == list(range(43))  # 340 runs in tasks of 8
    assert "#SBATCH --array=0-42\n" in script and "#SBATCH --requeue\n" in script
    runs = [tuple(run.rsplit(" seed ", 1)) for _, runs in table for run in runs.split(", ")]
    assert all(len(runs_of_task.split(", ")) <= 8 for _, runs_of_task in table)
    pairs = [p["pair"] for p in json.loads((tmp_path / "suite.json").read_text())["pairs"]]
    assert len(pairs) == 34
    assert sorted(runs) == sorted((pair, str(seed)) for pair in pairs for seed in range(1, 11))
    recorded = json.loads((tmp_path / "tasks.json").read_text())["tasks"]
    assert [[(r["unit"], str(r["seed"])) for r in task] for task in recorded] == \
        [[tuple(run.rsplit(" seed ", 1)) for run in runs.split(", ")] for _, runs in table]


def test_a_task_resolves_its_configs_from_any_directory(tmp_path):
    """The script is written from tmp_path with relative paths, then run by bash from / as Slurm would
    run array tasks 0 and 1 (with their own working directory): both find the suite, configs and DIR."""
    work = tmp_path / "work"
    work.mkdir()
    suite = os.path.relpath(ROOT / "suites" / "kage_bench.yaml", work)
    written = bench("slurm", suite, "--pairs", "background/1", "agent_appearance/1", "--seeds", "1", "--out", "bench",
                    *TINY_TRAINING, cwd=work)
    assert written.returncode == 0, written.stderr
    script = (work / "bench" / "slurm" / "kage_bench.sbatch").read_text()
    assert f"#SBATCH --chdir={work}\n" in script and f"#SBATCH --output={work}/bench/slurm/task_%a.log\n" in script
    assert "--gpus-per-task" not in script  # --device cpu
    command = next(line for line in script.splitlines() if line.startswith("exec "))
    assert f" {ROOT}/suites/kage_bench.yaml " in command and f" --out {work}/bench " in command

    # Task 1's run cannot load its checkpoint: the task fails, and status names the error.
    broken = work / "bench" / "runs" / "agent_appearance" / "1" / "seed_1" / "checkpoints"
    broken.mkdir(parents=True)
    (broken / "latest.pt").write_bytes(b"not a checkpoint")
    (broken / "latest.json").write_text('{"iteration": 1}')
    for task, expected in ((0, 0), (1, 1)):
        env = {**os.environ, "SLURM_ARRAY_TASK_ID": str(task)}
        ran = subprocess.run(["bash", str(work / "bench" / "slurm" / "kage_bench.sbatch")], cwd="/", env=env,
                             capture_output=True, text=True, timeout=600)
        assert ran.returncode == expected, ran.stderr
    assert (work / "bench" / "runs" / "background" / "1" / "seed_1" / "summary.json").exists()

    status = bench("status", str(work / "bench"))
    assert status.returncode == 0, status.stderr
    assert "2 runs: 1 done, 0 running, 1 failed, 0 interrupted, 0 not started" in status.stdout
    failed = next(line for line in status.stdout.splitlines() if line.startswith("  agent_appearance/1 seed 1:"))
    assert "exit 1" in failed and "task 1" in failed and "train.log" in failed
    log = (work / "bench" / "runs" / "agent_appearance" / "1" / "seed_1" / "train.log").read_text()
    assert failed.endswith(log.strip().splitlines()[-1])  # the log's last line: the error


def test_bad_slurm_arguments_are_refused(tmp_path):
    for args, message in (
            (["--array-parallelism", "0"], "--array-parallelism 0: out of range"),
            (["--task", "3"], "--task is for kage.bench run"),
            (["--seeds", "3-1"], "the range 3-1 is empty")):
        result = bench("slurm", "suites/kage_bench.yaml", "--out", str(tmp_path / "b"), *args)
        assert result.returncode != 0 and message in result.stderr, result.stderr
    missing = bench("status", str(tmp_path / "nothing"))
    assert missing.returncode != 0 and "bench.json" in missing.stderr and "not a directory written" in missing.stderr
