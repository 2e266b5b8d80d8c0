"""The published table (results/kage-bench-table) unpacks with its checksums (lab/tools/table_unpack.py), and
`kage.bench report` and `kage.bench compare` run on it, as a user comparing an agent with the baseline runs
them."""
import csv
import json
import shutil
import subprocess
import sys

import pytest

from support import ROOT
from test_bench_e2e import bench

TABLE = ROOT / "results/kage-bench-table"
UNPACK = ROOT / "lab/tools/table_unpack.py"


def packed_runs() -> int:
    """The runs the packs hold, by their checksum lists: one summary.json a run."""
    return sum(line.rstrip().endswith("/summary.json") for sums in (TABLE / "packs").glob("task_*.sha256")
               for line in open(sums))


def test_report_and_compare_run_on_the_published_table(tmp_path):
    baseline = tmp_path / "baseline"
    unpack = subprocess.run([sys.executable, str(UNPACK), str(TABLE / "packs"), str(baseline)],
                            capture_output=True, text=True)
    assert unpack.returncode == 0, unpack.stderr
    runs = packed_runs()
    assert runs == 90  # the whole table, tasks 0 to 16, published on 2026-11-26

    report = bench("report", str(baseline))
    assert report.returncode == 0, report.stderr
    with open(baseline / "report/report.json") as f:
        written = json.load(f)
    assert written["runs_found"]["finished"] == runs
    pairs_in = sum(p["n_seeds"] > 0 for p in written["levels"]["pairs"])
    assert pairs_in == 34 and {p["n_seeds"] for p in written["levels"]["pairs"]} == {10}  # all 340 results

    shutil.copytree(baseline, tmp_path / "again", ignore=shutil.ignore_patterns("report"))
    compare = bench("compare", str(baseline), str(tmp_path / "again"), "--out", str(tmp_path / "compare"))
    assert compare.returncode == 0, compare.stderr
    # A method against an identical copy of itself: every run ties, so P(X > Y) is exactly one half.
    with open(tmp_path / "compare/improvement.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["n_pairs"]) for r in rows if r["scope"] == "all"] == [pairs_in]
    assert {float(r["p"]) for r in rows} == {0.5}


def stand_in(baseline, out, seeds, steps, last_step):
    """A method trained for `steps` steps on a mixture, on `seeds` of the filters pairs, made from the table's own
    runs: its suite.json trains each filters pair on a mixture, its runs' logs stop at `steps` with a last
    evaluation at `last_step` (a copy of the one before), as a run of `steps` steps logs it."""
    suite = json.loads((baseline / "suite.json").read_text())
    bench = json.loads((baseline / "bench.json").read_text())
    pairs = [p for p in suite["pairs"] if p["declared_axis"] == "filters"]
    for p in pairs:
        p["train"] = {"name": "mixture of 9", "spec_sha256": "f" * 64, "schedule": None, "stages": [
            {"start": 0, "configs": [{"name": "configs/x.yaml", "spec_sha256": "e" * 64, "weight": 1.0}]}]}
    shared = {p["pair"]: bench["shared"][p["pair"]] for p in pairs}
    units = sorted({unit for unit, _ in shared.values()})
    out.mkdir()
    (out / "suite.json").write_text(json.dumps({**suite, "pairs": pairs}))
    (out / "bench.json").write_text(json.dumps({**bench, "seeds": seeds, "shared": shared, "units": units}))
    for unit in units:
        for seed in seeds:
            source, run = baseline / "runs" / unit / f"seed_{seed}", out / "runs" / unit / f"seed_{seed}"
            run.mkdir(parents=True)
            shutil.copy(source / "summary.json", run)
            record = json.loads((source / "run.json").read_text())
            record["args"]["total_timesteps"] = steps
            (run / "run.json").write_text(json.dumps(record))
            rows = [json.loads(line) for line in (source / "metrics.jsonl").read_text().splitlines()]
            rows = [r for r in rows if r.get("global_step", 0) <= steps]
            rows.append({**[r for r in rows if r["kind"] == "eval"][-1], "global_step": last_step})
            (run / "metrics.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    return shared


def test_a_method_of_fewer_steps_seeds_and_pairs_compares_with_the_table(tmp_path):
    """A method of 10 M steps, seeds 1-5, the filters pairs, trained on mixtures, against the table up to step
    10 M: every run's best eval success over its evaluations up to 10 M, the IQM of the 45 recomputed here from
    the table's logs; the stand-in's runs are the table's own, so P(X > Y) is one half."""
    baseline = tmp_path / "baseline"
    unpack = subprocess.run([sys.executable, str(UNPACK), str(TABLE / "packs"), str(baseline)],
                            capture_output=True, text=True)
    assert unpack.returncode == 0, unpack.stderr
    shared = stand_in(baseline, tmp_path / "loo", [1, 2, 3, 4, 5], 10_000_000, 9_994_240)
    filters = [f"filters/{i}" for i in range(1, 10)]
    flags = ["--names", "baseline", "loo", "--seeds", "1-5", "--reps", "2000", "--out", str(tmp_path / "compare")]
    refused = bench("compare", str(baseline), str(tmp_path / "loo"), *flags)
    assert refused.returncode != 0
    assert ("another protocol (total_timesteps 25000000 and 10000000): compare their first N steps with --max-step N "
            "(at most 10000000)") in refused.stderr
    done = bench("compare", str(baseline), str(tmp_path / "loo"), *flags, "--pairs", *filters,
                 "--max-step", "10000000")
    assert done.returncode == 0, done.stderr
    result = json.loads((tmp_path / "compare/compare.json").read_text())
    assert result["pairs"] == filters and result["results_compared"] == 45
    assert [m["trains_on"][0]["name"] for m in result["methods"]] == ["image_skeleton.yaml", "mixture of 9"]
    best = []
    for pair in filters:
        unit, label = shared[pair]
        for seed in range(1, 6):
            log = (baseline / "runs" / unit / f"seed_{seed}" / "metrics.jsonl").read_text().splitlines()
            rows = [r for r in map(json.loads, log) if r["kind"] == "eval" and r["global_step"] <= 10_000_000]
            assert rows[-1]["global_step"] == 12 * 819_200
            best.append(max(r["evals"][label]["success_once"] for r in rows))
    iqm = sum(sorted(best)[11:34]) / 23  # 45 runs, a quarter (11) cut at each end
    assert sum(best) > 0  # the first 10 M steps already succeed on some filters
    for m in result["methods"]:
        assert m["estimates"]["rows"][-1]["eval_iqm"]["point"] == pytest.approx(iqm)
    assert {r["p"]["point"] for r in result["improvement"]} == {0.5}
    assert "their last evaluations scored are at step 9830400 (baseline), 9994240 (loo)" in done.stdout


def test_a_damaged_archive_is_refused_by_name(tmp_path):
    packs = tmp_path / "packs"
    shutil.copytree(TABLE / "packs", packs)
    archive = sorted(packs.glob("task_*.tar.gz"))[0]
    with open(archive, "r+b") as f:
        f.seek(100)
        f.write(b"\0" * 8)
    unpack = subprocess.run([sys.executable, str(UNPACK), str(packs), str(tmp_path / "out")],
                            capture_output=True, text=True)
    assert unpack.returncode != 0
    assert f"{archive}: its sha256 is not the one in" in unpack.stderr
