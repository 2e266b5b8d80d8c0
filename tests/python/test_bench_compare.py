"""kage.bench compare: two benchmark directories side by side (IQMs with intervals, P(X > Y), the overlaid
plots), on hand-made directories with values worked out here and end to end on two tiny CPU benchmarks (the
baseline and the random-shift agent); that it compares only the pairs every directory ran (or --pairs), the
seeds of --seeds and the (pair, seed) results every directory has; that a method may train otherwise; --max-step
against values recomputed from the rows; and its refusals of directories whose eval configs, seeds or protocol
differ."""
import csv
import json
import shutil

import pytest
from test_bench_e2e import TINY, bench as bench_cli, run as run_tiny
from test_report import PNG_SIGNATURE, pair, plain, write_run
from test_report_intervals import rows_for, write_suite

from test_report_intervals import full_row

from kage.bench import compare

PAIRS = [pair("background/1", "background"), pair("background/2", "background"), pair("layout/1", "layout")]
ARGS = {"total_timesteps": 2048, "run_eval_every": 4, "num_envs": 2, "num_steps": 128, "eval_episodes": 2,
        "eval_num_envs": 2, "eval_greedy": False}


def method(path, evals, args=ARGS, seeds=(1, 2, 3)):
    """A benchmark directory whose runs have train success 1 and the given eval successes {pair: [per seed]}."""
    write_suite(path, PAIRS, seeds=list(seeds))
    for name, values in evals.items():
        for seed, e in zip(seeds, values):
            run = write_run(path, name, seed, ["eval"], plain(1.0, e), rows=rows_for([(1.0, e)]))
            run_json = json.loads((run / "run.json").read_text())
            (run / "run.json").write_text(json.dumps({**run_json, "args": {**run_json["args"], **args}}))
    return path


@pytest.fixture
def two(tmp_path):
    a = method(tmp_path / "A", {"background/1": [0.5, 0.6, 0.7], "background/2": [0.2, 0.3, 0.4],
                                "layout/1": [0.0, 0.1, 0.2]})
    b = method(tmp_path / "B", {"background/1": [0.1, 0.6, 0.2], "background/2": [0.4, 0.1, 0.1],
                                "layout/1": [0.0, 0.1, 0.2]})
    return a, b


def test_compare_by_hand(two):
    a, b = two
    result = compare.compare([str(a), str(b)], reps=2000)
    assert result["out_dir"] == str(a / "compare")
    estimates = {m["name"]: {r["name"]: r for r in m["estimates"]["rows"]} for m in result["methods"]}
    # A's background eval: 0.2 0.3 0.4 0.5 0.6 0.7, one cut at each end: IQM 0.45; B's: 0.1 0.1 0.1 0.2 0.4 0.6 -> 0.2
    assert estimates["A"]["background"]["eval_iqm"]["point"] == pytest.approx(0.45)
    assert estimates["B"]["background"]["eval_iqm"]["point"] == pytest.approx(0.2)
    p = {(r["name"], r["x"], r["y"]): r for r in result["improvement"]}
    # background/1: A's 0.5 beats 0.1 and 0.2 (2), 0.6 beats two and ties one (2.5), 0.7 beats all (3): 7.5 / 9;
    # background/2: A's 0.2 beats 0.1 twice (2), 0.3 likewise (2), 0.4 ties 0.4 and beats both 0.1 (2.5): 6.5 / 9
    background = p[("background", "A", "B")]
    assert background["n_pairs"] == 2 and background["p"]["point"] == pytest.approx((7.5 + 6.5) / 18)
    assert background["p"]["low"] < background["p"]["point"] < background["p"]["high"]
    # layout/1: the same scores 0.0, 0.1, 0.2 in both: 3 ties and 3 wins each way, 4.5 / 9
    assert p[("layout", "A", "B")]["p"]["point"] == pytest.approx(0.5)
    # all pairs: the mean over the three pairs
    assert p[("all pairs", "A", "B")]["p"]["point"] == pytest.approx(18.5 / 27)
    out = a / "compare"
    md = (out / "compare.md").read_text()
    assert md.startswith("# hand-made: A vs B")
    assert "**A**: `" in md and "trainer flags none (the defaults); **B**" in md
    assert "| axis | pairs | P(A > B) |" in md and f"| background | 2 | {(14 / 18):.2f} [" in md
    assert "| background | 0.45 [" in md
    with open(out / "compare.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(r["method"], r["name"]) for r in rows] == [(m, n) for m in "AB" for n in ("background", "layout",
                                                                                      "all pairs")]
    with open(out / "improvement.csv") as f:
        assert float(next(csv.DictReader(f))["p"]) == pytest.approx(14 / 18)
    for name in ("intervals.png", "profile_success_once.png"):
        data = (out / "plots" / name).read_bytes()
        assert data.startswith(PNG_SIGNATURE) and len(data) > 5000, name
    assert json.loads((out / "compare.json").read_text()) == result


