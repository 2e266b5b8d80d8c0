"""kage.bench report: the three levels of spec 5.1-5.3, the gap and drop, and the files, on a benchmark
directory written by hand with known per-run maxima. Every expected number is worked out here."""
import csv
import json
import math
import socket

import pytest

from kage.bench import report, tables
from support import dead_pid

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
METRICS = ("passed_distance", "progress", "success", "success_once", "return", "length", "jump_count")
DIFFS = ("return", "success", "progress", "success_once", "passed_distance", "jump_count")


# ---- writing a benchmark directory ----

def pair(name, axis, sweep=None, sweep_eval=None):
    return {"pair": name, "sweep": sweep, "sweep_eval": sweep_eval, "declared_axis": axis, "certified": True,
            "train": {"name": f"configs/{name}-train.yaml", "spec_sha256": "aa"},
            "eval": {"name": f"configs/{name}-eval.yaml", "spec_sha256": "bb"}, "problems": [], "lint_ok": True}


SUITE = {"kagec_suite_report": 1, "suite": "hand-made", "manifest": "suites/hand_made.yaml", "passed": 7, "total": 7,
         "pairs": [pair("background/1", "background"), pair("background/2", "background"),
                   pair("layout/1", "layout"), pair("filters/1", "filters"),
                   # manifest order 1.0, 0.0, 0.5: the table sorts the numeric names
                   pair("radial-light/1.0", "filters", "radial-light", "1.0"),
                   pair("radial-light/0.0", "filters", "radial-light", "0.0"),
                   pair("radial-light/0.5", "filters", "radial-light", "0.5")]}


def stat(maximum):
    """A summary statistic whose min, mean and median differ from its max, so that only max can match."""
    return None if maximum is None else {"min": -9.0, "mean": 0.123, "median": 0.321, "max": maximum, "n": 3}


def summary(labels, maxima):
    """summary.json: every key's max 0.5, except the keys of `maxima`."""
    keys = [f"train/{m}" for m in METRICS]
    for label in labels:
        keys += [f"eval/{label}/{m}" for m in METRICS] + [f"diff/{label}/{m}" for m in DIFFS]
    stats = {k: stat(0.5) for k in keys}
    stats.update({k: stat(v) for k, v in maxima.items()})
    return {"kage_summary": 1, "evaluations": 2, "iterations": [0, 50], "global_steps": [0, 100], "stats": stats}


def eval_row(step, train_success, evals_success):
    def side(success):
        return {"episodes": 128, "return": -30.0, "length": 500.0, "passed_distance": 400.0, "progress": 0.8,
                "jump_count": 3.0, "success": success, "success_once": success}
    return {"kind": "eval", "iteration": step // 2, "global_step": step, "seconds": 1.0, "train": side(train_success),
            "evals": {label: side(s) for label, s in evals_success.items()},
            "diffs": {label: {"success_once": abs(train_success - s)} for label, s in evals_success.items()}}


def write_run(bench, unit, seed, labels, maxima=None, rows=(), tail=""):
    """A run directory; finished (summary.json) when `maxima` is given; `tail` is appended to metrics.jsonl."""
    run = bench / "runs" / unit / f"seed_{seed}"
    run.mkdir(parents=True)
    configs = {"train": {"path": "t.yaml", "spec_sha256": "aa"},
               **{label: {"path": "e.yaml", "spec_sha256": "bb"} for label in labels}}
    (run / "run.json").write_text(json.dumps({"kage_run": 1, "args": {"seed": seed, "eval_config_labels": labels},
                                              "configs": configs}))
    train_row = {"kind": "train", "iteration": 1, "global_step": 50, "charts/SPS": 1000.0}
    lines = [json.dumps(train_row)] + [json.dumps(r) for r in rows]
    (run / "metrics.jsonl").write_text("\n".join(lines) + "\n" + tail)
    if maxima is not None:
        record = summary(labels, maxima)
        steps = [r["global_step"] for r in rows if r.get("kind") == "eval"]
        if steps:  # the evaluations the log holds, as the trainer's summary counts them
            record.update(evaluations=len(steps), global_steps=steps)
        (run / "summary.json").write_text(json.dumps(record))
    return run


def plain(train_success, eval_success, **more):
    values = {"train/success_once": train_success, "eval/eval/success_once": eval_success}
    values.update(more)
    return values


