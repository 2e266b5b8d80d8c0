"""kage.bench report's interval estimates (IQM, drop with a paired ratio bootstrap, profiles) and --protocol final,
on the hand-made benchmark directory of test_report.py and on small ones written here. Expected values are
worked out here."""
import csv
import json

import numpy as np
import pytest
from test_report import PNG_SIGNATURE, SUITE, bench, by_name, pair, plain, write_run  # noqa: F401 (bench: fixture)

from kage.bench import intervals, report
from kage.bench.interval_tables import fmt_drop

SIDE_METRICS = ("return", "length", "passed_distance", "progress", "jump_count", "success", "success_once")
DIFFS = ("return", "success", "progress", "success_once", "passed_distance", "jump_count")


def full_row(step, train, evals):
    """An evaluation row as kage.ppo.train logs it: every metric of each side (all set to the side's success)
    and every absolute difference."""
    def side(value):
        return {"episodes": 2, **{m: value for m in SIDE_METRICS}}
    return {"kind": "eval", "iteration": step // 10, "global_step": step, "seconds": 1.0, "train": side(train),
            "evals": {label: side(v) for label, v in evals.items()},
            "diffs": {label: {m: abs(train - v) for m in DIFFS} for label, v in evals.items()}}


def rows_for(values):
    """Rows at steps 0, 10, ... from [(train, eval)] of a plain pair."""
    return [full_row(10 * i, t, {"eval": e}) for i, (t, e) in enumerate(values)]


# ---- on test_report's directory (maximum over training) ----

def test_iqm_and_drop_per_axis(bench):
    _, result = bench
    rows = {r["name"]: r for r in result["intervals"]["rows"]}
    assert list(rows) == ["background", "layout", "filters", "all pairs"]
    background = rows["background"]
    assert (background["n_pairs"], background["n_runs"]) == (2, 5)
    # eval maxima 0.3, 0.5, 0.4 and 0.1, 0.3 pooled: 0.1 0.3 0.3 0.4 0.5, one cut at each end: (0.3 + 0.3 + 0.4) / 3
    assert background["eval_iqm"]["point"] == pytest.approx(1 / 3)
    # train 0.9, 0.8, 1.0 and 0.6, 0.8: 0.6 0.8 0.8 0.9 1.0 -> (0.8 + 0.8 + 0.9) / 3
    assert background["train_iqm"]["point"] == pytest.approx(2.5 / 3)
    # the drop of the means over pairs, the axes table's 62.5 %, with an interval around it
    drop = background["drop_pct"]
    assert drop["point"] == pytest.approx(62.5) and drop["low"] < 62.5 < drop["high"]
    assert drop["undefined_fraction"] == 0.0
    for side in ("eval_iqm", "train_iqm"):
        assert background[side]["low"] < background[side]["point"] < background[side]["high"]
    # layout/1's one run has train 0: every IQM 0, no drop at all
    layout = rows["layout"]
    assert layout["eval_iqm"] == {"point": 0.0, "low": 0.0, "high": 0.0}
    assert layout["drop_pct"] == {"point": None, "low": None, "high": None, "undefined_fraction": 1.0}
    assert rows["filters"] == {"scope": "axis", "name": "filters", "n_pairs": 0, "n_runs": 0, "eval_iqm": None,
                               "train_iqm": None, "drop_pct": None}
    assert (rows["all pairs"]["n_pairs"], rows["all pairs"]["n_runs"]) == (3, 6)
    # over all pairs the train mean is (0.9 + 0.7 + 0) / 3 and the eval mean (0.4 + 0.2 + 0) / 3
    assert rows["all pairs"]["drop_pct"]["point"] == pytest.approx(100 * (1.6 - 0.6) / 1.6)


def test_profile_counts_runs_above_each_threshold(bench):
    _, result = bench
    profile = result["intervals"]["profile"]
    taus = profile["taus"]
    assert len(taus) == 101 and taus[0] == 0.0 and taus[-1] == 1.0
    # eval maxima of the 6 runs: 0.3, 0.5, 0.4, 0.1, 0.3, 0.0; above 0.35: 0.5 and 0.4
    assert profile["eval"]["point"][taus.index(0.35)] == pytest.approx(2 / 6)
    assert profile["eval"]["point"][0] == pytest.approx(5 / 6)  # all but layout's 0
    assert profile["train"]["point"][taus.index(0.85)] == pytest.approx(2 / 6)  # 0.9 and 1.0