def test_three_methods_give_each_two(two, tmp_path):
    a, b = two
    c = method(tmp_path / "C", {"background/1": [0.9] * 3, "background/2": [0.9] * 3, "layout/1": [0.9] * 3})
    bench = json.loads((c / "bench.json").read_text())
    (c / "bench.json").write_text(json.dumps({**bench, "trainer_args": ["--augment", "kage.ppo.augment:grayscale"]}))
    result = compare.compare([str(a), str(b), str(c)], names=["base", "shift", "mine"], reps=500)
    assert "results, trainer flags `--augment kage.ppo.augment:grayscale`." in (a / "compare" / "compare.md").read_text()
    assert {(r["x"], r["y"]) for r in result["improvement"]} == {("base", "shift"), ("base", "mine"),
                                                                ("shift", "mine")}
    assert "P(base > mine)" in (a / "compare" / "compare.md").read_text()


def test_a_cache_reads_each_directory_once_and_keeps_it_unchanged(two, tmp_path):
    a, b = two
    everything = compare.compare([str(a), str(b)], out_dir=str(tmp_path / "plain"), reps=500)
    cache = {}
    compare.compare([str(a), str(b)], out_dir=str(tmp_path / "first"), reps=500, seeds=[1, 2], cache=cache)
    for d in (a, b):
        shutil.rmtree(d / "runs")  # a compare that read them again would now refuse the directories
    again = compare.compare([str(a), str(b)], out_dir=str(tmp_path / "again"), reps=500, cache=cache)
    # the first compare's seeds 1 and 2 changed its copies only: all three seeds, as without a cache
    assert {**again, "out_dir": None} == {**everything, "out_dir": None}
    renamed = compare.compare([str(b), str(a)], names=["B2", "A2"], out_dir=str(tmp_path / "renamed"), reps=500,
                              cache=cache)
    assert [m["name"] for m in renamed["methods"]] == ["B2", "A2"]


# ---- refusals ----

def test_a_method_may_train_otherwise_but_must_evaluate_alike(two):
    """B trains background/1 on a mixture: compared, and compare.md says what each trains on; B evaluating
    background/1 on another Spec is refused, naming the pair."""
    a, b = two
    suite = json.loads((b / "suite.json").read_text())
    suite["pairs"][0]["train"] = {"name": "mixture of 2", "spec_sha256": "dd", "schedule": None, "stages": [
        {"start": 0, "configs": [{"name": "configs/x.yaml", "spec_sha256": "aa", "weight": 0.5},
                                 {"name": "configs/y.yaml", "spec_sha256": "ee", "weight": 0.5}]}]}
    (b / "suite.json").write_text(json.dumps(suite))
    result = compare.compare([str(a), str(b)], reps=500)
    methods = {m["name"]: m for m in result["methods"]}
    assert methods["A"]["trains_on"] == [{"name": "1-train.yaml", "pairs": ["background/1", "layout/1"]},
                                         {"name": "2-train.yaml", "pairs": ["background/2"]}]
    assert methods["B"]["trains_on"] == [{"name": "mixture of 2", "pairs": ["background/1"]},
                                         {"name": "2-train.yaml", "pairs": ["background/2"]},
                                         {"name": "1-train.yaml", "pairs": ["layout/1"]}]
    assert methods["B"]["training"] == {"background/1": "dd", "background/2": "aa", "layout/1": "aa"}
    estimates = {m["name"]: {r["name"]: r for r in m["estimates"]["rows"]} for m in result["methods"]}
    assert estimates["B"]["background"]["eval_iqm"]["point"] == pytest.approx(0.2)  # as in test_compare_by_hand
    md = (a / "compare" / "compare.md").read_text()
    assert ("Trains on: **A** 1-train.yaml (2 pairs), 2-train.yaml (1 pair); **B** mixture of 2 (1 pair), "
            "2-train.yaml (1 pair), 1-train.yaml (1 pair). The methods train differently") in md
    suite["pairs"][0]["eval"]["spec_sha256"] = "cc"
    (b / "suite.json").write_text(json.dumps(suite))
    with pytest.raises(SystemExit, match=r"^kage.bench compare: .*A and .*B evaluate background/1 on other configs "
                                         r"\(eval spec_sha256 bb and cc\): compare methods evaluated on the same "
                                         r"configs, or leave background/1 out with --pairs$"):
        compare.compare([str(a), str(b)], reps=100)
    result = compare.compare([str(a), str(b)], pairs=["background/2", "layout/1"], reps=100)
    assert result["pairs"] == ["background/2", "layout/1"] and result["results_compared"] == 6


