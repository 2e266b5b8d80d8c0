"""lab/tools/pack_gpu_time.py: a method's GPU time from its runs' metrics and files' times, one run per pack, and its
devices from the packs' checksum lists."""
import json
import os
import sys

from support import ROOT

sys.path.insert(0, str(ROOT / "lab/tools"))
import pack_gpu_time  # noqa: E402 (lab/tools is no package)


def run_files(run, sps, eval_seconds, wall):
    """A run's metrics, and its run.json and summary.json `wall` seconds apart."""
    run.mkdir(parents=True)
    for name, at in (("run.json", 1_000_000), ("summary.json", 1_000_000 + wall)):
        (run / name).write_text("{}")
        os.utime(run / name, (at, at))
    rows = [{"kind": "train", "iteration": 1, "global_step": 500, "charts/SPS": 1.0},  # a running mean: not summed
            {"kind": "train", "iteration": 2, "global_step": 1000, "charts/SPS": sps}]
    rows += [{"kind": "eval", "iteration": 2, "seconds": s} for s in eval_seconds]
    (run / "metrics.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))


def test_a_pack_counts_once_from_its_first_run(tmp_path):
    root = tmp_path / "bench"
    (root / "packs").mkdir(parents=True)
    # Pack 0: two runs side by side (the second's numbers must not count); pack 1: one run.
    packs = {"task_0_pack_0.json": ["runs/a/seed_1", "runs/a/seed_2"], "task_1_pack_0.json": ["runs/b/seed_1"]}
    for name, runs in packs.items():
        (root / "packs" / name).write_text(json.dumps(
            {"runs": [{"out": f"/tmp/device-dir/{r}", "seed": 1} for r in runs]}))
    run_files(root / "runs/a/seed_1", 10.0, [2.0, 3.0], 120)  # 1000 / 10 = 100 s training, 5 s evaluation
    run_files(root / "runs/a/seed_2", 1.0, [99.0], 999)
    run_files(root / "runs/b/seed_1", 4.0, [7.0], 300)  # 250 s, 7 s
    time = pack_gpu_time.gpu_time(str(root))
    assert time["packs"] == 2
    assert abs(time["train_hours"] * 3600 - 350.0) < 1e-9
    assert abs(time["eval_hours"] * 3600 - 12.0) < 1e-9
    assert abs(time["wall_hours"] * 3600 - 420.0) < 1e-9


def test_devices_are_named_once_from_the_checksum_lists(tmp_path):
    (tmp_path / "task_0.sha256").write_text("# device: 4 x GPU A\n# commit: abc\n" + "0" * 64 + "  task_0.tar.gz\n")
    (tmp_path / "task_1.sha256").write_text("# device: 1 x GPU B\n# device: 4 x GPU A\n")
    assert pack_gpu_time.devices(str(tmp_path)) == ["1 x GPU B", "4 x GPU A"]