def test_interval_files(bench):
    path, result = bench
    out = path / "report"
    md = (out / "intervals.md").read_text()
    assert "## Interval estimates of `success_once`" in md
    assert "| background | 2 | 5 | 0.33 [" in md and "| 62.5 % [" in md
    assert "| layout | 1 | 1 | 0.00 [0.00, 0.00] | 0.00 [0.00, 0.00] | n/a |" in md
    assert "| filters | 0 | 0 | - | - | - |" in md
    assert "50,000 stratified bootstrap resamples" in md
    with open(out / "intervals.csv") as f:
        rows = {r["name"]: r for r in csv.DictReader(f)}
    assert float(rows["background"]["eval_iqm"]) == pytest.approx(1 / 3)
    assert rows["layout"]["drop_pct"] == "" and rows["layout"]["drop_undefined_fraction"] == "1.0"
    report_md = (out / "report.md").read_text()
    assert report_md.index("## Per axis") < report_md.index("## Interval estimates") < report_md.index("## Per pair")
    for name in ("intervals.png", "profile_success_once.png"):
        data = (out / "plots" / name).read_bytes()
        assert data.startswith(PNG_SIGNATURE) and len(data) > 5000, name
    assert {"intervals.md", "intervals.csv", "plots/intervals.png"} <= set(result["files"])


# ---- small directories ----

def write_suite(path, pairs, **bench_json):
    path.mkdir(parents=True, exist_ok=True)
    (path / "suite.json").write_text(json.dumps({**SUITE, "pairs": pairs}))
    (path / "bench.json").write_text(json.dumps({"kage_bench": 1, "suite": "suites/hand_made.yaml", "seeds": [1, 2, 3],
                                                 "trainer_args": [], **bench_json}))


def test_a_run_whose_eval_is_half_its_train_drops_50_percent_in_every_resample(tmp_path):
    # Resampling each run's (train, eval) pair together keeps eval = train / 2 in every resample.
    write_suite(tmp_path, [pair("background/1", "background"), pair("background/2", "background")])
    for name, trains in (("background/1", (0.9, 0.5, 0.7)), ("background/2", (0.3, 1.0, 0.6))):
        for seed, t in enumerate(trains, start=1):
            write_run(tmp_path, name, seed, ["eval"], plain(t, t / 2), rows=rows_for([(t, t / 2)]))
    result = report.report(str(tmp_path), reps=2000)
    for row in result["intervals"]["rows"]:
        assert row["drop_pct"] == pytest.approx({"point": 50.0, "low": 50.0, "high": 50.0, "undefined_fraction": 0.0})


def test_protocol_final_takes_the_last_evaluation(tmp_path):
    write_suite(tmp_path, [pair("background/1", "background")])
    # per seed (train, eval) at steps 0, 10, 20; the maxima (0.9, 0.6) come before the end
    histories = {1: [(0.1, 0.0), (0.9, 0.6), (0.7, 0.2)], 2: [(0.2, 0.1), (0.8, 0.5), (0.5, 0.3)]}
    for seed, history in histories.items():
        write_run(tmp_path, "background/1", seed, ["eval"], plain(max(t for t, _ in history),
                                                                  max(e for _, e in history)), rows=rows_for(history))
    final = report.report(str(tmp_path), protocol="final", reps=500)
    assert final["out_dir"] == str(tmp_path / "report_final") and final["protocol"]["score"] == "final"
    run = next(r for r in final["levels"]["runs"] if r["seed"] == 1)["metrics"]["success_once"]
    assert (run["train"], run["eval"], run["max_abs_diff"]) == pytest.approx((0.7, 0.2, 0.5))
    v = by_name(final["levels"]["pairs"], "pair", "background/1")["metrics"]["success_once"]
    # last points: train 0.7, 0.5 -> 0.6; eval 0.2, 0.3 -> 0.25; drop 100 * 0.35 / 0.6
    assert v["train"]["mean"] == pytest.approx(0.6) and v["eval"]["mean"] == pytest.approx(0.25)
    assert v["drop_pct"] == pytest.approx(100 * 0.35 / 0.6)
    assert "at its last evaluation point" in (tmp_path / "report_final" / "axes.md").read_text()
    maxima = report.report(str(tmp_path), reps=500)  # the paper's protocol reads summary.json: 0.9, 0.8
    v = by_name(maxima["levels"]["pairs"], "pair", "background/1")["metrics"]["success_once"]
    assert v["train"]["mean"] == pytest.approx(0.85) and maxima["out_dir"] == str(tmp_path / "report")
    with pytest.raises(SystemExit, match="unknown protocol 'best': choose max or final"):
        report.report(str(tmp_path), protocol="best")