def curve_rows(train_values):
    return [eval_row(step, v, {"eval": v / 2}) for step, v in zip((0, 100), train_values)]


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    bench = tmp_path_factory.mktemp("bench")
    (bench / "suite.json").write_text(json.dumps(SUITE))
    (bench / "bench.json").write_text(json.dumps({"kage_bench": 1, "suite": "suites/hand_made.yaml",
                                                  "seeds": [1, 2, 3, 4], "trainer_args": []}))
    # background/1: three finished seeds and an unfinished one, killed while writing its last log row.
    distance = {1: 480.0, 2: 490.0, 3: 500.0}
    eval_distance = {1: 300.0, 2: 330.0, 3: 360.0}
    for seed, (t, e, d) in {1: (0.9, 0.3, 0.6), 2: (0.8, 0.5, 0.4), 3: (1.0, 0.4, 0.65)}.items():
        write_run(bench, "background/1", seed, ["eval"], plain(
            t, e, **{"diff/eval/success_once": d, "train/passed_distance": distance[seed],
                     "eval/eval/passed_distance": eval_distance[seed]}), rows=curve_rows([0.1 * seed, 0.3 * seed]))
    write_run(bench, "background/1", 4, ["eval"], rows=curve_rows([0.2]), tail='{"kind": "eval", "iterat')
    # background/2: two seeds.
    for seed, (t, e, d) in {1: (0.6, 0.1, 0.5), 2: (0.8, 0.3, 0.7)}.items():
        write_run(bench, "background/2", seed, ["eval"], plain(t, e, **{"diff/eval/success_once": d}),
                  rows=curve_rows([0.5, 0.7]))
    # layout/1: one seed that never succeeds, and whose returns were all zero (null).
    write_run(bench, "layout/1", 1, ["eval"], plain(0.0, 0.0, **{"train/return": None, "eval/eval/return": None}),
              rows=curve_rows([0.0, 0.0]))
    # filters/1: no run. radial-light: one run per seed evaluates the three eval configs.
    sweep_labels = ["1.0", "0.0", "0.5"]
    for seed, (t, e00, e05, e10) in {1: (0.8, 0.8, 0.4, 0.0), 2: (1.0, 1.0, 0.6, 0.2)}.items():
        write_run(bench, "radial-light", seed, sweep_labels, {
            "train/success_once": t, "eval/0.0/success_once": e00, "eval/0.5/success_once": e05,
            "eval/1.0/success_once": e10}, rows=[eval_row(0, t, {"0.0": e00, "0.5": e05, "1.0": e10})])
    result = report.report(str(bench))
    return bench, result


def test_a_killed_reports_temporary_files_are_removed_by_the_next_report(bench):
    path, _ = bench
    host = socket.gethostname()
    strays = [path / "report" / f"axes.md.tmp.{host}.{dead_pid()}.ab12cd",
              path / "report" / "plots" / f"drop_per_axis.png.tmp.{host}.{dead_pid()}.cd34ef"]
    for stray in strays:
        stray.write_bytes(b"\0" * 4096)
    report.report(str(path))
    assert not any(stray.exists() for stray in strays)


@pytest.mark.parametrize("text, found", [("[]", "not an object"), ('{"seeds": ["1"]}', "'seeds'"),
                                         ('{"units": [3], "seeds": [1]}', "'units'"),
                                         ('{"seeds": [1], "trainer_args": 5}', "'trainer_args'")],
                         ids=["list", "seeds", "units", "trainer_args"])
def test_a_damaged_bench_json_is_refused_by_name(tmp_path, text, found):
    (tmp_path / "suite.json").write_text(json.dumps(SUITE))
    (tmp_path / "bench.json").write_text(text)
    with pytest.raises(SystemExit) as refused:
        report.report(str(tmp_path))
    message = str(refused.value)
    assert str(tmp_path / "bench.json") in message and found in message and "fix or delete it" in message, message


def test_without_bench_json_shared_runs_are_not_left_out_silently(tmp_path):
    """Only bench.json's "shared" names the pairs of the runs in runs/shared/ (--share-training): without it (or with
    a bench.json that lacks it) the report would leave them out of every table, so it is refused."""
    (tmp_path / "suite.json").write_text(json.dumps(SUITE))
    (tmp_path / "runs" / "shared").mkdir(parents=True)
    for text in (None, '{"seeds": [1]}'):
        if text is not None:
            (tmp_path / "bench.json").write_text(text)
        with pytest.raises(SystemExit, match=r"bench.json (not found|is damaged \(no 'shared'\)): restore it: its "
                                             r"'shared' names the pairs of the runs in runs/shared/"):
            report.report(str(tmp_path))


def by_name(entries, key, name):
    return next(e for e in entries if e[key] == name)


# ---- the levels ----

