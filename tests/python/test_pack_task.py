"""lab/tools/pack_task.py packs the finished tasks of a benchmark directory for the trip home from a device
machine, within the files a call brings back, and lab/tools/table_unpack.py unpacks them with their checksums."""
import calendar
import hashlib
import json
import os
import subprocess
import sys
import tarfile

from support import ROOT

PACK_TASK = ROOT / "lab/tools/pack_task.py"
UNPACK = ROOT / "lab/tools/table_unpack.py"
TASKS = [[("a/1", 1), ("a/1", 2)], [("b/1", 1)], [("c/1", 1)]]
TEN_TWENTY_TWO = calendar.timegm((2026, 11, 26, 10, 22, 0))  # UTC


def benchmark(root, state="done"):
    """A benchmark directory as `kage.bench run --pack` leaves it, every run finished."""
    root.mkdir()
    (root / "tasks.json").write_text(json.dumps(
        {"pack": 2, "tasks": [[{"unit": u, "seed": s} for u, s in task] for task in TASKS]}))
    (root / "bench.json").write_text("{}")
    (root / "suite.json").write_text("{}")
    (root / "packs").mkdir()
    (root / "packs/task_0_pack_0.log").write_text("kage.ppo.train: done\n")
    for task in TASKS:
        for unit, seed in task:
            run = root / "runs" / unit / f"seed_{seed}"
            (run / "checkpoints").mkdir(parents=True)
            (run / "checkpoints/latest.pt").write_bytes(b"\0" * 64)
            (run / "tensorboard").mkdir()
            (run / "tensorboard/events").write_bytes(b"\1" * 64)
            (run / "metrics.jsonl").write_text(f'{{"unit": "{unit}", "seed": {seed}}}\n')
            (run / "run.json").write_text("{}")
            (run / "summary.json").write_text("{}")
            (run / "bench_state.json").write_text(json.dumps({"state": state}))
    return root


def pack_new(root, dest, max_files):
    return subprocess.run([sys.executable, str(PACK_TASK), str(root), "new", str(dest), str(max_files)],
                          capture_output=True, text=True,
                          env={**os.environ, "KAGE_PACK_PROVENANCE": "device: test"})


def assert_unpacks_to_the_runs(packs, home, root):
    """table_unpack.py unpacks the folder of packs into `home` with every run's metrics as in `root`."""
    unpack = subprocess.run([sys.executable, str(UNPACK), str(packs), str(home)], capture_output=True, text=True)
    assert unpack.returncode == 0, unpack.stderr
    for task in TASKS:
        for unit, seed in task:
            metrics = f"runs/{unit}/seed_{seed}/metrics.jsonl"
            assert (home / metrics).read_text() == (root / metrics).read_text()


def test_new_packs_what_fits_and_ends_with_status_3_for_the_rest(tmp_path):
    root = benchmark(tmp_path / "bench")
    out = tmp_path / "out"
    out.mkdir()
    (out / "call.log").write_text("")
    # Task 0's first run starts at 10:22, its second at 10:24; they end at 10:31 and 10:35.
    for seed, (start, end) in ((1, (0, 9)), (2, (2, 13))):
        run = root / "runs/a/1" / f"seed_{seed}"
        os.utime(run / "run.json", (TEN_TWENTY_TWO + 60 * start,) * 2)
        os.utime(run / "summary.json", (TEN_TWENTY_TWO + 60 * end,) * 2)
    first = pack_new(root, out, 5)  # the log and two tasks' archive and checksum list
    assert first.returncode == 3, first.stderr
    assert "task(s) 2 finished but not packed" in first.stdout
    assert sorted(p.name for p in out.iterdir()) == [
        "call.log", "task_0.sha256", "task_0.tar.gz", "task_1.sha256", "task_1.tar.gz"]

    second = pack_new(root, tmp_path / "next_call", 5)  # the next call packs only what is left
    assert second.returncode == 0, second.stderr
    assert sorted(p.name for p in (tmp_path / "next_call").iterdir()) == ["task_2.sha256", "task_2.tar.gz"]

    with tarfile.open(out / "task_0.tar.gz") as tar:
        names = set(tar.getnames())
    assert {"tasks.json", "bench.json", "suite.json", "packs/task_0_pack_0.log",
            "runs/a/1/seed_2/metrics.jsonl", "runs/a/1/seed_2/summary.json"} <= names
    assert not [n for n in names if "checkpoints" in n or "tensorboard" in n]
    sums = (out / "task_0.sha256").read_text().splitlines()
    assert sums[0] == "# device: test"
    assert sums[1].startswith("# date: 2026-11-26 10:22-10:35 UTC (trained), ")  # task 0's times, set above
    digest = hashlib.sha256((out / "task_0.tar.gz").read_bytes()).hexdigest()
    assert f"{digest}  task_0.tar.gz" in sums

    packs = tmp_path / "packs"  # as results/kage-bench-table/packs gathers the calls' tasks
    packs.mkdir()
    for path in [*out.glob("task_*"), *(tmp_path / "next_call").glob("task_*")]:
        path.rename(packs / path.name)
    assert_unpacks_to_the_runs(packs, tmp_path / "home", root)


def test_new_waits_until_the_runner_marks_the_runs_done(tmp_path):
    root = benchmark(tmp_path / "bench", state="running")  # summary.json written, trainer not yet exited
    result = pack_new(root, tmp_path / "out", 8)
    assert result.returncode == 0, result.stderr
    assert not (tmp_path / "out").exists()
    for state in root.glob("runs/*/*/seed_*/bench_state.json"):
        state.write_text(json.dumps({"state": "done"}))
    result = pack_new(root, tmp_path / "out", 8)
    assert result.returncode == 0, result.stderr
    assert len(list((tmp_path / "out").glob("task_*.tar.gz"))) == 3