def test_refuses_a_pair_on_another_axis(two):
    a, b = two
    suite = json.loads((b / "suite.json").read_text())
    suite["pairs"][2]["declared_axis"] = "background"
    (b / "suite.json").write_text(json.dumps(suite))
    with pytest.raises(SystemExit, match=r"put layout/1 on other axes \(layout and background\): compare suites that "
                                         r"agree on the pair's axis, or leave layout/1 out with --pairs"):
        compare.compare([str(a), str(b)], reps=100)


def test_refuses_other_seeds(two, tmp_path):
    a, _ = two
    fewer = method(tmp_path / "D", {"background/1": [0.1, 0.2]}, seeds=(1, 2))
    with pytest.raises(SystemExit,
                       match=r"have other seeds \(1-3 and 1-2\): run both with the same --seeds, or "
                             r"compare the seeds they share with --seeds 1-2$"):
        compare.compare([str(a), str(fewer)], reps=100)


def test_seeds_compares_a_subset(two, tmp_path):
    """A ran seeds 1-3, D seeds 1-2: --seeds 1-2 compares those; a seed that D lacks is refused, naming D."""
    a, _ = two
    d = method(tmp_path / "D", {"background/1": [0.1, 0.6], "background/2": [0.4, 0.1], "layout/1": [0.0, 0.1]},
               seeds=(1, 2))
    result = compare.compare([str(a), str(d)], seeds=[1, 2], reps=500)
    assert result["seeds"] == [1, 2] and result["seeds_chosen"] and result["results_compared"] == 6
    methods = {m["name"]: m for m in result["methods"]}
    assert methods["A"]["results_finished"] == 6 and methods["A"]["left_out"] == []
    estimates = {m["name"]: {r["name"]: r for r in m["estimates"]["rows"]} for m in result["methods"]}
    # A's background eval, seeds 1 and 2: 0.2 0.3 0.5 0.6, one cut at each end: IQM 0.4; D's 0.1 0.1 0.4 0.6 -> 0.25
    assert estimates["A"]["background"]["eval_iqm"]["point"] == pytest.approx(0.4)
    assert estimates["D"]["background"]["eval_iqm"]["point"] == pytest.approx(0.25)
    assert {r["n_runs"] for m in result["methods"] for r in m["estimates"]["rows"] if r["name"] == "layout"} == {2}
    assert "Seeds 1-2 (--seeds);" in (a / "compare" / "compare.md").read_text()
    with pytest.raises(SystemExit, match=r"^kage.bench compare: .*D has no seed 3 \(its seeds are 1-2\): give --seeds "
                                         r"that every directory has"):
        compare.compare([str(a), str(d)], seeds=[2, 3], reps=100)
    with pytest.raises(SystemExit, match=r"^kage.bench compare: --seeds '2-1': the range 2-1 is empty$"):
        compare.main([str(a), str(d), "--seeds", "2-1"])