def test_level_1_is_each_runs_maximum_and_its_gap(bench):
    _, result = bench
    run = next(r for r in result["levels"]["runs"] if r["pair"] == "background/1" and r["seed"] == 1)
    v = run["metrics"]["success_once"]
    assert v["train"] == 0.9 and v["eval"] == 0.3 and v["max_abs_diff"] == 0.6
    assert v["gap"] == pytest.approx(0.6)
    assert v["drop_pct"] == pytest.approx(100 * 0.6 / 0.9)
    assert len(result["levels"]["runs"]) == 3 + 2 + 1 + 2 * 3  # finished runs x eval configs


def test_level_2_mean_and_sem_over_seeds(bench):
    _, result = bench
    p = by_name(result["levels"]["pairs"], "pair", "background/1")
    assert p["n_seeds"] == 3 and p["seeds"] == [1, 2, 3]  # seed 4 is unfinished
    v = p["metrics"]["success_once"]
    # train 0.9, 0.8, 1.0: mean 0.9, s = sqrt((0 + 0.01 + 0.01) / 2) = 0.1; eval 0.3, 0.5, 0.4: mean 0.4, s = 0.1
    assert v["train"]["mean"] == pytest.approx(0.9) and v["train"]["sem"] == pytest.approx(0.1 / math.sqrt(3))
    assert v["eval"]["mean"] == pytest.approx(0.4) and v["eval"]["sem"] == pytest.approx(0.1 / math.sqrt(3))
    assert v["gap"] == pytest.approx(0.5)
    assert v["drop_pct"] == pytest.approx(100 * 0.5 / 0.9)
    # max |diff| 0.6, 0.4, 0.65: mean 0.55, s^2 = (0.0025 + 0.0225 + 0.01) / 2 = 0.0175
    assert v["max_abs_diff"]["mean"] == pytest.approx(0.55)
    assert v["max_abs_diff"]["sem"] == pytest.approx(math.sqrt(0.0175 / 3))
    d = p["metrics"]["passed_distance"]
    # train 480, 490, 500: mean 490; eval 300, 330, 360: mean 330, s = 30
    assert d["train"]["mean"] == pytest.approx(490.0) and d["eval"]["sem"] == pytest.approx(30 / math.sqrt(3))
    assert d["drop_pct"] == pytest.approx(100 * 160 / 490)

    v2 = by_name(result["levels"]["pairs"], "pair", "background/2")["metrics"]["success_once"]
    # train 0.6, 0.8: mean 0.7, s = sqrt(0.02), SEM = sqrt(0.02) / sqrt(2) = 0.1
    assert v2["train"]["mean"] == pytest.approx(0.7) and v2["train"]["sem"] == pytest.approx(0.1)
    assert v2["eval"]["mean"] == pytest.approx(0.2) and v2["eval"]["sem"] == pytest.approx(0.1)
    assert v2["drop_pct"] == pytest.approx(100 * 0.5 / 0.7)


def test_level_3_weights_each_pair_equally_and_drops_the_means(bench):
    _, result = bench
    axis = by_name(result["levels"]["axes"], "axis", "background")
    assert axis["n_pairs"] == 2 and axis["pairs"] == ["background/1", "background/2"]
    v = axis["metrics"]["success_once"]
    # pair means: train 0.9, 0.7 -> 0.8, SEM 0.1; eval 0.4, 0.2 -> 0.3, SEM 0.1
    assert v["train"]["mean"] == pytest.approx(0.8) and v["train"]["sem"] == pytest.approx(0.1)
    assert v["eval"]["mean"] == pytest.approx(0.3) and v["eval"]["sem"] == pytest.approx(0.1)
    assert v["gap"] == pytest.approx(0.5)
    # the drop of the axis means, 62.5 %, not the mean of the pairs' drops (55.6 % and 71.4 %)
    assert v["drop_pct"] == pytest.approx(62.5)
    assert v["max_abs_diff"]["mean"] == pytest.approx((0.55 + 0.6) / 2)


def test_one_seed_has_sem_0_and_a_zero_train_value_no_drop(bench):
    _, result = bench
    v = by_name(result["levels"]["pairs"], "pair", "layout/1")["metrics"]["success_once"]
    assert v["train"] == {"mean": 0.0, "sem": 0.0, "n": 1} and v["eval"] == {"mean": 0.0, "sem": 0.0, "n": 1}
    assert v["gap"] == 0.0 and v["drop_pct"] is None
    axis = by_name(result["levels"]["axes"], "axis", "layout")["metrics"]["success_once"]
    assert axis["train"]["sem"] == 0.0 and axis["drop_pct"] is None
    returns = by_name(result["levels"]["pairs"], "pair", "layout/1")["metrics"]["return"]
    assert returns["train"] == {"mean": None, "sem": None, "n": 0} and returns["gap"] is None