def test_an_unfinished_task_is_refused_by_its_runs(tmp_path):
    root = benchmark(tmp_path / "bench")
    (root / "runs/a/1/seed_2/summary.json").unlink()
    result = subprocess.run([sys.executable, str(PACK_TASK), str(root), "0", str(tmp_path / "out")],
                            capture_output=True, text=True)
    assert result.returncode != 0
    assert "task 0 is not finished: no summary.json in runs/a/1/seed_2" in result.stderr


def test_new_bundles_what_passes_the_file_limit_in_one_file(tmp_path):
    root = benchmark(tmp_path / "bench")
    out = tmp_path / "out"
    out.mkdir()
    (out / "call.log").write_text("")
    result = pack_new(root, out, 4)  # the log, task 0's two files, one more
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in out.iterdir()) == ["call.log", "more_tasks.tar", "task_0.sha256", "task_0.tar.gz"]
    with tarfile.open(out / "more_tasks.tar") as tar:
        assert sorted(tar.getnames()) == ["task_1.sha256", "task_1.tar.gz", "task_2.sha256", "task_2.tar.gz"]
        tar.extractall(tmp_path / "packs", filter="data")  # as the packs folder gathers them at home
    for path in out.glob("task_*"):
        path.rename(tmp_path / "packs" / path.name)
    assert_unpacks_to_the_runs(tmp_path / "packs", tmp_path / "home", root)
    assert pack_new(root, tmp_path / "next_call", 4).returncode == 0  # nothing left to pack
    assert not (tmp_path / "next_call").exists() or not list((tmp_path / "next_call").iterdir())


def test_unpack_refuses_the_archives_of_two_benchmarks_in_one_folder(tmp_path):
    """Archives whose bench.json differ beyond the path each runner started from come from two benchmarks (another
    --pairs, --seeds, --pack or trainer flags): unpacked into one folder, report and compare would read one's runs."""
    roots = {}
    every = ["a/1", "b/1", "c/1"]
    for name, suite, units in (("first", "/a/s.yaml", every), ("moved", "/b/s.yaml", every),
                               ("other", "/a/s.yaml", ["c/1"])):
        roots[name] = benchmark(tmp_path / name)
        (roots[name] / "bench.json").write_text(json.dumps({"suite": suite, "units": units}))
        assert pack_new(roots[name], tmp_path / f"out_{name}", 8).returncode == 0
    packs = tmp_path / "packs"
    packs.mkdir()

    def publish(task, name):
        for suffix in (".tar.gz", ".sha256"):
            (tmp_path / f"out_{name}" / f"{task}{suffix}").replace(packs / f"{task}{suffix}")

    publish("task_0", "first")
    publish("task_1", "moved")  # the same benchmark, its runner started from another path: unpacks as one
    publish("task_2", "moved")
    assert_unpacks_to_the_runs(packs, tmp_path / "home", roots["first"])

    publish("task_2", "other")
    result = subprocess.run([sys.executable, str(UNPACK), str(packs), str(tmp_path / "home2")],
                            capture_output=True, text=True)
    assert result.returncode == 1
    assert f"{packs / 'task_2.tar.gz'}: its bench.json differs from {tmp_path / 'home2/bench.json'}" in result.stderr
    assert "unpack each benchmark's archives into a folder of its own" in result.stderr


def test_unpack_names_an_archive_that_is_not_a_task_s(tmp_path):
    root = benchmark(tmp_path / "bench")
    packs = tmp_path / "packs"
    assert pack_new(root, packs, 8).returncode == 0
    (packs / "task_1.tar.gz").rename(packs / "task_1 (copy).tar.gz")  # as a browser names a second download
    result = subprocess.run([sys.executable, str(UNPACK), str(packs), str(tmp_path / "home")],
                            capture_output=True, text=True)
    assert result.returncode == 1
    assert f"{packs / 'task_1 (copy).tar.gz'}: not a task archive (task_I.tar.gz" in result.stderr


def test_tasks_trained_as_one_carry_their_pack_in_each_archive(tmp_path):
    """`kage.bench run --task 1+2` trains tasks 1 and 2 in one pack (packs/task_1+2_pack_0.*): both tasks' archives
    carry its files, no other task's does, and the archives unpack side by side (the same files)."""
    root = benchmark(tmp_path / "bench")
    for suffix in ("json", "log"):
        (root / f"packs/task_1+2_pack_0.{suffix}").write_text(f"the pack of tasks 1 and 2 ({suffix})\n")
    (root / "packs/task_12_pack_0.log").write_text("another benchmark's task 12, had it one\n")
    packs = tmp_path / "packs"
    assert pack_new(root, packs, 8).returncode == 0
    carried = {}
    for task in range(3):
        with tarfile.open(packs / f"task_{task}.tar.gz") as tar:
            carried[task] = sorted(n for n in tar.getnames() if n.startswith("packs/"))
    assert carried == {0: ["packs/task_0_pack_0.log"],
                       1: ["packs/task_1+2_pack_0.json", "packs/task_1+2_pack_0.log"],
                       2: ["packs/task_1+2_pack_0.json", "packs/task_1+2_pack_0.log"]}
    assert_unpacks_to_the_runs(packs, tmp_path / "home", root)
    assert (tmp_path / "home/packs/task_1+2_pack_0.log").read_text() == "the pack of tasks 1 and 2 (log)\n"
