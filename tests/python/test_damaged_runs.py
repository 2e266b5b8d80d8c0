"""Damaged run data is refused by name, never read as something else: duplicated or out-of-order evaluation rows
(which --protocol final would misread as the last evaluation), a bench.json whose seeds kage.bench run would not
train or whose units leave DIR/runs/ (which status and report would count differently), an evaluation row whose
sides are not objects of numbers, one seed in two folders, records of the wrong shape, and a summary.json whose
values or last evaluation its run could not have written beside its log. Each refusal is one
SystemExit line naming the file and the fix; the values expected are worked out here."""
import io
import json

import pytest

from kage.bench import report, status
from test_report import SUITE, pair, plain, write_run
from test_report_intervals import full_row as eval_row


def bench_dir(tmp_path, rows, seeds=(1,)):
    """A benchmark directory of one finished plain pair, layout/1, whose runs log `rows`."""
    (tmp_path / "suite.json").write_text(json.dumps({**SUITE, "pairs": [pair("layout/1", "layout")]}))
    (tmp_path / "bench.json").write_text(json.dumps({"kage_bench": 1, "suite": "s.yaml", "seeds": list(seeds),
                                                     "units": ["layout/1"], "trainer_args": []}))
    return [write_run(tmp_path, "layout/1", seed, ["eval"], plain(1.0, 1.0), rows=rows) for seed in seeds]


def refusal(call, *names):
    with pytest.raises(SystemExit) as refused:
        call()
    message = str(refused.value)
    assert "\n" not in message, message
    for name in names:
        assert name in message, message
    return message


# ---- evaluation rows ----

def test_final_protocol_refuses_a_duplicated_evaluation_row(tmp_path):
    """The first evaluation (success 1) written again after the last (success 0): the final protocol read the
    duplicate as the final checkpoint's, 1.00 where the run ended at 0.00."""
    rows = [eval_row(0, 1.0, {"eval": 1.0}), eval_row(100, 0.0, {"eval": 0.0})]
    run, = bench_dir(tmp_path, rows + [rows[0]])
    refusal(lambda: report.report(str(tmp_path), protocol="final", reps=100), str(run / "metrics.jsonl"), "line 4",
            "duplicated or out-of-order", "line 3 (step 100)")


def test_an_out_of_order_evaluation_row_is_refused(tmp_path):
    rows = [eval_row(0, 0.1, {"eval": 0.1}), eval_row(100, 0.0, {"eval": 0.0}), eval_row(50, 0.9, {"eval": 0.9})]
    run, = bench_dir(tmp_path, rows)
    for protocol in ("final", "max"):
        refusal(lambda: report.report(str(tmp_path), protocol=protocol, partial=True, reps=100),
                str(run / "metrics.jsonl"), "line 4: an evaluation row at step 50, not after the one of line 3")


def test_rows_in_order_still_give_the_last_evaluation(tmp_path):
    bench_dir(tmp_path, [eval_row(0, 1.0, {"eval": 1.0}), eval_row(100, 0.25, {"eval": 0.0})])
    result = report.report(str(tmp_path), protocol="final", reps=100)
    run, = result["levels"]["runs"]
    assert (run["metrics"]["success_once"]["train"], run["metrics"]["success_once"]["eval"]) == (0.25, 0.0)


@pytest.mark.parametrize("change, said", [
    (lambda row: row["evals"].update(eval=None), 'evals["eval"] is null, not an object'),
    (lambda row: row.update(train=None), "without global_step, train and evals"),
    (lambda row: row["train"].update(success_once="1.0"), 'train has success_once = "1.0", not a number or null'),
    (lambda row: row.update(diffs=[]), "diffs are [], not an object"),
    (lambda row: row["diffs"].update(eval={"success_once": [0.5]}), 'diffs["eval"] has success_once = [0.5]'),
], ids=["eval-null", "train-null", "string-value", "diffs-list", "list-value"])
def test_an_evaluation_row_of_another_shape_is_refused(tmp_path, change, said):
    row = eval_row(100, 0.5, {"eval": 0.5})
    change(row)
    run, = bench_dir(tmp_path, [eval_row(0, 0.5, {"eval": 0.5}), row])
    for protocol in ("final", "max"):
        refusal(lambda: report.report(str(tmp_path), protocol=protocol, reps=100), str(run / "metrics.jsonl"),
                "line 3", said, "delete that line")


# ---- bench.json, suite.json, run folders ----

@pytest.mark.parametrize("bench, said", [
    ({"seeds": [1, -5, 10**30], "units": ["layout/1", "../../etc"]}, "'../../etc' is not a relative path"),
    ({"seeds": [1, -5, 10**30], "units": ["layout/1"]}, "seed -5 is outside [0, 2**63)"),
    ({"seeds": [1, 10**30], "units": ["layout/1"]}, f"seed {10**30} is outside [0, 2**63)"),
    ({"seeds": [1], "units": ["layout/1", "../../etc"]}, "'../../etc' is not a relative path of plain parts"),
    ({"seeds": [1, 1], "units": ["layout/1"]}, "seed 1 is listed twice"),
    ({"seeds": [1], "units": ["layout/1", "layout/1"]}, "'layout/1' is listed twice"),
], ids=["listed", "negative-seed", "huge-seed", "unit-escapes", "seed-twice", "unit-twice"])
def test_report_and_status_refuse_a_bench_json_that_run_would_not_write(tmp_path, bench, said):
    bench_dir(tmp_path, [eval_row(0, 0.5, {"eval": 0.5})])
    (tmp_path / "bench.json").write_text(json.dumps({"kage_bench": 1, "trainer_args": [], **bench}))
    path = str(tmp_path / "bench.json")
    refusal(lambda: report.report(str(tmp_path), reps=100), path, said, "fix or delete it")
    refusal(lambda: status.status(str(tmp_path), io.StringIO()), path, said, "restore it")