def test_compares_the_results_every_method_has(two):
    """B ran two of the three pairs (run --pairs) and its seed 3 is still training: both are compared on seeds 1
    and 2 of background/1 and 2, and compare.md names the pair and the results that A has beyond them."""
    a, b = two
    bench = json.loads((b / "bench.json").read_text())
    (b / "bench.json").write_text(json.dumps({**bench, "units": ["background/1", "background/2"]}))
    shutil.rmtree(b / "runs" / "layout/1")
    for name in ("background/1", "background/2"):
        (b / "runs" / name / "seed_3" / "summary.json").unlink()
    result = compare.compare([str(a), str(b)], reps=500)
    assert result["results_compared"] == 4
    assert result["pairs"] == ["background/1", "background/2"] and not result["pairs_chosen"]
    methods = {m["name"]: m for m in result["methods"]}
    assert methods["A"]["pairs_left_out"] == ["layout/1"] and methods["B"]["pairs_left_out"] == []
    assert methods["A"]["results_finished"] == 6 and methods["B"]["results_finished"] == 4
    assert methods["A"]["left_out"] == [{"pair": "background/1", "seed": 3}, {"pair": "background/2", "seed": 3}]
    assert methods["B"]["left_out"] == []
    estimates = {m["name"]: {r["name"]: r for r in m["estimates"]["rows"]} for m in result["methods"]}
    # A's background eval, seeds 1 and 2: 0.2 0.3 0.5 0.6, one cut at each end: IQM 0.4; B's 0.1 0.1 0.4 0.6 -> 0.25
    assert estimates["A"]["background"]["eval_iqm"]["point"] == pytest.approx(0.4)
    assert estimates["B"]["background"]["eval_iqm"]["point"] == pytest.approx(0.25)
    p = {(r["name"], r["x"], r["y"]): r for r in result["improvement"]}
    # background/1: A's 0.5 beats 0.1 (1), 0.6 beats 0.1 and ties 0.6 (1.5): 2.5 / 4; background/2: A's 0.2 and 0.3
    # each beat 0.1 only: 2 / 4
    assert p[("background", "A", "B")]["p"]["point"] == pytest.approx((2.5 / 4 + 2 / 4) / 2)
    assert {name for name, _, _ in p} == {r["name"] for r in estimates["A"].values()} == {"background", "all pairs"}
    md = (a / "compare" / "compare.md").read_text()
    assert "2 pairs, those every directory ran; left out, run by some methods only: **A** 1: layout/1;" in md
    assert ("Compared on the 4 (pair, seed) results that every method has finished; left out, finished by some "
            "methods only: **A** 2: background/1 (seed 3), background/2 (seed 3).") in md


def test_pairs_chooses_the_pairs_compared(two):
    a, b = two
    result = compare.compare([str(a), str(b)], pairs=["layout/1", "background/1"], reps=500)
    assert result["pairs"] == ["background/1", "layout/1"] and result["pairs_chosen"]  # in the suite's order
    assert result["results_compared"] == 6
    assert {r["name"] for r in result["methods"][0]["estimates"]["rows"]} == {"background", "layout", "all pairs"}
    assert result["methods"][0]["pairs_left_out"] == []
    p = {(r["name"], r["x"], r["y"]): r for r in result["improvement"]}
    assert p[("background", "A", "B")]["p"]["point"] == pytest.approx(7.5 / 9)  # background/1 alone, as by hand
    assert "2 pairs (--pairs);" in (a / "compare" / "compare.md").read_text()
    with pytest.raises(SystemExit, match=r"^kage.bench compare: --pairs backgrund/1: .*A ran no plain pair of that "
                                         r"name; did you mean background/1"):
        compare.compare([str(a), str(b)], pairs=["backgrund/1"], reps=100)
    bench = json.loads((b / "bench.json").read_text())
    (b / "bench.json").write_text(json.dumps({**bench, "units": ["background/1", "background/2"]}))
    with pytest.raises(SystemExit, match=r"--pairs layout/1: .*B ran no plain pair of that name: give --pairs that "
                                         r"every directory ran$"):
        compare.compare([str(a), str(b)], pairs=["layout/1"], reps=100)


def test_refuses_directories_with_no_pair_in_common(two):
    a, b = two
    for path, units in ((a, ["layout/1"]), (b, ["background/1", "background/2"])):
        bench = json.loads((path / "bench.json").read_text())
        (path / "bench.json").write_text(json.dumps({**bench, "units": units}))
    with pytest.raises(SystemExit, match=r"the directories ran no plain pair in common \(pairs: A 1 \(layout/1\), B 2 "
                                         r"\(background/1, background/2\)\): compare directories of one suite's pairs"):
        compare.compare([str(a), str(b)], reps=100)


def test_refuses_directories_with_no_result_in_common(two):
    """B finished only layout/1, whose runs A has not finished."""
    a, b = two
    bench = json.loads((b / "bench.json").read_text())
    (b / "bench.json").write_text(json.dumps({**bench, "units": ["layout/1"]}))
    for name in ("background/1", "background/2"):
        shutil.rmtree(b / "runs" / name)
    for seed in (1, 2, 3):
        (a / "runs" / "layout/1" / f"seed_{seed}" / "summary.json").unlink()
    with pytest.raises(SystemExit, match=r"no \(pair, seed\) result of the pairs and seeds compared is finished in "
                                         r"every directory \(finished: A 0, B 3\): run the same pairs and seeds"):
        compare.compare([str(a), str(b)], reps=100)