def test_a_pair_without_runs_has_n_0_and_sweeps_stay_out_of_the_axes(bench):
    _, result = bench
    p = by_name(result["levels"]["pairs"], "pair", "filters/1")
    assert p["n_seeds"] == 0 and p["metrics"]["success_once"]["train"]["mean"] is None
    axis = by_name(result["levels"]["axes"], "axis", "filters")
    assert axis["n_pairs"] == 0 and axis["pairs"] == ["filters/1"]
    assert axis["metrics"]["success_once"]["eval"]["mean"] is None
    assert [a["axis"] for a in result["levels"]["axes"]] == ["background", "layout", "filters"]


def test_sweep_table_orders_numeric_names_and_drops_each_eval(bench):
    _, result = bench
    (sweep,) = result["levels"]["sweeps"]
    assert sweep["sweep"] == "radial-light" and sweep["n_seeds"] == 2
    assert [e["sweep_eval"] for e in sweep["evals"]] == ["0.0", "0.5", "1.0"]
    expected_eval = {"0.0": 0.9, "0.5": 0.5, "1.0": 0.1}  # (0.8 + 1.0) / 2, (0.4 + 0.6) / 2, (0.0 + 0.2) / 2
    for e in sweep["evals"]:
        v = e["metrics"]["success_once"]
        assert v["train"]["mean"] == pytest.approx(0.9) and v["train"]["sem"] == pytest.approx(0.1)
        assert v["eval"]["mean"] == pytest.approx(expected_eval[e["sweep_eval"]])
        assert v["eval"]["sem"] == pytest.approx(0.1)
        assert v["drop_pct"] == pytest.approx(100 * (0.9 - expected_eval[e["sweep_eval"]]) / 0.9)


def test_unfinished_and_not_started_runs_are_listed(bench):
    path, result = bench
    found = result["runs_found"]
    assert found["finished"] == 3 + 2 + 1 + 2
    assert [(r["unit"], r["seed"]) for r in found["unfinished"]] == [("background/1", 4)]
    # bench.json asks for seeds 1-4: background/2 lacks 2, layout/1 3, filters/1 4, radial-light 2
    assert len(found["not_started"]) == 11
    assert "1 unfinished, not in the tables: background/1 seed 4" in (path / "report" / "pairs.md").read_text()


# ---- the files ----

def test_files_exist_and_plots_are_png(bench):
    path, result = bench
    out = path / "report"
    assert result["out_dir"] == str(out)
    for name in ("axes.md", "axes.csv", "pairs.md", "pairs.csv", "sweeps.md", "sweeps.csv", "runs.csv", "report.md",
                 "report.json"):
        assert (out / name).stat().st_size > 0, name
    assert json.loads((out / "report.json").read_text()) == result
    pngs = ["curves_background_1.png", "curves_background_1_return.png", "curves_background_2.png",
            "curves_layout_1.png", "drop_per_axis.png", "sweep_radial-light.png"]
    for name in pngs:
        data = (out / "plots" / name).read_bytes()
        assert data.startswith(PNG_SIGNATURE) and len(data) > 5000, name
    assert not (out / "plots" / "curves_filters_1.png").exists()  # no run, no curve
    assert not [p for p in out.rglob("*.tmp.*")]


def test_csv_rows(bench):
    path, _ = bench
    with open(path / "report" / "pairs.csv") as f:
        rows = {(r["pair"], r["metric"]): r for r in csv.DictReader(f)}
    row = rows[("background/1", "success_once")]
    assert row["n_seeds"] == "3" and float(row["train_mean"]) == pytest.approx(0.9)
    assert float(row["drop_pct"]) == pytest.approx(100 * 0.5 / 0.9)
    assert float(row["max_abs_diff_mean"]) == pytest.approx(0.55)
    assert rows[("layout/1", "success_once")]["drop_pct"] == ""
    assert rows[("filters/1", "success")]["n_seeds"] == "0" and rows[("filters/1", "success")]["train_mean"] == ""
    assert rows[("background/1", "length")]["max_abs_diff_mean"] == ""  # no difference is logged for length
    with open(path / "report" / "axes.csv") as f:
        axes = {(r["axis"], r["metric"]): r for r in csv.DictReader(f)}
    assert float(axes[("background", "success_once")]["drop_pct"]) == pytest.approx(62.5)
    assert axes[("background", "success_once")]["n_pairs"] == "2"


