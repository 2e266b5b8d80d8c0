"""python3 -m kage.bench compare DIR_A DIR_B [DIR_C ...] [--names A B ...] [--out DIR] [--protocol max|final]
    [--metric success_once|success|progress]

Two or more benchmark directories of one suite side by side, each a method (for example the baseline and the
agent trained on randomly shifted frames), with the report's interval estimates (kage.bench.intervals) per axis
and over all plain pairs:

- each method's IQM of eval and of train success and its success drop, with 95 % intervals;
- for every two methods X and Y, the probability of improvement P(X > Y) of eval success (rliable's: per pair,
  the probability that a run of X scores above a run of Y, ties counting half, averaged over the pairs), its
  interval from resampling each method's runs within each pair, independently of the other method's;
- the report's interval plot and performance profile with the methods overlaid.

Success is `success_once`; --metric chooses `success` or `progress` instead (after a few thousand steps no agent
succeeds, while their progress already differs).

Only finished runs enter, each scored as `kage.bench report --protocol` scores it, and only the (pair, seed)
results that every directory has finished, so that each estimate and each P(X > Y) compares the same pairs and
seeds: a directory whose runs are not all finished yet (a baseline still being published, a run still training)
or that ran other pairs (`kage.bench run --pairs`) is compared on what all have, and compare.md names each
method's results left out. The directories must have the same suite (the same pairs with the same train and
eval Specs), the same seeds and the same training and evaluation protocol (run.json: total steps, steps between
evaluations, evaluation episodes and environments, sampled or greedy evaluation); a directory that differs is
refused, naming what differs. The methods are named after their directories unless --names is given.

Output, in DIR_A/compare/ (or --out): compare.md, compare.csv (the estimates, one row per method and axis),
improvement.csv (P(X > Y) per axis and pair of methods), compare.json (everything) and plots/intervals.png,
plots/profile_<metric>.png.
"""
import argparse
import json
import os
import sys
from dataclasses import dataclass, field
from typing import Dict, List, NoReturn, Optional, Set, Tuple

from kage.bench import intervals, plots, report, stats
from kage.bench.interval_tables import explanation, fmt_drop, fmt_interval, intervals_csv
from kage.util.files import atomic_write, output_folder
from kage.fields import INTERVAL_METRICS, SUCCESS_SHOWN
from kage.util.tables import csv_text, md_table

SCHEDULE_ARGS = ("total_timesteps", "eval_every_steps", "eval_episodes", "eval_num_envs", "eval_greedy")


def fail(message: str) -> NoReturn:
    raise SystemExit(f"kage.bench compare: {message}")


@dataclass
class Method:
    name: str
    bench_dir: str
    suite: dict
    seeds: List[int]
    schedule: dict  # the SCHEDULE_ARGS its runs were trained with ({} where no run.json has arguments)
    units: List[report.Unit]
    runs: Dict[str, List[report.Run]]
    results: Set[Tuple[str, int]]  # the (pair, seed) results it has finished
    levels: dict = field(default_factory=dict)  # of the results that every method has (restrict)
    left_out: List[Tuple[str, int]] = field(default_factory=list)  # its results that another method lacks
    estimates: dict = field(default_factory=dict)


def schedule_of(run: report.Run) -> dict:
    """A run's training and evaluation schedule from its run.json arguments."""
    args = run.args
    every = None
    if all(isinstance(args.get(k), int) for k in ("run_eval_every", "num_envs", "num_steps")):
        every = args["run_eval_every"] * args["num_envs"] * args["num_steps"]
    return {"total_timesteps": args.get("total_timesteps"), "eval_every_steps": every,
            "eval_episodes": args.get("eval_episodes"), "eval_num_envs": args.get("eval_num_envs"),
            "eval_greedy": args.get("eval_greedy")}


def load(bench_dir: str, name: str, protocol: str) -> Method:
    try:
        suite, bench, units, runs = report.read_benchmark(bench_dir)
    except SystemExit as e:  # the report's refusal of a directory or a record, in compare's name
        prefix = "kage.bench report: "
        if str(e).startswith(prefix):
            fail(str(e)[len(prefix):])
        raise
    every_run = [r for unit_runs in runs.values() for r in unit_runs]
    schedules = {json.dumps(schedule_of(r), sort_keys=True) for r in every_run if r.args}
    if len(schedules) > 1:
        fail(f"the runs of {bench_dir} were trained with different schedules ({' and '.join(sorted(schedules))}): "
             "rerun them with one set of flags")
    seeds = bench.get("seeds") or sorted({r.seed for r in every_run})
    levels = report.aggregate(units, runs, protocol)
    if not levels["pairs"]:
        fail(f"{bench_dir} has no plain pair (only sweeps): compare reads plain pairs")
    if not levels["runs"]:
        unfinished = len(every_run)
        fail(f"{bench_dir} has no finished run (a run directory with summary.json)"
             + (f"; its {unfinished} runs are still training or stopped" if unfinished else "") +
             f": compare reads finished runs only: let them finish (kage.bench status {bench_dir}), or compare "
             "other directories")
    return Method(name, bench_dir, suite, sorted(seeds), json.loads(schedules.pop()) if schedules else {}, units,
                  runs, {(r["pair"], r["seed"]) for r in levels["runs"]})