def test_pairs_of_one_train_config_are_one_group():
    # A run depends only on its train config and seed: a/1 and a/2 (train config "ta") have the same runs, b/1
    # (train config "tb") its own; a/3 (also "ta") lacks seed 2 so far, and is resampled on its own.
    def record(pair_name, seed, train, evaluated):
        return {"pair": pair_name, "unit": pair_name, "seed": seed,
                "metrics": {"success_once": {"train": train, "eval": evaluated}}}
    level1 = [record("a/1", 1, 0.9, 0.5), record("a/2", 1, 0.9, 0.4), record("a/1", 2, 0.8, 0.3),
              record("a/2", 2, 0.8, 0.2), record("b/1", 3, 0.7, 0.1), record("a/3", 1, 0.9, 0.6)]
    pairs = [{"pair": name, "train_spec": spec} for name, spec in
             (("a/1", "ta"), ("a/2", "ta"), ("b/1", "tb"), ("c/1", "tc"), ("a/3", "ta"))]
    scores = intervals.scores_of(level1, pairs)
    assert scores.pairs == ["a/1", "a/2", "b/1", "a/3"] and scores.seeds == [1, 2, 3]
    assert scores.groups == ["ta seeds [0, 1]", "ta seeds [0, 1]", "tb seeds [2]", "ta seeds [0]"]
    np.testing.assert_array_equal(scores.eval, [[0.5, 0.4, np.nan, 0.6], [0.3, 0.2, np.nan, np.nan],
                                                [np.nan, np.nan, 0.1, np.nan]])
    np.testing.assert_array_equal(scores.train[:, 0], [0.9, 0.8, np.nan])


def test_metric_progress(tmp_path):
    # No run succeeds, so success gives no drop; progress does.
    write_suite(tmp_path, [pair("background/1", "background")])
    for seed, (train, evaluated) in {1: (0.8, 0.2), 2: (0.6, 0.4), 3: (0.7, 0.3)}.items():
        write_run(tmp_path, "background/1", seed, ["eval"],
                  plain(0.0, 0.0, **{"train/progress": train, "eval/eval/progress": evaluated}),
                  rows=rows_for([(0.0, 0.0)]))
    success = report.report(str(tmp_path), reps=500)
    result = report.report(str(tmp_path), reps=500, metric="progress")
    row = by_name(result["intervals"]["rows"], "name", "background")
    # three values each: nothing cut, so the IQMs are the means 0.7 and 0.3
    assert row["train_iqm"]["point"] == pytest.approx(0.7) and row["eval_iqm"]["point"] == pytest.approx(0.3)
    assert row["drop_pct"]["point"] == pytest.approx(100 * 0.4 / 0.7)
    # Its own folder: the success report beside it stays as it was.
    assert result["out_dir"] == str(tmp_path / "report_progress") and success["out_dir"] == str(tmp_path / "report")
    assert "## Interval estimates of `progress`" in (tmp_path / "report_progress" / "intervals.md").read_text()
    assert "## Interval estimates of `success_once`" in (tmp_path / "report" / "intervals.md").read_text()
    assert (tmp_path / "report_progress" / "plots" / "profile_progress.png").read_bytes().startswith(PNG_SIGNATURE)
    assert not (tmp_path / "report" / "plots" / "profile_progress.png").exists()
    final = report.report(str(tmp_path), protocol="final", reps=100, metric="progress", partial=True)
    assert final["out_dir"] == str(tmp_path / "report_final_progress_interim")
    with pytest.raises(SystemExit, match="take success_once, success, progress, not 'passed_distance'"):
        report.report(str(tmp_path), reps=100, metric="passed_distance")


def test_drop_without_interval_names_its_share_of_resamples():
    # The interval is dropped when a resample's train mean is 0; a share rounding to 0.0 % must not read as none.
    rare = {"point": 14.2, "low": None, "high": None, "undefined_fraction": 3 / 50_000}
    common = {"point": 14.2, "low": None, "high": None, "undefined_fraction": 0.25}
    assert fmt_drop(rare) == "14.2 % [n/a: train 0 in < 0.1 % of resamples]"
    assert fmt_drop(common) == "14.2 % [n/a: train 0 in 25.0 % of resamples]"