def test_a_directory_without_finished_runs_is_named(two, tmp_path):
    """B with no run at all, or with runs that have not finished: the message says so (it said "another protocol
    (total_timesteps 2048 and None ...)" for the first), in compare's name."""
    a, b = two
    empty = tmp_path / "empty"
    write_suite(empty, PAIRS)
    with pytest.raises(SystemExit, match=r"^kage.bench compare: .*empty has no finished run \(a run directory with "
                                         r"summary.json\): compare reads finished runs only \(and, under --max-step, runs "
                                         r"logged past it\): let them finish "
                                         r"\(kage.bench status .*empty\)"):
        compare.compare([str(a), str(empty)], reps=100)
    for summary in b.glob("runs/*/*/seed_*/summary.json"):
        summary.unlink()
    with pytest.raises(SystemExit, match=r"B has no finished run .*; its 9 runs are still training or stopped"):
        compare.compare([str(a), str(b)], reps=100)


def test_runs_without_run_json_are_named(two):
    a, b = two
    for run_json in b.glob("runs/*/*/seed_*/run.json"):
        run_json.unlink()
    with pytest.raises(SystemExit, match=r"the runs of .*B have no run.json with their arguments, so their protocol "
                                         r"cannot be compared"):
        compare.compare([str(a), str(b)], reps=100)


def test_a_directory_that_is_not_one_is_refused_in_compares_name(two, tmp_path):
    a, _ = two
    with pytest.raises(SystemExit, match=r"^kage.bench compare: .*absent is not a directory: give the --out"):
        compare.compare([str(a), str(tmp_path / "absent")], reps=100)


def test_refuses_another_protocol(two, tmp_path):
    a, _ = two
    longer = method(tmp_path / "E", {"background/1": [0.1] * 3}, args={**ARGS, "total_timesteps": 4096,
                                                                      "eval_episodes": 8})
    with pytest.raises(SystemExit, match=r"another protocol \(total_timesteps 2048 and 4096, eval_episodes 2 and 8\): "
                                         r"compare runs trained and evaluated alike \(other total_timesteps alone: "
                                         r"compare their first N steps with --max-step N\)$"):
        compare.compare([str(a), str(longer)], reps=100)
    with pytest.raises(SystemExit, match=r"another protocol \(eval_episodes 2 and 8\): compare runs trained and "
                                         r"evaluated alike$"):
        compare.compare([str(a), str(longer)], max_step=2048, reps=100)


# ---- --max-step: every run scored on its evaluation rows up to a step ----

STEPPED = {**ARGS, "run_eval_every": 1, "num_envs": 1, "num_steps": 10}  # an evaluation every 10 steps


def stepped(path, histories, total, args=STEPPED, steps=range(0, 1000, 10)):
    """A directory of background/1, seeds 1 and 2, trained for `total` steps: each run's eval success at `steps`
    (0, 10, 20, ...) from `histories` {seed: [...]} (train success 1), and a summary.json whose maxima (0.99) no
    row has, so that a value read from it shows."""
    write_suite(path, PAIRS, seeds=[1, 2], units=["background/1"])
    for seed, evals in histories.items():
        rows = [full_row(step, 1.0, {"eval": e}) for step, e in zip(steps, evals)]
        run = write_run(path, "background/1", seed, ["eval"], plain(1.0, 0.99), rows=rows)
        run_json = json.loads((run / "run.json").read_text())
        (run / "run.json").write_text(json.dumps({**run_json, "args": {**run_json["args"], **args,
                                                                        "total_timesteps": total}}))
    return path


@pytest.fixture
def long_and_short(tmp_path):
    long = stepped(tmp_path / "long", {1: [0.0, 0.2, 0.5, 0.9, 0.1], 2: [0.1, 0.4, 0.3, 0.8, 0.8]}, 40)
    short = stepped(tmp_path / "short", {1: [0.0, 0.3, 0.4], 2: [0.0, 0.1, 0.6]}, 20)
    return long, short