def suite_differences(a: Method, b: Method) -> List[str]:
    """How b's suite differs from a's: pairs only in one, or pairs whose configs' Specs differ."""
    pairs_a = {p["pair"]: p for p in a.suite["pairs"]}
    pairs_b = {p["pair"]: p for p in b.suite["pairs"]}
    found = []
    for name, where in ((sorted(set(pairs_a) - set(pairs_b)), a), (sorted(set(pairs_b) - set(pairs_a)), b)):
        if name:
            found.append(f"pairs only in {where.bench_dir}: {', '.join(name[:5])}" + (" ..." if len(name) > 5 else ""))
    for name in sorted(set(pairs_a) & set(pairs_b)):
        for side in ("train", "eval"):
            sha_a, sha_b = pairs_a[name][side].get("spec_sha256"), pairs_b[name][side].get("spec_sha256")
            if sha_a != sha_b:
                found.append(f"{name}'s {side} config has another Spec (spec_sha256 {sha_a} and {sha_b})")
    return found


def check_comparable(methods: List[Method]) -> None:
    """Refuses, naming what differs, directories of other suites, seeds, pairs or schedules than the first."""
    first = methods[0]
    for other in methods[1:]:
        pair = f"{first.bench_dir} and {other.bench_dir}"
        differences = suite_differences(first, other)
        if differences:
            fail(f"{pair} are not of the same suite: {'; '.join(differences[:3])}: compare runs of one suite")
        if first.seeds != other.seeds:
            fail(f"{pair} have other seeds ({first.seeds} and {other.seeds}): run both with the same --seeds")
        unrecorded = [m.bench_dir for m in (first, other) if not m.schedule]
        if len(unrecorded) == 1:
            fail(f"the runs of {unrecorded[0]} have no run.json with their arguments, so their protocol cannot be "
                 "compared with the other directory's: restore their run.json files, or compare other directories")
        keys = [k for k in SCHEDULE_ARGS if first.schedule.get(k) != other.schedule.get(k)]
        if keys:
            shown = ", ".join(f"{k} {first.schedule.get(k)} and {other.schedule.get(k)}" for k in keys)
            fail(f"{pair} were trained or evaluated with another protocol ({shown}): compare runs trained and "
                 "evaluated alike")


def restrict(methods: List[Method], protocol: str, reps: int, metric: str) -> None:
    """Scores every method on the (pair, seed) results that all of them have finished, and notes what each
    leaves out; refuses when they have none in common."""
    common = set.intersection(*(m.results for m in methods))
    if not common:
        counts = ", ".join(f"{m.name} {len(m.results)}" for m in methods)
        fail(f"no (pair, seed) result is finished in every directory (finished: {counts}): run the same pairs "
             "and seeds, or wait for the runs to finish (kage.bench status DIR)")
    pairs = {pair for pair, _ in common}
    for m in methods:
        m.left_out = sorted(m.results - common)
        m.levels = report.aggregate(m.units, m.runs, protocol, keep=common)
        m.levels["pairs"] = [p for p in m.levels["pairs"] if p["pair"] in pairs]  # rows of the pairs compared
        m.levels["axes"] = report.axes_of(m.levels["pairs"])
        m.estimates = intervals.interval_report(m.levels["runs"], m.levels["pairs"], reps, metric)


def left_out_text(m: Method, shown: int = 12) -> str:
    """A method's results left out, grouped by pair: 'background/4 (10 seeds), background/6 (seeds 1, 2)', the
    first `shown` pairs (compare.json lists every one)."""
    seeds: Dict[str, List[int]] = {}
    for pair, seed in m.left_out:
        seeds.setdefault(pair, []).append(seed)
    parts = [f"{pair} ({len(s)} seeds)" if len(s) == len(m.seeds) else
             f"{pair} (seed{'s' if len(s) > 1 else ''} {', '.join(map(str, s))})" for pair, s in seeds.items()]
    more = f", ... ({len(parts)} pairs; compare.json lists them)" if len(parts) > shown else ""
    return f"**{m.name}** {len(m.left_out)}: {', '.join(parts[:shown])}{more}"


