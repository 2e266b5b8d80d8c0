"""The files kage.bench reads back (metrics.jsonl, run.json, summary.json, bench.json, suite.json,
bench_state.json, checkpoints/latest.json, a lock, a checkpoint) must be regular files of a bounded size: a FIFO
is refused at once instead of waited on, a symlink to /dev/zero or a sparse file of gigabytes instead of read
until the memory runs out, each in one line naming the file, what it is and the fix. Every command runs in a
child process with a time limit and a 3 GiB address space, so that the old behaviour (a hang, a MemoryError)
fails the test instead of the machine."""
import json
import os
import resource
import subprocess
import sys

import pytest

from support import NOISY_SKELETON, ROOT, TINY_TRAINING
from test_report import SUITE, curve_rows, pair, plain, write_run

LIMIT_S = 60
ADDRESS_SPACE = 3 << 30


def bounded(*args, address_space=ADDRESS_SPACE):
    """`python3 args...` with at most LIMIT_S seconds and `address_space` bytes of memory; a hang is a failure."""
    def limit():
        if address_space:
            resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))
    try:
        return subprocess.run([sys.executable, *args], cwd=ROOT, capture_output=True, text=True, timeout=LIMIT_S,
                              preexec_fn=limit)
    except subprocess.TimeoutExpired:
        pytest.fail(f"python3 {' '.join(args)} still ran after {LIMIT_S} s (waiting on a FIFO?)")


def refused(done, *names):
    """Failed with one line (no traceback) that names each of `names`."""
    assert done.returncode not in (0, None), done.stdout + done.stderr
    assert "Traceback" not in done.stderr and "MemoryError" not in done.stderr, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    for name in names:
        assert name in lines[0], done.stderr
    return lines[0]


def one_pair(path, seeds=(1,)):
    """A benchmark directory of one finished plain pair."""
    path.mkdir(parents=True, exist_ok=True)
    (path / "suite.json").write_text(json.dumps({**SUITE, "pairs": [pair("layout/1", "layout")]}))
    (path / "bench.json").write_text(json.dumps({"kage_bench": 1, "suite": "s.yaml", "seeds": list(seeds),
                                                 "units": ["layout/1"], "trainer_args": []}))
    for seed in seeds:
        run = write_run(path, "layout/1", seed, ["eval"], plain(0.5, 0.25), rows=curve_rows([0.1, 0.2]))
        (run / "run.json").write_text(json.dumps({"kage_run": 1, "args": {"seed": seed, "total_timesteps": 100}}))
    return path


def fifo(path):
    path.unlink(missing_ok=True)
    os.mkfifo(path)


def dev_zero(path):
    path.unlink(missing_ok=True)
    path.symlink_to("/dev/zero")


def sparse(path):
    """A regular file of 8 GiB that takes no disk space."""
    with open(path, "wb") as f:
        f.truncate(8 << 30)


RUN = "runs/layout/1/seed_1"


@pytest.mark.parametrize("name, make, said", [
    (f"{RUN}/metrics.jsonl", dev_zero, "a character device (a symlink to /dev/zero)"),
    (f"{RUN}/metrics.jsonl", fifo, "a FIFO"),
    (f"{RUN}/summary.json", fifo, "a FIFO"),
    (f"{RUN}/run.json", dev_zero, "a character device"),
    ("suite.json", sparse, "more than such a file can be"),
    ("bench.json", fifo, "a FIFO"),
], ids=["metrics-dev-zero", "metrics-fifo", "summary-fifo", "run-json-dev-zero", "suite-8-gib", "bench-fifo"])
def test_report_refuses_what_is_not_a_regular_file(tmp_path, name, make, said):
    bench = one_pair(tmp_path / "bench")
    make(bench / name)
    refused(bounded("-m", "kage.bench", "report", str(bench)), str(bench / name), said, "kage.bench report")


@pytest.mark.parametrize("make, said", [(fifo, "a FIFO"), (dev_zero, "a character device"),
                                        (sparse, "more than such a file can be")])
def test_status_refuses_a_bench_json_that_is_not_a_regular_file(tmp_path, make, said):
    bench = one_pair(tmp_path / "bench")
    make(bench / "bench.json")
    refused(bounded("-m", "kage.bench", "status", str(bench)), str(bench / "bench.json"), said, "restore it")