def test_max_step_scores_the_rows_up_to_it(long_and_short):
    long, short = long_and_short
    result = compare.compare([str(long), str(short)], max_step=20, reps=500)
    assert result["protocol"]["max_step"] == 20 and result["protocol"]["total_timesteps"] is None
    assert "at or before step 20" in result["protocol"]["level_1_runs"]
    assert [m["total_timesteps"] for m in result["methods"]] == [40, 20]
    estimates = {m["name"]: {r["name"]: r for r in m["estimates"]["rows"]} for m in result["methods"]}
    # long's maxima over steps 0, 10, 20: seed 1 0.5, seed 2 0.4 (not 0.9 and 0.8 after step 20, nor summary's
    # 0.99); short's 0.4 and 0.6. Two runs: the IQM is their mean.
    assert estimates["long"]["all pairs"]["eval_iqm"]["point"] == pytest.approx(0.45)
    assert estimates["short"]["all pairs"]["eval_iqm"]["point"] == pytest.approx(0.5)
    # long 0.5 beats 0.4 and loses to 0.6 (1); 0.4 ties 0.4 and loses to 0.6 (0.5): 1.5 / 4
    p = {(r["name"], r["x"], r["y"]): r for r in result["improvement"]}
    assert p[("all pairs", "long", "short")]["p"]["point"] == pytest.approx(1.5 / 4)
    md = (long / "compare" / "compare.md").read_text()
    assert "every run scored up to step 20 (--max-step; trained for long 40, short 20 steps)" in md
    final = compare.compare([str(long), str(short)], max_step=20, protocol="final", reps=500)
    estimates = {m["name"]: {r["name"]: r for r in m["estimates"]["rows"]} for m in final["methods"]}
    # the rows at step 20: long 0.5 and 0.3, short 0.4 and 0.6
    assert estimates["long"]["all pairs"]["eval_iqm"]["point"] == pytest.approx(0.4)
    assert estimates["short"]["all pairs"]["eval_iqm"]["point"] == pytest.approx(0.5)
    # the long one against itself up to step 35 (its rows at 0, 10, 20, 30): maxima 0.9 and 0.8 -> 0.85
    again = compare.compare([str(long), str(long)], names=["x", "y"], out_dir=str(long / "again"), max_step=35,
                            reps=500)
    assert again["methods"][0]["estimates"]["rows"][-1]["eval_iqm"]["point"] == pytest.approx(0.85)


def test_max_step_counts_an_unfinished_run_logged_past_it(long_and_short):
    """A run still training (no summary.json) enters under --max-step N once its log is past N: its rows up to N
    are all written. One whose log stops short of N stays out, as without --max-step."""
    long, short = long_and_short
    (long / "runs" / "background/1" / "seed_1" / "summary.json").unlink()  # logged to step 40, unfinished
    result = compare.compare([str(long), str(short)], max_step=20, reps=500)
    estimates = {m["name"]: m["estimates"]["rows"][-1]["eval_iqm"]["point"] for m in result["methods"]}
    assert estimates == {"long": pytest.approx(0.45), "short": pytest.approx(0.5)}  # as when both had finished
    log = long / "runs" / "background/1" / "seed_1" / "metrics.jsonl"
    log.write_text("".join(line + "\n" for line in log.read_text().splitlines()[:3]))  # the train row, steps 0, 10
    result = compare.compare([str(long), str(short)], max_step=20, reps=500)
    assert result["results_compared"] == 1  # seed 2 alone: seed 1 of long has not reached step 20


def test_max_step_names_other_last_evaluations(long_and_short, tmp_path):
    """A run of 25 steps in iterations of 5, evaluated every 10 steps, evaluates at 0, 10, 20 and at its end, 25;
    up to step 25 the 40-step runs' last evaluation is at 20: compare.md says so."""
    long, _ = long_and_short
    odd = stepped(tmp_path / "odd", {1: [0.0, 0.1, 0.2, 0.7], 2: [0.0, 0.1, 0.2, 0.3]}, 25,
                  {**STEPPED, "run_eval_every": 2, "num_steps": 5}, (0, 10, 20, 25))
    result = compare.compare([str(long), str(odd)], max_step=25, reps=500)
    assert [m["last_evaluation_steps"] for m in result["methods"]] == [[20], [25]]
    estimates = {m["name"]: m["estimates"]["rows"][-1]["eval_iqm"]["point"] for m in result["methods"]}
    assert estimates == {"long": pytest.approx(0.45), "odd": pytest.approx(0.5)}  # (0.7 + 0.3) / 2
    assert ("their last evaluations scored are at step 20 (long), 25 (odd): a multiple of 10 steps scores the same "
            "evaluation points") in (long / "compare" / "compare.md").read_text()
    assert compare.compare([str(long), str(odd)], max_step=20, reps=100)["methods"][1]["last_evaluation_steps"] == [20]