def improvement(x: Method, y: Method, pairs: List[dict], reps: int) -> dict:
    """P(X > Y) of the eval metric over the `pairs` (level-2 entries) that both methods have runs of."""
    metric = x.estimates["metric"]
    sx, sy = intervals.scores_of(x.levels["runs"], pairs, metric), intervals.scores_of(y.levels["runs"], pairs, metric)
    common = [p for p in sx.pairs if p in sy.pairs]
    if not common:
        return {"n_pairs": 0, "p": None}
    ix, iy = [sx.pairs.index(p) for p in common], [sy.pairs.index(p) for p in common]
    p = stats.probability_of_improvement(sx.eval[:, ix], sy.eval[:, iy], reps, intervals.CONFIDENCE, intervals.SEED,
                                         [sx.groups[i] for i in ix], [sy.groups[i] for i in iy])
    return {"n_pairs": len(common), "p": p._asdict()}


def improvements(methods: List[Method], reps: int) -> List[dict]:
    """For each two methods (in the order given) and each scope: per axis, then over all plain pairs."""
    pairs = methods[0].levels["pairs"]
    scopes: Dict[str, List[dict]] = {}
    for p in pairs:
        scopes.setdefault(p["axis"], []).append(p)
    scopes[intervals.ALL_PAIRS] = pairs
    rows = []
    for i, x in enumerate(methods):
        for y in methods[i + 1:]:
            rows += [{"scope": "all" if name == intervals.ALL_PAIRS else "axis", "name": name, "x": x.name,
                      "y": y.name, **improvement(x, y, members, reps)} for name, members in scopes.items()]
    return rows


# ---- tables ----

def md_estimates(methods: List[Method], key: str, fmt) -> str:
    by_name = [{row["name"]: row for row in m.estimates["rows"]} for m in methods]  # axes in each one's pair order
    rows = [[row["name"]] + [fmt(rows[row["name"]][key]) for rows in by_name] for row in methods[0].estimates["rows"]]
    return md_table(["axis"] + [m.name for m in methods], rows, 1)


def md_improvements(rows: List[dict]) -> str:
    columns = list(dict.fromkeys((r["x"], r["y"]) for r in rows))
    by_scope: Dict[str, dict] = {}
    for r in rows:
        by_scope.setdefault(r["name"], {"pairs": r["n_pairs"]})[(r["x"], r["y"])] = fmt_interval(r["p"])
    table = [[name, cells["pairs"]] + [cells[c] for c in columns] for name, cells in by_scope.items()]
    return md_table(["axis", "pairs"] + [f"P({x} > {y})" for x, y in columns], table, 1)


def markdown(methods: List[Method], rows: List[dict], protocol: str) -> str:
    metric = methods[0].estimates["metric"]
    listed = "; ".join(f"**{m.name}**: `{m.bench_dir}`, {len(m.results)} finished (pair, seed) results"
                       for m in methods)
    compared = len(methods[0].results) - len(methods[0].left_out)
    left_out = [left_out_text(m) for m in methods if m.left_out]
    schedule = ", ".join(f"{k} {v}" for k, v in methods[0].schedule.items() if v is not None) or "not recorded"
    return (f"# {methods[0].suite.get('suite', 'suite')}: {' vs '.join(m.name for m in methods)}\n\n"
            f"Methods: {listed}. Seeds {methods[0].seeds}; the same suite, seeds and protocol ({schedule}). "
            f"Compared on the {compared} (pair, seed) results that every method has finished"
            f"{'; left out, finished by some methods only: ' + '; '.join(left_out) if left_out else ''}. "
            f"{report.LEVEL_1[protocol][0].upper()}{report.LEVEL_1[protocol][1:]}.\n\n"
            f"## IQM of eval `{metric}`\n\n{md_estimates(methods, 'eval_iqm', fmt_interval)}\n"
            f"## IQM of train `{metric}`\n\n{md_estimates(methods, 'train_iqm', fmt_interval)}\n"
            f"## Drop of `{metric}`\n\n{md_estimates(methods, 'drop_pct', fmt_drop)}\n"
            f"## Probability of improvement of eval `{metric}`\n\n{md_improvements(rows)}\n"
            f"P(X > Y): per pair, the probability that a run of X has a higher eval {metric} than a run of Y (ties "
            "count half), averaged over the pairs both have runs of; 0.5 is no difference. Its interval resamples "
            "each method's runs within each pair, independently of the other method's.\n\n"
            f"{explanation(methods[0].estimates)}\n")


def improvement_csv(rows: List[dict]) -> str:
    return csv_text(("scope", "name", "x", "y", "n_pairs", "p", "p_low", "p_high"),
                    [[r["scope"], r["name"], r["x"], r["y"], r["n_pairs"],
                      *([None] * 3 if r["p"] is None else [r["p"]["point"], r["p"]["low"], r["p"]["high"]])]
                     for r in rows])


# ---- the command ----