def test_status_of_a_folder_that_is_no_benchmark_says_so(tmp_path):
    missing = tmp_path / "nowhere"
    with pytest.raises(SystemExit) as refused:
        status.status(str(missing), io.StringIO())
    assert refused.value.code == (f"{missing / 'bench.json'}: error: no such file: {missing} is not a directory "
                                  "written by python3 -m kage.bench run (or slurm): give the --out of a benchmark")


def test_a_malformed_shared_entry_is_refused(tmp_path):
    bench_dir(tmp_path, [eval_row(0, 0.5, {"eval": 0.5})])
    bench = json.loads((tmp_path / "bench.json").read_text())
    (tmp_path / "bench.json").write_text(json.dumps({**bench, "shared": {"layout/1": "shared/x"}}))
    refusal(lambda: report.report(str(tmp_path), reps=100), str(tmp_path / "bench.json"),
            "'shared'", "is not [unit, label]")


def test_a_sweep_without_its_eval_name_is_refused(tmp_path):
    bench_dir(tmp_path, [eval_row(0, 0.5, {"eval": 0.5})])
    sweep = pair("light/0.5", "filters", "light", None)
    (tmp_path / "suite.json").write_text(json.dumps({**SUITE, "pairs": [pair("layout/1", "layout"), sweep]}))
    bench = json.loads((tmp_path / "bench.json").read_text())
    (tmp_path / "bench.json").write_text(json.dumps({**bench, "units": ["layout/1", "light"]}))
    refusal(lambda: report.report(str(tmp_path), reps=100), str(tmp_path / "suite.json"),
            "'light/0.5': a sweep without a valid sweep name and sweep_eval", "rerun `python3 -m kage.bench run`")


def test_one_seed_in_two_folders_is_refused(tmp_path):
    """seed_1 and seed_01 both read as seed 1: its results would count twice in the pair's mean."""
    bench_dir(tmp_path, [eval_row(0, 0.5, {"eval": 0.5})])
    write_run(tmp_path, "layout/1", "01", ["eval"], plain(0.0, 0.0), rows=[eval_row(0, 0.0, {"eval": 0.0})])
    refusal(lambda: report.report(str(tmp_path), reps=100), "seed_01", "seed_1", "both seed 1 of layout/1")


def test_a_run_json_without_an_args_object_is_refused(tmp_path):
    run, = bench_dir(tmp_path, [eval_row(0, 0.5, {"eval": 0.5})])
    (run / "run.json").write_text(json.dumps({"kage_run": 1, "args": []}))
    refusal(lambda: report.report(str(tmp_path), reps=100), str(run / "run.json"), "not a kage.ppo.train run record")


# ---- a finished run's summary.json against its log ----

def test_final_protocol_refuses_a_log_that_lost_its_last_rows(tmp_path):
    """summary.json counts the evaluation of step 100; a log cut after step 0's (a copy cut short) was read as
    ending there, and --protocol final scored step 0's values as the final checkpoint's."""
    run, = bench_dir(tmp_path, [eval_row(0, 1.0, {"eval": 1.0}), eval_row(100, 0.0, {"eval": 0.0})])
    lines = (run / "metrics.jsonl").read_text().splitlines(keepends=True)
    (run / "metrics.jsonl").write_text("".join(lines[:-1]))
    refusal(lambda: report.report(str(tmp_path), protocol="final", reps=100), str(run / "metrics.jsonl"),
            "ends at the evaluation of step 0, before the last that summary.json counts (step 100)", "restore it")
    report.report(str(tmp_path), reps=100)  # the paper's protocol reads summary.json alone


@pytest.mark.parametrize("value, said", [(1e300, "max 1e+300, outside [0, 1]"), (-7, "max -7, outside [0, 1]")])
def test_a_share_of_episodes_outside_0_1_is_refused(tmp_path, value, said):
    run, = bench_dir(tmp_path, [eval_row(0, 0.5, {"eval": 0.5})])
    record = json.loads((run / "summary.json").read_text())
    record["stats"]["eval/eval/success_once"]["max"] = value
    (run / "summary.json").write_text(json.dumps(record))
    refusal(lambda: report.report(str(tmp_path), reps=100), str(run / "summary.json"), "eval/eval/success_once", said)


def test_one_side_without_a_value_is_refused(tmp_path):
    """A null eval value left the train side's mean over five seeds and the eval side's over four: a gap of
    different runs."""
    run, = bench_dir(tmp_path, [eval_row(0, 0.5, {"eval": 0.5})])
    record = json.loads((run / "summary.json").read_text())
    record["stats"]["eval/eval/success_once"] = None
    (run / "summary.json").write_text(json.dumps(record))
    refusal(lambda: report.report(str(tmp_path), reps=100), "eval/eval/success_once has no value where the other "
            "side has one")