def test_max_step_refusals(long_and_short):
    long, short = long_and_short
    with pytest.raises(SystemExit, match=r"another protocol \(total_timesteps 40 and 20\): compare their first N steps "
                                         r"with --max-step N \(at most 20\)$"):
        compare.compare([str(long), str(short)], reps=100)
    with pytest.raises(SystemExit, match=r"^kage.bench compare: --max-step 25 is beyond the 20 steps that the runs of "
                                         r".*short trained for: give at most --max-step 20$"):
        compare.compare([str(long), str(short)], max_step=25, reps=100)
    with pytest.raises(SystemExit, match=r"^kage.bench compare: --max-step 5 is before the first evaluation after step "
                                         r"0 of the runs of .*long \(step 10\): give at least --max-step 10$"):
        compare.compare([str(long), str(short)], max_step=5, reps=100)
    with pytest.raises(SystemExit, match=r"--max-step takes a number of steps above 0, not 0"):
        compare.compare([str(long), str(short)], max_step=0, reps=100)
    # a log that stops at step 10 though its run trained for 40 steps
    log = long / "runs" / "background/1" / "seed_2" / "metrics.jsonl"
    log.write_text("".join(line + "\n" for line in log.read_text().splitlines()[:3]))  # the train row, steps 0, 10
    with pytest.raises(SystemExit, match=r"seed_2/metrics.jsonl has no evaluation row after step 10 and at or before "
                                         r"step 20, which --max-step 20 reads \(its last is at step 10\): the log is "
                                         r"incomplete"):
        compare.compare([str(long), str(short)], max_step=20, reps=100)
    for run_json in short.glob("runs/*/*/seed_*/run.json"):
        run_json.unlink()
    with pytest.raises(SystemExit, match=r"the runs of .*short have no run.json with their arguments"):
        compare.compare([str(long), str(short)], max_step=20, reps=100)


def with_train(path, histories):
    """background/1, seeds 1 and 2, trained for 20 steps: each run's train (success_once, jump_count) at steps 0,
    10 and 20 from `histories` {seed: [...]}, eval success 0.1 throughout."""
    write_suite(path, PAIRS, seeds=[1, 2], units=["background/1"])
    for seed, history in histories.items():
        rows = []
        for step, (success, jumps) in zip((0, 10, 20), history):
            row = full_row(step, success, {"eval": 0.1})
            row["train"]["jump_count"] = jumps
            rows.append(row)
        run = write_run(path, "background/1", seed, ["eval"], plain(max(s for s, _ in history), 0.1), rows=rows)
        run_json = json.loads((run / "run.json").read_text())
        (run / "run.json").write_text(json.dumps({**run_json, "args": {**run_json["args"], **STEPPED,
                                                                        "total_timesteps": 20}}))
    return path