def method_names(dirs: List[str], names: Optional[List[str]]) -> List[str]:
    if names is not None:
        if len(names) != len(dirs):
            fail(f"--names gives {len(names)} names for {len(dirs)} directories: give one per directory")
        chosen = names
    else:
        chosen = [os.path.basename(os.path.normpath(d)) for d in dirs]
    if len(set(chosen)) < len(chosen):
        fail(f"two methods would be named alike ({', '.join(chosen)}): name them with --names")
    return chosen


def compare(dirs: List[str], names: Optional[List[str]] = None, out_dir: Optional[str] = None,
            protocol: str = "max", reps: int = intervals.REPS, metric: str = SUCCESS_SHOWN) -> dict:
    """Compares the benchmark directories `dirs` (see the module's docstring), writes the tables and plots into
    `out_dir` (default dirs[0]/compare) and returns compare.json's content."""
    if len(dirs) < 2:
        fail("give two or more benchmark directories")
    if protocol not in report.PROTOCOLS:
        fail(f"unknown protocol '{protocol}': choose {' or '.join(report.PROTOCOLS)}")
    if metric not in INTERVAL_METRICS:
        fail(f"--metric takes {', '.join(INTERVAL_METRICS)}, not '{metric}'")
    if intervals.reps_problem(reps):
        fail(intervals.reps_problem(reps))
    methods = [load(d, name, protocol) for d, name in zip(dirs, method_names(dirs, names))]
    check_comparable(methods)
    restrict(methods, protocol, reps, metric)
    rows = improvements(methods, reps)
    out_dir = out_dir or os.path.join(dirs[0], "compare")
    result = {"kage_bench_compare": 1, "suite": methods[0].suite.get("suite", "suite"), "out_dir": out_dir,
              "protocol": {"score": protocol, "level_1_runs": report.LEVEL_1[protocol], **methods[0].schedule},
              "seeds": methods[0].seeds,
              "results_compared": len(methods[0].results) - len(methods[0].left_out),
              "methods": [{"name": m.name, "bench_dir": m.bench_dir, "results_finished": len(m.results),
                           "left_out": [{"pair": p, "seed": s} for p, s in m.left_out], "estimates": m.estimates}
                          for m in methods],
              "improvement": rows}
    try:
        write(out_dir, methods, result)
    except OSError as e:
        fail(f"cannot write into {out_dir} ({e}): give a writable directory with --out")
    return result


def write(out_dir: str, methods: List[Method], result: dict) -> None:
    output_folder(out_dir, "plots")
    files = {"compare.md": markdown(methods, result["improvement"], result["protocol"]["score"]).encode(),
             "compare.csv": intervals_csv([r for m in methods for r in m.estimates["rows"]],
                                          [m.name for m in methods for _ in m.estimates["rows"]]).encode(),
             "improvement.csv": improvement_csv(result["improvement"]).encode()}
    result["plots_note"] = None
    try:
        metric = methods[0].estimates["metric"]
        files["plots/intervals.png"] = plots.interval_estimates({m.name: m.estimates["rows"] for m in methods}, metric)
        profiles = {m.name: m.estimates["profile"]["eval"] for m in methods if m.estimates["profile"]}
        if profiles:
            files[f"plots/profile_{metric}.png"] = plots.performance_profiles(intervals.TAUS, profiles, metric=metric)
    except ImportError as e:  # the tables do not need matplotlib
        result["plots_note"] = f"no plots: {e}; install matplotlib (pip install matplotlib) and rerun"
        print(f"kage.bench compare: {result['plots_note']}", file=sys.stderr)
    result["files"] = sorted(files) + ["compare.json"]
    for name, data in files.items():
        atomic_write(os.path.join(out_dir, name), data)
    atomic_write(os.path.join(out_dir, "compare.json"), (json.dumps(result, indent=1, allow_nan=False) + "\n").encode())


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m kage.bench compare", description=__doc__.split("\n\n")[0])
    parser.add_argument("dirs", nargs="+", metavar="DIR", help="benchmark directories of one suite, two or more")
    parser.add_argument("--names", nargs="+", help="the methods' names, one per DIR (default: the directories' names)")
    parser.add_argument("--out", help="where to write (default DIR_A/compare)")
    parser.add_argument("--protocol", choices=report.PROTOCOLS, default="max",
                        help="a run's value: its maximum over training (the paper's) or its last evaluation")
    parser.add_argument("--reps", type=int, default=intervals.REPS, help="bootstrap resamples of the intervals")
    parser.add_argument("--metric", choices=INTERVAL_METRICS, default=SUCCESS_SHOWN,
                        help="the eval metric compared (default success_once)")
    args = parser.parse_args(argv)
    result = compare(args.dirs, args.names, args.out, args.protocol, args.reps, args.metric)
    with open(os.path.join(result["out_dir"], "compare.md"), encoding="utf-8") as f:
        sys.stdout.write(f.read())
    print(f"kage.bench compare: wrote {result['out_dir']}", file=sys.stderr)
    return 0
