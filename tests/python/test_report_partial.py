"""kage.bench report --partial: an interim report that includes unfinished runs at their latest evaluation point,
marked as interim in every table and plot, with how far each run got; the default stays finished runs only."""
import csv
import json
import subprocess
import sys

import pytest
from support import ROOT
from test_report import by_name, pair, plain, write_run
from test_report_intervals import full_row, write_suite

from kage.bench import plots, report

M = 1_000_000


def unfinished(bench, unit, seed, history):
    """An unfinished run of 25 M steps: evaluation rows [(step, train, eval)], and a last row cut short."""
    run = write_run(bench, unit, seed, ["eval"], rows=[full_row(step, t, {"eval": e}) for step, t, e in history],
                    tail='{"kind": "eval", "iterat')
    run_json = json.loads((run / "run.json").read_text())
    run_json["args"]["total_timesteps"] = 25 * M
    (run / "run.json").write_text(json.dumps(run_json))


@pytest.fixture
def bench(tmp_path):
    write_suite(tmp_path, [pair("background/1", "background"), pair("background/2", "background")])
    for seed, (t, e) in {1: (0.9, 0.5), 2: (0.8, 0.4)}.items():
        write_run(tmp_path, "background/1", seed, ["eval"], plain(t, e), rows=[full_row(25 * M, t, {"eval": e})])
    # background/1 seed 3 got to 18 M steps, its best evaluation at 9 M; background/2 seed 1 to 18 M, and seed 2
    # has no evaluation yet
    unfinished(tmp_path, "background/1", 3, [(0, 0.0, 0.0), (9 * M, 0.7, 0.3), (18 * M, 0.6, 0.2)])
    unfinished(tmp_path, "background/2", 1, [(0, 0.0, 0.0), (18 * M, 0.5, 0.25)])
    unfinished(tmp_path, "background/2", 2, [])
    return tmp_path


def test_default_report_has_finished_runs_only(bench):
    result = report.report(str(bench), reps=200)
    assert result["out_dir"] == str(bench / "report") and result["interim"] is None
    assert by_name(result["levels"]["pairs"], "pair", "background/1")["n_seeds"] == 2
    assert by_name(result["levels"]["pairs"], "pair", "background/2")["n_seeds"] == 0
    md = (bench / "report" / "axes.md").read_text()
    assert "(interim)" not in md and "3 unfinished, not in the tables" in md
    assert (bench / "report" / "axes.csv").read_text().startswith("axis,")


def test_partial_includes_unfinished_runs_at_their_latest_evaluation(bench):
    result = report.report(str(bench), reps=200, partial=True)
    assert result["out_dir"] == str(bench / "report_interim")
    p1 = by_name(result["levels"]["pairs"], "pair", "background/1")
    assert p1["n_seeds"] == 3 and p1["seeds"] == [1, 2, 3]
    v1 = p1["metrics"]["success_once"]
    # seeds 1 and 2 from summary.json, seed 3 its maximum so far (0.7, 0.3): train 0.8, eval 0.4
    assert v1["train"]["mean"] == pytest.approx(0.8) and v1["eval"]["mean"] == pytest.approx(0.4)
    p2 = by_name(result["levels"]["pairs"], "pair", "background/2")
    assert p2["n_seeds"] == 1 and p2["metrics"]["success_once"]["eval"]["mean"] == pytest.approx(0.25)
    axis = by_name(result["levels"]["axes"], "axis", "background")["metrics"]["success_once"]
    # train (0.8 + 0.5) / 2 = 0.65, eval (0.4 + 0.25) / 2 = 0.325: a 50 % drop
    assert axis["drop_pct"] == pytest.approx(50.0)
    run3 = next(r for r in result["levels"]["runs"] if r["pair"] == "background/1" and r["seed"] == 3)
    assert (run3["finished"], run3["evaluations"], run3["step"], run3["total_steps"]) == (False, 3, 18 * M, 25 * M)
    status = {(r["unit"], r["seed"]): r["in_tables"] for r in result["runs_found"]["unfinished"]}
    assert status == {("background/1", 3): True, ("background/2", 1): True, ("background/2", 2): False}
    assert result["interim"] == ("INTERIM (--partial): 2 unfinished runs included at their latest evaluation, "
                                 "18 M steps of 25 M")
    final = report.report(str(bench), reps=200, partial=True, protocol="final")
    assert final["out_dir"] == str(bench / "report_final_interim")
    run3 = next(r for r in final["levels"]["runs"] if r["pair"] == "background/1" and r["seed"] == 3)
    assert (run3["metrics"]["success_once"]["train"], run3["metrics"]["success_once"]["eval"]) == (0.6, 0.2)


def test_every_interim_file_says_so(bench, monkeypatch):
    marks = []
    original = plots.png_bytes
    monkeypatch.setattr(plots, "png_bytes", lambda figure, interim=None: marks.append(interim) or original(figure))
    result = report.report(str(bench), reps=200, partial=True)
    out = bench / "report_interim"
    pngs = [f for f in result["files"] if f.endswith(".png")]
    assert len(pngs) == len(marks) >= 6 and set(marks) == {result["interim"]}
    for name in [f for f in result["files"] if f.endswith(".md")]:
        text = (out / name).read_text()
        assert text.splitlines()[0].endswith("(interim)") and "**Interim report** (`--partial`)" in text, name
        assert "| background/1 | 3 | 3 | 18 M | 25 M | yes |" in text, name
        assert "| background/2 | 2 | 0 | - | 25 M | no |" in text, name
    for name in [f for f in result["files"] if f.endswith(".csv")]:
        with open(out / name) as f:
            rows = list(csv.reader(f))
        assert rows[0][0] == "interim" and all(r[0] == "yes" for r in rows[1:]), name
    with open(out / "runs.csv") as f:
        runs = [r for r in csv.DictReader(f) if r["metric"] == "success_once"]
    assert {(r["pair"], r["seed"], r["finished"], r["step"]) for r in runs} == {
        ("background/1", "1", "True", str(25 * M)), ("background/1", "2", "True", str(25 * M)),
        ("background/1", "3", "False", str(18 * M)), ("background/2", "1", "False", str(18 * M))}


def test_partial_from_the_command_line(bench):
    done = subprocess.run([sys.executable, "-m", "kage.bench", "report", str(bench), "--partial", "--reps", "200"],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert json.loads((bench / "report_interim" / "report.json").read_text())["interim"].startswith("INTERIM")