def test_markdown_shows_success_once_as_success(bench):
    path, result = bench
    axes_md = (path / "report" / "axes.md").read_text()
    assert result["markdown_success_column"] == "success_once"
    assert "| background | 2 | 0.80 ± 0.10 | 0.30 ± 0.10 | 0.50 | 62.5 % |" in axes_md
    assert "| layout | 1 | 0.00 ± 0.00 | 0.00 ± 0.00 | 0.00 | n/a |" in axes_md
    assert "| filters | 0 | - | - | - | - |" in axes_md
    assert "success is `success_once`" in axes_md
    report_md = (path / "report" / "report.md").read_text()
    assert report_md.index("## Per axis") < report_md.index("## Per pair") < report_md.index("## Sweeps")


# ---- the pure functions ----

def test_mean_sem():
    assert report.mean_sem([0.5]) == {"mean": 0.5, "sem": 0.0, "n": 1}
    assert report.mean_sem([]) == {"mean": None, "sem": None, "n": 0}
    # 1 and 3 (None left out): mean 2, s = sqrt(2), SEM = sqrt(2) / sqrt(2) = 1
    assert report.mean_sem([1.0, None, 3.0]) == pytest.approx({"mean": 2.0, "sem": 1.0, "n": 2})


def test_gap_and_drop():
    gap, drop = report.gap_and_drop(0.83, 0.11)  # the paper's filters axis
    assert gap == pytest.approx(0.72) and drop == pytest.approx(86.746987951807)
    assert report.gap_and_drop(0.0, 0.2) == (-0.2, None)
    assert report.gap_and_drop(None, 0.2) == (None, None)


def test_curve_is_the_per_step_mean_over_the_runs_that_reached_it():
    runs = [curve_rows([0.0, 0.5]), curve_rows([0.2, 0.7]), curve_rows([0.1])]  # the third stopped early
    (step0, first), (step100, second) = report.curve(runs, None, "success_once")
    assert (step0, step100) == (0, 100)
    # step 0: 0.0, 0.2, 0.1 -> mean 0.1, s = 0.1; step 100: 0.5, 0.7 -> mean 0.6, s = sqrt(0.02)
    assert first == pytest.approx({"mean": 0.1, "sem": 0.1 / math.sqrt(3), "n": 3})
    assert second == pytest.approx({"mean": 0.6, "sem": 0.1, "n": 2})
    (_, eval0), _ = report.curve(runs, "eval", "success_once")
    assert eval0["mean"] == pytest.approx(0.05)  # the eval sides are half the train values


def test_number_format():
    assert tables.fmt_stat({"mean": 0.8312, "sem": 0.0234, "n": 3}) == "0.83 ± 0.02"
    assert tables.fmt_value(12.345) == "12.3"
    assert tables.fmt_value(480.4) == "480"
    assert tables.fmt_value(-3456.2) == "-3456"


# ---- bad input ----

def test_missing_directory_and_suite_json(tmp_path):
    with pytest.raises(SystemExit, match="is not a directory"):
        report.report(str(tmp_path / "absent"))
    with pytest.raises(SystemExit, match=r"suite.json not found: is .* written by `python3 -m kage.bench run`"):
        report.report(str(tmp_path))


def one_pair_bench(tmp_path):
    (tmp_path / "suite.json").write_text(json.dumps({**SUITE, "pairs": [pair("layout/1", "layout")]}))
    return write_run(tmp_path, "layout/1", 1, ["eval"], plain(0.5, 0.25), rows=curve_rows([0.1, 0.2]))


def test_a_damaged_log_line_before_the_last_is_an_error(tmp_path):
    run = one_pair_bench(tmp_path)
    lines = (run / "metrics.jsonl").read_text().splitlines()
    (run / "metrics.jsonl").write_text("\n".join([lines[0], '{"kind": "ev', *lines[1:]]) + "\n")
    with pytest.raises(SystemExit, match=r"metrics.jsonl, line 2: not a JSON row"):
        report.report(str(tmp_path))


def test_a_summary_of_another_shape_is_an_error(tmp_path):
    run = one_pair_bench(tmp_path)
    (run / "summary.json").write_text(json.dumps({"kage_summary": 1, "stats": {"train/success": {"min": 0.0}}}))
    with pytest.raises(SystemExit, match=r"summary.json is not a kage.ppo.train summary.*delete it and rerun"):
        report.report(str(tmp_path))
    (run / "summary.json").write_text(json.dumps({"kage_summary": 1, "stats": {}}))
    with pytest.raises(SystemExit, match=r"summary.json has no 'train/passed_distance'"):
        report.report(str(tmp_path))