def test_status_reads_a_fifo_state_file_and_latest_json_as_damaged(tmp_path):
    """A run's bench_state.json and checkpoints/latest.json that are FIFOs: status goes on, the run listed as
    interrupted with its state file named damaged."""
    bench = one_pair(tmp_path / "bench", seeds=(1, 2))
    (bench / "runs/layout/1/seed_2/summary.json").unlink()
    (bench / "runs/layout/1/seed_2/checkpoints").mkdir()
    fifo(bench / "runs/layout/1/seed_2/checkpoints/latest.json")
    fifo(bench / "runs/layout/1/seed_2/bench_state.json")
    done = bounded("-m", "kage.bench", "status", str(bench))
    assert done.returncode == 0, done.stderr
    assert "2 runs: 1 done, 0 running, 0 failed, 1 interrupted" in done.stdout, done.stdout
    assert "bench_state.json is damaged (a FIFO (named pipe), not a regular file)" in done.stdout, done.stdout


def test_compare_refuses_a_summary_that_is_dev_zero(tmp_path):
    a, b = one_pair(tmp_path / "A"), one_pair(tmp_path / "B")
    dev_zero(b / RUN / "summary.json")
    refused(bounded("-m", "kage.bench", "compare", str(a), str(b), "--reps", "100"),
            str(b / RUN / "summary.json"), "a character device", "kage.bench compare:")


def test_a_checkpoint_that_is_a_fifo_is_refused(tmp_path):
    fifo(tmp_path / "latest.pt")
    done = bounded("-c", "import sys; from kage.ppo import checkpoint\n"
                         "try:\n    checkpoint.load(sys.argv[1])\n"
                         "except checkpoint.CheckpointError as e:\n    sys.exit(str(e))", str(tmp_path / "latest.pt"),
                   address_space=None)
    refused(done, str(tmp_path / "latest.pt"), "a FIFO")


SUITE_YAML = "suite: names\npairs:\n  - name: alone\n    axis: background\n    train: {c}\n    eval: {c}\n"


def test_run_refuses_a_bench_lock_that_is_a_fifo(tmp_path):
    (tmp_path / "suite.yaml").write_text(SUITE_YAML.format(c=NOISY_SKELETON))
    bench = tmp_path / "bench"
    bench.mkdir()
    fifo(bench / "bench.lock")
    done = bounded("-m", "kage.bench", "run", str(tmp_path / "suite.yaml"), "--seeds", "1", "--out", str(bench),
                   *TINY_TRAINING, address_space=None)
    assert done.returncode != 0 and "Traceback" not in done.stderr, done.stderr
    assert str(bench / "bench.lock") in done.stderr and "names no writer" in done.stderr, done.stderr
    assert not (bench / "runs").exists()


def test_run_refuses_a_seed_range_of_ten_billion(tmp_path):
    (tmp_path / "suite.yaml").write_text(SUITE_YAML.format(c=NOISY_SKELETON))
    done = bounded("-m", "kage.bench", "run", str(tmp_path / "suite.yaml"), "--seeds", "0-9999999999", "--out",
                   str(tmp_path / "bench"), *TINY_TRAINING, address_space=8 << 30)
    refused(done, "--seeds", "more than 1,000,000 seeds", "give fewer seeds")
    assert not (tmp_path / "bench").exists()


@pytest.mark.parametrize("command", ["report", "compare"])
def test_a_trillion_resamples_are_refused(tmp_path, command):
    """--reps 10**12 kept every resample's statistic until the memory ran out (a MemoryError at 3 GiB); 0 or -5
    ended in a ValueError traceback from kage.bench.stats."""
    bench = one_pair(tmp_path / "A")
    dirs = [str(bench), str(one_pair(tmp_path / "B"))] if command == "compare" else [str(bench)]
    for reps in ("1000000000000", "0", "-5"):
        refused(bounded("-m", "kage.bench", command, *dirs, "--reps", reps), f"kage.bench {command}: --reps {reps}",
                "a number of bootstrap resamples from 1 to 10,000,000")
