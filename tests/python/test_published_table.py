"""The published table (results/kage-bench-table) unpacks with its checksums (lab/tools/table_unpack.py), and
`kage.bench report` and `kage.bench compare` run on it, as a user comparing an agent with the baseline runs
them."""
import csv
import json
import shutil
import subprocess
import sys

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
