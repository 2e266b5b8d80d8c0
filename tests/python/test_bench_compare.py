"""kage.bench compare: two benchmark directories side by side (IQMs with intervals, P(X > Y), the overlaid
plots), on hand-made directories with values worked out here and end to end on two tiny CPU benchmarks (the
baseline and the random-shift agent); that it compares only the (pair, seed) results every directory has; and
its refusals of directories whose suite, seeds or protocol differ."""
import csv
import json
import shutil

import pytest
from test_bench_e2e import TINY, bench as bench_cli, run as run_tiny
from test_report import PNG_SIGNATURE, pair, plain, write_run
from test_report_intervals import rows_for, write_suite

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
    result = compare.compare([str(a), str(b), str(c)], names=["base", "shift", "mine"], reps=500)
    assert {(r["x"], r["y"]) for r in result["improvement"]} == {("base", "shift"), ("base", "mine"),
                                                                ("shift", "mine")}
    assert "P(base > mine)" in (a / "compare" / "compare.md").read_text()


# ---- refusals ----

def test_refuses_another_suite(two):
    a, b = two
    suite = json.loads((b / "suite.json").read_text())
    suite["pairs"][0]["eval"]["spec_sha256"] = "cc"
    (b / "suite.json").write_text(json.dumps(suite))
    with pytest.raises(SystemExit, match=r"are not of the same suite: background/1's eval config has another Spec "
                                         r"\(spec_sha256 bb and cc\)"):
        compare.compare([str(a), str(b)], reps=100)
    (b / "suite.json").write_text(json.dumps({**suite, "pairs": suite["pairs"][1:]}))
    with pytest.raises(SystemExit, match=r"pairs only in .*A: background/1"):
        compare.compare([str(a), str(b)], reps=100)


def test_refuses_other_seeds(two, tmp_path):
    a, _ = two
    fewer = method(tmp_path / "D", {"background/1": [0.1, 0.2]}, seeds=(1, 2))
    with pytest.raises(SystemExit,
                       match=r"have other seeds \(\[1, 2, 3\] and \[1, 2\]\): run both with the same --seeds"):
        compare.compare([str(a), str(fewer)], reps=100)


def test_compares_the_results_every_method_has(two):
    """B ran two of the three pairs (run --pairs) and its seed 3 is still training: both are compared on seeds 1
    and 2 of background/1 and 2, and compare.md names what A has beyond them."""
    a, b = two
    bench = json.loads((b / "bench.json").read_text())
    (b / "bench.json").write_text(json.dumps({**bench, "units": ["background/1", "background/2"]}))
    shutil.rmtree(b / "runs" / "layout/1")
    for name in ("background/1", "background/2"):
        (b / "runs" / name / "seed_3" / "summary.json").unlink()
    result = compare.compare([str(a), str(b)], reps=500)
    assert result["results_compared"] == 4
    methods = {m["name"]: m for m in result["methods"]}
    assert methods["A"]["results_finished"] == 9 and methods["B"]["results_finished"] == 4
    assert methods["A"]["left_out"] == [{"pair": "background/1", "seed": 3}, {"pair": "background/2", "seed": 3},
                                        *({"pair": "layout/1", "seed": s} for s in (1, 2, 3))]
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
    assert ("Compared on the 4 (pair, seed) results that every method has finished; left out, finished by some "
            "methods only: **A** 5: background/1 (seed 3), background/2 (seed 3), layout/1 (3 seeds).") in md


def test_refuses_directories_with_no_result_in_common(two):
    """B finished only layout/1, whose runs A has not finished."""
    a, b = two
    bench = json.loads((b / "bench.json").read_text())
    (b / "bench.json").write_text(json.dumps({**bench, "units": ["layout/1"]}))
    for name in ("background/1", "background/2"):
        shutil.rmtree(b / "runs" / name)
    for seed in (1, 2, 3):
        (a / "runs" / "layout/1" / f"seed_{seed}" / "summary.json").unlink()
    with pytest.raises(SystemExit, match=r"no \(pair, seed\) result is finished in every directory \(finished: A 6, B "
                                         r"3\): run the same pairs and seeds"):
        compare.compare([str(a), str(b)], reps=100)


def test_a_directory_without_finished_runs_is_named(two, tmp_path):
    """B with no run at all, or with runs that have not finished: the message says so (it said "another protocol
    (total_timesteps 2048 and None ...)" for the first), in compare's name."""
    a, b = two
    empty = tmp_path / "empty"
    write_suite(empty, PAIRS)
    with pytest.raises(SystemExit, match=r"^kage.bench compare: .*empty has no finished run \(a run directory with "
                                         r"summary.json\): compare reads finished runs only: let them finish "
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
    with pytest.raises(SystemExit, match=r"another protocol \(total_timesteps 2048 and 4096, eval_episodes 2 and 8\)"):
        compare.compare([str(a), str(longer)], reps=100)


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
    done = run_tiny(trained / "longer", "--pack", "2", "--eval-episodes", "4")
    assert done.returncode == 0, done.stderr
    refused = bench_cli("compare", str(trained / "baseline"), str(trained / "longer"), "--reps", "100")
    assert refused.returncode != 0
    assert "another protocol (eval_episodes 2 and 4)" in refused.stderr
