"""kage.bench run --gpus on the CPU, with fake devices (KAGE_BENCH_FAKE_GPUS): one worker per device takes
tasks until none is left, each task's process sees its own device, a rerun trains nothing, and one report
covers every task's runs; the device list is checked and follows an outer CUDA_VISIBLE_DEVICES."""
import json
import os
import subprocess
import sys

import pytest

from kage.bench import gpus, run, tasks
from support import ROOT, TINY_TRAINING

PAIRS = ["background/1", "agent_appearance/1", "distractors/1"]


def bench(*args, fake_gpus="2"):
    env = {**os.environ, "KAGE_BENCH_FAKE_GPUS": fake_gpus}
    env.pop("CUDA_VISIBLE_DEVICES", None)
    return subprocess.run([sys.executable, "-m", "kage.bench", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=900, env=env)


def run_args(out):
    """`kage.bench run` of PAIRS, seed 1, a tiny training each, into `out`: one task a pair."""
    return ["run", "suites/kage_bench.yaml", "--pairs", *PAIRS, "--seeds", "1", "--out", str(out), *TINY_TRAINING]


def test_two_fake_gpus_train_three_tasks(tmp_path):
    out = tmp_path / "bench"
    args = run_args(out)
    first = bench(*args, "--gpus", "all")
    assert first.returncode == 0, first.stderr
    assert "3 tasks, 0 finished earlier; 3 to train on GPUs 0,1" in first.stderr
    devices = {}
    for task, pair in enumerate(PAIRS):
        run_dir = out / "runs" / pair / "seed_1"
        assert (run_dir / "summary.json").exists(), (out / "tasks" / f"task_{task}.log").read_text()
        state = json.loads((run_dir / "bench_state.json").read_text())
        assert state["state"] == "done" and state["task"] == task
        devices[task] = state["gpu"]
    assert devices[0] != devices[1] and set(devices.values()) == {"0", "1"}  # both workers start at once
    assert first.stderr.count(": done · tasks left") == 3

    again = bench(*args, "--gpus", "0,1")
    assert again.returncode == 0 and "3 tasks, 3 finished earlier; 0 to train" in again.stderr, again.stderr

    reported = bench("report", str(out))
    assert reported.returncode == 0, reported.stderr
    report = json.loads((out / "report" / "report.json").read_text())
    assert {p["pair"]: p["n_seeds"] for p in report["levels"]["pairs"]} == {p: 1 for p in PAIRS}
    status = bench("status", str(out))
    assert "3 runs: 3 done, 0 running, 0 failed, 0 interrupted, 0 not started" in status.stdout


def test_tasks_picks_what_the_gpus_train(tmp_path):
    out = tmp_path / "bench"
    args = run_args(out)
    first = bench(*args, "--gpus", "all", "--tasks", "2,0")
    assert first.returncode == 0, first.stderr
    assert "3 tasks, 0 finished earlier; 2 to train (of tasks 2,0) on GPUs 0,1" in first.stderr
    assert "2 runs in" in first.stderr
    trained = [(out / "runs" / pair / "seed_1" / "summary.json").exists() for pair in PAIRS]
    assert trained == [True, False, True]
    rest = bench(*args, "--gpus", "all", "--tasks", "0,1")
    assert rest.returncode == 0 and "3 tasks, 2 finished earlier; 1 to train (of tasks 0,1)" in rest.stderr, rest.stderr
    assert (out / "runs" / PAIRS[1] / "seed_1" / "summary.json").exists()


def test_tasks_joined_by_plus_train_as_one_pack(tmp_path):
    """--tasks 0+2 trains tasks 0 and 2 in one process, one pack of both runs (packs/task_0+2_pack_0.json), on one
    GPU; the runs land where each task's own would, and a rerun finds both finished."""
    out = tmp_path / "bench"
    args = run_args(out)
    first = bench(*args, "--gpus", "all", "--tasks", "0+2")
    assert first.returncode == 0, first.stderr
    assert "3 tasks, 0 finished earlier; 1 to train (of tasks 0+2) on GPUs 0,1" in first.stderr
    assert "[gpu 0] task 0+2: background/1 seed 1, distractors/1 seed 1" in first.stderr
    assert "2 runs in" in first.stderr
    pack = json.loads((out / "packs" / "task_0+2_pack_0.json").read_text())
    assert [run["out"] for run in pack["runs"]] == [str(out / "runs" / PAIRS[p] / "seed_1") for p in (0, 2)]
    for pair in (PAIRS[0], PAIRS[2]):
        state = json.loads((out / "runs" / pair / "seed_1" / "bench_state.json").read_text())
        assert state["state"] == "done" and state["task"] == "0+2" and state["gpu"] == "0"
    assert not (out / "runs" / PAIRS[1] / "seed_1" / "summary.json").exists()
    assert (out / "tasks" / "task_0+2.log").exists() and not (out / "tasks" / "task_0.lock").exists()
    again = bench(*args, "--gpus", "all", "--tasks", "2+0,1")
    assert again.returncode == 0, again.stderr
    assert "3 tasks, 2 finished earlier; 1 to train (of tasks 2+0,1)" in again.stderr
    beyond = bench(*args, "--task", "3")  # the table is written now, so the refusal points at it
    assert beyond.returncode != 0 and f"0 to 2, each named once (see {out / 'tasks.json'})" in beyond.stderr


@pytest.mark.parametrize("extra, message", [
    (["--gpus", "all", "--tasks", "3"], "--tasks 3: the task table of {out} has 3 tasks, 0 to 2, each named once"),
    (["--gpus", "all", "--tasks", "0,1+0"], "--tasks 0,1+0: the task table of {out} has 3 tasks, 0 to 2, each named"),
    (["--gpus", "all", "--tasks", "0+"], "--tasks 0+: use task indices like 0,3,4, or 3+4 to train tasks 3 and 4"),
    (["--task", "3"], "--task 3: the task table of {out} has 3 tasks, 0 to 2, each named once (--dry-run lists "
                      "them)"),
    (["--task", " 1"], "--task  1: use task indices like 0,3,4"),  # int() would take these three
    (["--task", "1_0"], "--task 1_0: use task indices like 0,3,4"),
    (["--task", "\u0663"], "--task \u0663: use task indices like 0,3,4"),
    (["--task", "0,1"], "--task 0,1: one task (or tasks joined by '+', like 3+4); several tasks one after the other: "
                        "--gpus all --tasks 3,4"),
    (["--gpus", "all", "--tasks", "1,1"], "--tasks 1,1: the task table of {out} has 3 tasks"),
    (["--gpus", "all", "--tasks", "one"], "--tasks one: use task indices like 0,3,4"),
    (["--tasks", "0"], "--tasks picks the tasks that --gpus trains: add --gpus all"),
])
def test_tasks_is_checked(tmp_path, extra, message):
    out = tmp_path / "bench"
    refused = bench(*run_args(out), *extra)
    assert refused.returncode != 0 and message.format(out=out) in refused.stderr, refused.stderr
    assert not (out / "runs").exists()


def test_the_device_list_is_checked(monkeypatch):
    monkeypatch.delenv("CUDA_VISIBLE_DEVICES", raising=False)
    monkeypatch.setenv(gpus.FAKE_GPUS, "3")
    assert gpus.parse_gpus("all", "cpu") == ["0", "1", "2"]
    assert gpus.parse_gpus("2,0", "cpu") == ["2", "0"]
    for text, message in (("0,3", "this machine's GPUs are 0 to 2"), ("0,0", "each named once"),
                          ("first", "use 'all' or GPU indices like 0,2")):
        with pytest.raises(SystemExit, match=message):
            gpus.parse_gpus(text, "cpu")
    monkeypatch.setenv(gpus.FAKE_GPUS, "0")
    with pytest.raises(SystemExit, match="torch sees no CUDA GPU"):
        gpus.parse_gpus("all", "cpu")
    with pytest.raises(SystemExit, match="--task and --gpus exclude each other"):
        run.main(["suites/kage_bench.yaml", "--out", "unused", "--gpus", "all", "--task", "0"])


def test_an_outer_allocation_maps_the_indices(monkeypatch):
    """Under Slurm's (or anyone's) CUDA_VISIBLE_DEVICES, index i is the i-th GPU this process sees."""
    monkeypatch.delenv(gpus.FAKE_GPUS, raising=False)
    monkeypatch.setenv("CUDA_VISIBLE_DEVICES", "3,5")
    monkeypatch.setattr(gpus, "device_count", lambda: 2)
    assert gpus.parse_gpus("all", "cuda") == ["3", "5"]
    assert gpus.parse_gpus("1", "cuda") == ["5"]
    with pytest.raises(SystemExit, match="remove --device cpu, or --gpus"):
        gpus.parse_gpus("all", "cpu")


def test_the_eta_counts_the_workers_in_parallel():
    """As when the first of four parallel tasks ends: 600 s a task (weight 60 at 10 s a unit), three of four GPUs
    still busy (590, 580 and 100 s in), six tasks waiting. By hand: the GPUs come free at 0, 10, 20 and 500 s; the
    six waiting tasks take them in that order and then at 600 and 610 s, so the last ends at 610 + 600 = 1,210 s."""
    assert gpus.eta_seconds(10, [60] * 6, [(60, 590, 0, 0), (60, 580, 0, 0), (60, 100, 0, 0)], 4) == 1210
    assert gpus.eta_seconds(10, [], [(60, 100, 0, 0)], 4) == 500  # only the running task's rest
    assert gpus.eta_seconds(100, [1, 1, 1], [], 1) == 300  # one GPU: one task after another
    # Tasks of other weights, handed out longest first to 2 GPUs at 1 s a unit: 50 and 40 start at 0; 30 takes
    # the GPU free at 40 (ends 70); 20 the one free at 50 (ends 70); 10 the one free at 70: the last ends at 80.
    assert gpus.eta_seconds(1, [50, 40, 30, 20, 10], [], 2) == 80


def test_a_running_task_ends_at_its_own_rate_once_it_has_one():
    """A running task's rest comes from its runs' progress once they have trained MEASURED_PROGRESS of it in this
    process: as in a 4-GPU lease, where the weights put a 7-config task's end 6 minutes away when it ended in one."""
    # 95 % of the task in 925 s: the last 5 % at the same rate takes 925 * 0.05 / 0.95 = 48.68 s, whatever its weight
    assert gpus.running_rest(15.4, 85, 925, 0.0, 0.95) == pytest.approx(48.68, abs=0.01)
    # resumed at half its training, three quarters now after 300 s: the last quarter takes 300 s more
    assert gpus.running_rest(15.4, 85, 300, 0.5, 0.75) == pytest.approx(300)
    # too little done in this process to say (the start, the first iterations): the weight's estimate
    assert gpus.running_rest(10, 60, 100, 0.5, 0.51) == 500
    assert gpus.running_rest(10, 60, 700, 0.0, 0.0) == 0  # past its weight's time and nothing known: no rest
    # the parallel case above with measured tasks: ends at 48.7, 300 and 500 s; two waiting tasks of 60 (600 s)
    # take the free GPU at 0 and the one free at 48.7: the last ends at 648.7
    running = [(85, 925, 0.0, 0.95), (85, 300, 0.5, 0.75), (60, 100, 0.0, 0.0)]
    assert gpus.eta_seconds(10, [60, 60], running, 4) == pytest.approx(648.68, abs=0.01)


def test_task_progress_reads_the_runs_metrics(tmp_path):
    """A task's share done: a finished run (summary.json) counts whole, a running one its last training row's
    global_step (a last row cut off mid-write skipped), a run not started yet none."""
    runs = [tmp_path / name for name in ("finished", "running", "waiting")]
    runs[0].mkdir()
    (runs[0] / "summary.json").write_text("{}")
    runs[1].mkdir()
    rows = [{"kind": "train", "global_step": 250, "charts/SPS": 5.0}, {"kind": "eval", "global_step": 300},
            {"kind": "train", "global_step": 300, "charts/SPS": 6.0}]
    (runs[1] / "metrics.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows) + '{"kind": "tra')
    task = [(None, seed, str(run)) for seed, run in enumerate(runs)]
    assert tasks.last_progress(str(runs[1] / "metrics.jsonl")) == (300, 6.0)
    assert tasks.last_progress(str(runs[2] / "metrics.jsonl")) == (0, None)
    assert tasks.task_progress(task, 1000) == pytest.approx((1000 + 300 + 0) / 3000)


def test_tasks_are_handed_out_longest_first():
    """A task's weight is, per run, its configs (train and evals) plus its training (TRAINING_AS_CONFIGS); the
    heaviest task goes first, ties in table order."""
    from types import SimpleNamespace
    unit = lambda evals: SimpleNamespace(evals=["e"] * evals)  # noqa: E731
    table = [[(unit(1), 1, "a")] * 6, [(unit(9), 1, "b")] * 4, [(unit(1), 1, "c")] * 2, [(unit(5), 1, "d")] * 6,
             [(unit(5), 2, "e")] * 6]
    weights = [gpus.task_weight(task) for task in table]
    assert weights == [6 * (2 + gpus.TRAINING_AS_CONFIGS), 4 * (10 + gpus.TRAINING_AS_CONFIGS),
                       2 * (2 + gpus.TRAINING_AS_CONFIGS), 6 * (6 + gpus.TRAINING_AS_CONFIGS),
                       6 * (6 + gpus.TRAINING_AS_CONFIGS)]
    # 252, 200, 84, 276, 276 at TRAINING_AS_CONFIGS = 40: tasks 3 and 4 tie (table order), then 0, 1 and 2
    assert gpus.longest_first(table, gpus.every_task(table)) == [[3], [4], [0], [1], [2]]
    assert gpus.longest_first(table, [[0], [2]]) == [[0], [2]]
    # tasks joined by '+' weigh together: 1+2 (284) before 3 (276), 0 (252) last
    assert gpus.longest_first(table, [[0], [3], [1, 2]]) == [[1, 2], [3], [0]]