def test_train_success_and_collapse_per_method(tmp_path):
    """Per method, its training runs: the mean of their best train success, those never above 0.1, and those
    with no jump on the train config at the last evaluation point scored (collapsed)."""
    a = with_train(tmp_path / "a", {1: [(0.0, 3), (0.6, 5), (1.0, 4)],    # learned: best 1.0
                                    2: [(0.05, 2), (0.08, 1), (0.0, 0)]})  # never above 0.1, ends collapsed
    b = with_train(tmp_path / "b", {1: [(0.2, 1), (0.9, 2), (0.0, 0)],     # learned, then collapsed
                                    2: [(0.0, 0), (0.3, 1), (0.7, 2)]})    # collapsed at first, then learned
    result = compare.compare([str(a), str(b)], reps=200)
    runs = {m["name"]: m["training_runs"] for m in result["methods"]}
    assert {k: runs["a"][k] for k in ("runs", "never_learned", "collapsed")} == {"runs": 2, "never_learned": 1,
                                                                                "collapsed": 1}
    assert runs["a"]["mean_best"] == pytest.approx((1.0 + 0.08) / 2)
    assert {k: runs["b"][k] for k in ("runs", "never_learned", "collapsed")} == {"runs": 2, "never_learned": 0,
                                                                                "collapsed": 1}
    assert runs["b"]["mean_best"] == pytest.approx((0.9 + 0.7) / 2)
    assert [(r["seed"], r["best"], r["last"], r["collapsed"]) for r in runs["b"]["runs_listed"]] == [
        (1, 0.9, 0.0, True), (2, 0.7, 0.7, False)]
    md = (a / "compare" / "compare.md").read_text()
    assert "| method | training runs | mean of max train success_once | never above 0.1 | collapsed |" in md
    assert "| a | 2 | 0.54 | 1 | 1 |" in md and "| b | 2 | 0.80 | 0 | 1 |" in md
    # Up to step 10, no run has ended collapsed yet, and a's second run's best is 0.08
    early = compare.compare([str(a), str(b)], max_step=10, out_dir=str(tmp_path / "early"), reps=200)
    runs = {m["name"]: m["training_runs"] for m in early["methods"]}
    assert runs["a"]["collapsed"] == runs["b"]["collapsed"] == 0
    assert runs["a"]["mean_best"] == pytest.approx((0.6 + 0.08) / 2) and runs["a"]["never_learned"] == 1
    assert runs["b"]["mean_best"] == pytest.approx((0.9 + 0.3) / 2)


def test_refuses_one_directory_and_alike_names(two, tmp_path):
    a, b = two
    with pytest.raises(SystemExit, match="give two or more benchmark directories"):
        compare.compare([str(a)])
    twin = tmp_path / "elsewhere" / "A"
    shutil.copytree(b, twin)
    with pytest.raises(SystemExit, match=r"two methods would be named alike \(A, A\): name them with --names"):
        compare.compare([str(a), str(twin)], reps=100)
    with pytest.raises(SystemExit, match="--names gives 1 names for 2 directories"):
        compare.compare([str(a), str(b)], names=["x"], reps=100)
    with pytest.raises(SystemExit, match="--names '' 'b': a method's name is the title of its columns"):
        compare.compare([str(a), str(b)], names=["", "b"], reps=100)


# ---- end to end on the CPU ----

@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """Two tiny benchmarks of two pairs, one seed: the baseline and the random-shift agent."""
    root = tmp_path_factory.mktemp("compare")
    for name, extra in (("baseline", ()), ("shift", ("--augment", "kage.ppo.augment:random_shift"))):
        done = run_tiny(root / name, "--pack", "2", *extra)
        assert done.returncode == 0, done.stderr
    return root


def test_compare_end_to_end(trained):
    # progress: after 128 steps no run succeeds, but they move
    done = bench_cli("compare", str(trained / "baseline"), str(trained / "shift"), "--reps", "1000",
                     "--out", str(trained / "out"), "--metric", "progress")
    assert done.returncode == 0, done.stderr
    assert "## Probability of improvement of eval `progress`" in done.stdout
    assert "| axis | pairs | P(baseline > shift) |" in done.stdout
    result = json.loads((trained / "out" / "compare.json").read_text())
    assert [m["name"] for m in result["methods"]] == ["baseline", "shift"]
    assert {r["name"] for r in result["methods"][0]["estimates"]["rows"]} == {"background", "agent", "all pairs"}
    assert result["protocol"]["total_timesteps"] == int(TINY[TINY.index("--total-timesteps") + 1])
    for r in result["improvement"]:
        assert r["n_pairs"] >= 1 and 0.0 <= r["p"]["low"] <= r["p"]["point"] <= r["p"]["high"] <= 1.0
    for name in ("intervals.png", "profile_progress.png"):
        assert (trained / "out" / "plots" / name).read_bytes().startswith(PNG_SIGNATURE)


def test_compare_end_to_end_refuses_another_protocol(trained):
    """The baseline's runs as if evaluated on 4 episodes (their run.json arguments say the protocol)."""
    shutil.copytree(trained / "baseline", trained / "longer")
    for path in (trained / "longer").glob("runs/**/run.json"):
        run_json = json.loads(path.read_text())
        path.write_text(json.dumps({**run_json, "args": {**run_json["args"], "eval_episodes": 4}}))
    refused = bench_cli("compare", str(trained / "baseline"), str(trained / "longer"), "--reps", "100")
    assert refused.returncode != 0
    assert "another protocol (eval_episodes 2 and 4)" in refused.stderr
