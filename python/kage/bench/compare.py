"""python3 -m kage.bench compare DIR_A DIR_B [DIR_C ...] [--names A B ...] [--out DIR] [--protocol max|final]
    [--metric success_once|success|progress] [--seeds 1-5] [--pairs NAME ...] [--max-step N]

Two or more benchmark directories side by side, each a method (for example the baseline, the agent trained on
randomly shifted frames, and the agent trained on a mixture of configs), with the report's interval estimates
(kage.bench.intervals) per axis and over all plain pairs compared:

- each method's IQM of eval and of train success and its success drop, with 95 % intervals;
- for every two methods X and Y, the probability of improvement P(X > Y) of eval success (rliable's: per pair,
  the probability that a run of X scores above a run of Y, ties counting half, averaged over the pairs), its
  interval from resampling each method's runs within each pair, independently of the other method's;
- per method, its training runs (kage.bench.training_runs): the mean of their best train success, how many never
  passed 0.1 and how many ended collapsed to the never-jump policy, as the published table counts them;
- the report's interval plot and performance profile with the methods overlaid.

Success is `success_once`; --metric chooses `success` or `progress` instead (after a few thousand steps no agent
succeeds, while their progress already differs).

What is compared:
- pairs: those named by --pairs (plain pairs, which every directory must have run), else the plain pairs that
  every directory ran; compare.md and compare.json name each method's pairs left out. Each compared pair must
  evaluate on the same Spec in every directory; its train side may differ (another config, a mixture, a
  schedule: a method that trains otherwise), and compare.md says what each method trains on;
- seeds: those of --seeds (which every directory must have), else the directories' seeds, which must be equal;
- results: of these pairs and seeds, the (pair, seed) results that every directory has finished, so that each
  estimate and each P(X > Y) compares the same pairs and seeds; compare.md names each method's results left
  out (a run still training, a baseline still being published);
- protocol: the runs must be evaluated alike (run.json: steps between evaluations, evaluation episodes and
  environments, sampled or greedy evaluation) and trained for as many steps, unless --max-step N scores every
  run on its evaluation rows at or before step N only (metrics.jsonl; under --protocol max their maximum, under
  final the last of them), so that a method trained for N steps meets the others' first N steps. N is at most
  every directory's total steps and at least its first evaluation after step 0.
Each run is scored as `kage.bench report --protocol` scores it. A directory that differs otherwise is refused,
naming what differs. The methods are named after their directories unless --names is given.

Output, in DIR_A/compare/ (or --out): compare.md, compare.csv (the estimates, one row per method and axis),
improvement.csv (P(X > Y) per axis and pair of methods), compare.json (everything) and plots/intervals.png,
plots/profile_<metric>.png.
"""
import argparse
import contextlib
import copy
import dataclasses
import difflib
import json
import os
import sys
from dataclasses import dataclass, field
from typing import Dict, List, NoReturn, Optional, Set, Tuple

from kage.bench import intervals, plots, report, stats, training_runs
from kage.bench.records import parse_seeds, seeds_text
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
    results: Set[Tuple[str, int]]  # the (pair, seed) results it has finished (of the pairs and seeds compared)
    pairs: Dict[str, dict]  # its plain pairs' suite.json entries, of the units it ran, by name in manifest order
    pairs_left_out: List[str] = field(default_factory=list)  # its pairs that another method did not run
    levels: dict = field(default_factory=dict)  # of the results that every method has (restrict)
    left_out: List[Tuple[str, int]] = field(default_factory=list)  # its results that another method lacks
    trains_on: List[dict] = field(default_factory=list)  # what it trains on for the pairs compared (trains_on)
    last_steps: List[int] = field(default_factory=list)  # under --max-step, its runs' last evaluation steps scored
    training: List[training_runs.Outcome] = field(default_factory=list)  # the training runs behind its results
    trainer_flags: List[str] = field(default_factory=list)  # bench.json's trainer_args: what sets the methods apart
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


def scored(run: report.Run, max_step: Optional[int]) -> bool:
    """Whether a run enters the comparison: finished, or, under --max-step, logged past that step (every evaluation
    at or before it is then written, and none later is read)."""
    return run.stats is not None or (max_step is not None and bool(run.evaluations) and
                                     run.evaluations[-1]["global_step"] >= max_step)


@contextlib.contextmanager
def in_compares_name():
    """The report's refusals of a directory or a record, in compare's name."""
    try:
        yield
    except SystemExit as e:
        prefix = "kage.bench report: "
        if str(e).startswith(prefix):
            fail(str(e)[len(prefix):])
        raise


def load(bench_dir: str, name: str, protocol: str, max_step: Optional[int] = None) -> Method:
    with in_compares_name():
        suite, bench, units, runs = report.read_benchmark(bench_dir)
    every_run = [r for unit_runs in runs.values() for r in unit_runs]
    schedules = {json.dumps(schedule_of(r), sort_keys=True) for r in every_run if r.args}
    if len(schedules) > 1:
        fail(f"the runs of {bench_dir} were trained with different schedules ({' and '.join(sorted(schedules))}): "
             "rerun them with one set of flags")
    seeds = bench.get("seeds") or sorted({r.seed for r in every_run})
    with in_compares_name():
        levels = report.aggregate(units, runs, protocol, partial=max_step is not None, max_step=max_step)
    counted = {r.path for r in every_run if scored(r, max_step)}
    levels["runs"] = [r for r in levels["runs"] if r["path"] in counted]
    if not levels["pairs"]:
        fail(f"{bench_dir} has no plain pair (only sweeps): compare reads plain pairs")
    if not levels["runs"]:
        unfinished = len(every_run)
        fail(f"{bench_dir} has no finished run (a run directory with summary.json)"
             + (f" and none logged past step {max_step}" if max_step is not None else "")
             + (f"; its {unfinished} runs are still training or stopped" if unfinished else "") +
             f": compare reads finished runs only (and, under --max-step, runs logged past it): let them finish "
             f"(kage.bench status {bench_dir}), or compare other directories")
    ran = {p["pair"] for u in units if not u.is_sweep for p in u.pairs}
    return Method(name, bench_dir, suite, sorted(seeds), json.loads(schedules.pop()) if schedules else {}, units,
                  runs, {(r["pair"], r["seed"]) for r in levels["runs"]},
                  {p["pair"]: p for p in suite["pairs"] if p["pair"] in ran},
                  trainer_flags=list(bench.get("trainer_args") or []))


def load_once(cache: Optional[dict], bench_dir: str, name: str, protocol: str, max_step: Optional[int]) -> Method:
    """load, or a copy of what an earlier compare with the same `cache` loaded from the directory: reading its runs'
    logs is most of a compare's time, and a caller comparing one directory with many others reads it once."""
    if cache is None:
        return load(bench_dir, name, protocol, max_step)
    key = (os.path.realpath(bench_dir), protocol, max_step)
    if key not in cache:
        cache[key] = load(bench_dir, name, protocol, max_step)
    return dataclasses.replace(copy.deepcopy(cache[key]), name=name)  # compare changes its methods: never the cached


def choose_seeds(methods: List[Method], wanted: Optional[List[int]]) -> List[int]:
    """The seeds compared: `wanted` (--seeds), which every directory must have, else the directories' seeds,
    which must be equal."""
    first = methods[0]
    if wanted is None:
        for other in methods[1:]:
            if other.seeds != first.seeds:
                shared = sorted(set(first.seeds) & set(other.seeds))
                hint = f", or compare the seeds they share with --seeds {seeds_text(shared)}" if shared else ""
                fail(f"{first.bench_dir} and {other.bench_dir} have other seeds ({seeds_text(first.seeds)} and "
                     f"{seeds_text(other.seeds)}): run both with the same --seeds{hint}")
        return first.seeds
    for m in methods:
        missing = [s for s in wanted if s not in m.seeds]
        if missing:
            fail(f"{m.bench_dir} has no seed {seeds_text(missing)} (its seeds are {seeds_text(m.seeds)}): give "
                 "--seeds that every directory has, or run these seeds into it (kage.bench run --seeds)")
    return wanted


def choose_pairs(methods: List[Method], wanted: Optional[List[str]]) -> List[str]:
    """The plain pairs compared, in the first directory's order: `wanted` (--pairs), which every directory must
    have run, else those that every directory ran, noting in each method the pairs it ran beyond them."""
    if wanted:
        for name in wanted:
            for m in methods:
                if name not in m.pairs:
                    close = difflib.get_close_matches(name, list(m.pairs), n=3)
                    hint = f"; did you mean {', '.join(close)}?" if close else ""
                    fail(f"--pairs {name}: {m.bench_dir} ran no plain pair of that name{hint}: give --pairs that "
                         "every directory ran")
        return [p for p in methods[0].pairs if p in wanted]
    common = [p for p in methods[0].pairs if all(p in m.pairs for m in methods[1:])]
    if not common:
        counts = ", ".join(f"{m.name} {len(m.pairs)} ({', '.join(list(m.pairs)[:3])}"
                           f"{' ...' if len(m.pairs) > 3 else ''})" for m in methods)
        fail(f"the directories ran no plain pair in common (pairs: {counts}): compare directories of one suite's "
             "pairs, or name pairs that all ran with --pairs")
    for m in methods:
        m.pairs_left_out = [p for p in m.pairs if p not in common]
    return common


def check_pairs(methods: List[Method], pairs: List[str]) -> None:
    """Refuses a compared pair that another directory evaluates on another Spec or puts on another axis; its
    train side may differ (a method that trains otherwise)."""
    first = methods[0]
    for name in pairs:
        a = first.pairs[name]
        for other in methods[1:]:
            b = other.pairs[name]
            both = f"{first.bench_dir} and {other.bench_dir}"
            sha_a, sha_b = a["eval"].get("spec_sha256"), b["eval"].get("spec_sha256")
            if sha_a != sha_b:
                fail(f"{both} evaluate {name} on other configs (eval spec_sha256 {sha_a} and {sha_b}): compare methods "
                     f"evaluated on the same configs, or leave {name} out with --pairs")
            if a["declared_axis"] != b["declared_axis"]:
                fail(f"{both} put {name} on other axes ({a['declared_axis']} and {b['declared_axis']}): compare "
                     f"suites that agree on the pair's axis, or leave {name} out with --pairs")


def check_protocol(methods: List[Method], max_step: Optional[int]) -> None:
    """Refuses directories evaluated otherwise than the first, or trained for other total steps without
    --max-step, and a --max-step outside a directory's evaluations."""
    first = methods[0]
    for other in methods[1:]:
        pair = f"{first.bench_dir} and {other.bench_dir}"
        unrecorded = [m.bench_dir for m in (first, other) if not m.schedule]
        if len(unrecorded) == 1:
            fail(f"the runs of {unrecorded[0]} have no run.json with their arguments, so their protocol cannot be "
                 "compared with the other directory's: restore their run.json files, or compare other directories")
        keys = [k for k in SCHEDULE_ARGS if first.schedule.get(k) != other.schedule.get(k)
                and not (k == "total_timesteps" and max_step is not None)]
        if keys:
            shown = ", ".join(f"{k} {first.schedule.get(k)} and {other.schedule.get(k)}" for k in keys)
            fix = "compare runs trained and evaluated alike"
            if keys == ["total_timesteps"]:
                steps = [m.schedule["total_timesteps"] for m in (first, other)]
                most = f" (at most {min(steps)})" if all(isinstance(x, int) for x in steps) else ""
                fix = f"compare their first N steps with --max-step N{most}"
            elif "total_timesteps" in keys:
                fix += " (other total_timesteps alone: compare their first N steps with --max-step N)"
            fail(f"{pair} were trained or evaluated with another protocol ({shown}): {fix}")
    if max_step is None:
        return
    for m in methods:
        total, every = m.schedule.get("total_timesteps"), m.schedule.get("eval_every_steps")
        if not isinstance(total, int) or not isinstance(every, int):
            fail(f"the runs of {m.bench_dir} have no run.json with their total_timesteps, run_eval_every, num_envs "
                 "and num_steps, which --max-step reads: restore their run.json files, or compare without --max-step")
        if every <= 0:
            fail(f"the runs of {m.bench_dir} were trained without evaluations (run_eval_every 0), whose rows "
                 "--max-step reads: compare without --max-step")
        if max_step > total:
            fail(f"--max-step {max_step} is beyond the {total} steps that the runs of {m.bench_dir} trained for: "
                 f"give at most --max-step {min(x.schedule['total_timesteps'] for x in methods)}")
        if max_step < every:
            fail(f"--max-step {max_step} is before the first evaluation after step 0 of the runs of {m.bench_dir} "
                 f"(step {every}): give at least --max-step {max(x.schedule['eval_every_steps'] for x in methods)}")


def check_rows(m: Method, keep: Set[Tuple[str, int]], max_step: int) -> None:
    """Refuses a compared run whose metrics.jsonl stops short of --max-step: the last of its evaluations at or
    before that step must come after step min(max_step, total) - the steps between evaluations."""
    after = min(max_step, m.schedule["total_timesteps"]) - m.schedule["eval_every_steps"]
    last: Set[int] = set()
    for unit in m.units:
        for run in m.runs[unit.name]:
            if not scored(run, max_step) or not any((p["pair"], run.seed) in keep for p in unit.pairs):
                continue
            steps = [r["global_step"] for r in run.evaluations if r["global_step"] <= max_step]
            if not steps or steps[-1] <= after:
                found = f"its last is at step {steps[-1]}" if steps else "it has none"
                fail(f"{os.path.join(run.path, 'metrics.jsonl')} has no evaluation row after step {after} and at "
                     f"or before step {max_step}, which --max-step {max_step} reads ({found}): the log is "
                     "incomplete: delete the run directory and rerun `python3 -m kage.bench run`, or compare "
                     "without it (--seeds, --pairs)")
            last.add(steps[-1])
    m.last_steps = sorted(last)


def restrict(methods: List[Method], pairs: List[str], seeds: List[int], protocol: str, reps: int, metric: str,
             max_step: Optional[int] = None) -> None:
    """Scores every method on the (pair, seed) results of `pairs` and `seeds` that all of them have finished,
    on their evaluation rows up to `max_step` where given, and notes what each leaves out; refuses when they
    have none in common."""
    scope = {(p, s) for p in pairs for s in seeds}
    for m in methods:
        m.seeds = seeds
        m.results &= scope
    common = set.intersection(*(m.results for m in methods))
    if not common:
        counts = ", ".join(f"{m.name} {len(m.results)}" for m in methods)
        fail(f"no (pair, seed) result of the pairs and seeds compared is finished in every directory (finished: "
             f"{counts}): run the same pairs and seeds, or wait for the runs to finish (kage.bench status DIR)")
    compared = {pair for pair, _ in common}
    for m in methods:
        if max_step is not None:
            check_rows(m, common, max_step)
        m.left_out = sorted(m.results - common)
        m.levels = report.aggregate(m.units, m.runs, protocol, partial=max_step is not None, keep=common,
                                    max_step=max_step)
        m.levels["pairs"] = [p for p in m.levels["pairs"] if p["pair"] in compared]  # rows of the pairs compared
        m.levels["axes"] = report.axes_of(m.levels["pairs"])
        m.estimates = intervals.interval_report(m.levels["runs"], m.levels["pairs"], reps, metric)
        m.training = training_of(m, metric, max_step)


def training_of(m: Method, metric: str, max_step: Optional[int]) -> List[training_runs.Outcome]:
    """The outcome of each training run (run directory) behind the method's compared results, in unit and seed
    order, on its evaluation rows up to `max_step` where given."""
    paths = {r["path"] for r in m.levels["runs"]}
    found = (training_runs.outcome(unit.name, run.seed, run.evaluations, metric, max_step)
             for unit in m.units for run in sorted(m.runs[unit.name], key=lambda r: r.seed) if run.path in paths)
    return [o for o in found if o is not None]  # a run scored from summary.json alone has no row to read


def trains_on(m: Method, pairs: List[str]) -> List[dict]:
    """What the method trains on for the compared `pairs`, grouped by name: a config's file name, "mixture of
    N", or a schedule's file name."""
    groups: Dict[str, List[str]] = {}
    for name in pairs:
        groups.setdefault(os.path.basename(m.pairs[name]["train"]["name"]), []).append(name)
    return [{"name": name, "pairs": members} for name, members in groups.items()]


def level_1_text(protocol: str, max_step: Optional[int]) -> str:
    if max_step is None:
        return report.LEVEL_1[protocol]
    return {"max": f"per run, each value's maximum over its evaluation points at or before step {max_step}, every "
                   "side maximised independently",
            "final": f"per run, each value at its last evaluation point at or before step {max_step}"}[protocol]


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


def pairs_text(m: Method, shown: int = 12) -> str:
    """A method's pairs left out: '**B** 2: layout/1, layout/2', the first `shown` (compare.json lists all)."""
    more = ", ... (compare.json lists them)" if len(m.pairs_left_out) > shown else ""
    return f"**{m.name}** {len(m.pairs_left_out)}: {', '.join(m.pairs_left_out[:shown])}{more}"


def trains_text(m: Method) -> str:
    return f"**{m.name}** " + ", ".join(f"{t['name']} ({len(t['pairs'])} pair{'s' if len(t['pairs']) > 1 else ''})"
                                        for t in m.trains_on)


def markdown(methods: List[Method], rows: List[dict], result: dict) -> str:
    metric = methods[0].estimates["metric"]
    protocol = result["protocol"]
    done = "finished (pair, seed) results" if protocol["max_step"] is None else \
        f"(pair, seed) results finished or logged past step {protocol['max_step']}"
    listed = "; ".join(f"**{m.name}**: `{m.bench_dir}`, {len(m.results)} {done}, trainer flags "
                       f"{'`' + ' '.join(m.trainer_flags) + '`' if m.trainer_flags else 'none (the defaults)'}"
                       for m in methods)
    left_out = [left_out_text(m) for m in methods if m.left_out]
    pairs_out = [pairs_text(m) for m in methods if m.pairs_left_out]
    chosen = result["pairs_chosen"]
    n = len(result["pairs"])
    pairs = (f"{n} pair{'s' if n > 1 else ''}{' (--pairs)' if chosen else ', those every directory ran'}"
             f"{'; left out, run by some methods only: ' + '; '.join(pairs_out) if pairs_out else ''}")
    schedule = ", ".join(f"{k} {protocol[k]}" for k in SCHEDULE_ARGS if protocol.get(k) is not None) or "not recorded"
    steps = "" if protocol["max_step"] is None else \
        f"; every run scored up to step {protocol['max_step']} (--max-step; trained for " + \
        ", ".join(f"{m.name} {m.schedule.get('total_timesteps')}" for m in methods) + " steps)"
    if len({tuple(m.last_steps) for m in methods}) > 1:
        steps += ("; their last evaluations scored are at step " +
                  ", ".join(f"{' and '.join(map(str, m.last_steps))} ({m.name})" for m in methods) +
                  f": a multiple of {protocol['eval_every_steps']} steps scores the same evaluation points")
    differ = len({json.dumps([m.pairs[p]["train"].get("spec_sha256") for p in result["pairs"]]) for m in methods}) > 1
    trains = "; ".join(trains_text(m) for m in methods) + (
        ". The methods train differently, so each one's train success is measured on its own training (for a "
        "mixture, on the mixture); the eval side is the same configs for all" if differ else "")
    return (f"# {methods[0].suite.get('suite', 'suite')}: {' vs '.join(m.name for m in methods)}\n\n"
            f"Methods: {listed}. Seeds {seeds_text(methods[0].seeds)}{' (--seeds)' if result['seeds_chosen'] else ''}; "
            f"{pairs}; the same eval configs and protocol ({schedule}{steps}). Trains on: {trains}. "
            f"Compared on the {result['results_compared']} (pair, seed) results that every method has finished"
            f"{'; left out, finished by some methods only: ' + '; '.join(left_out) if left_out else ''}. "
            f"{protocol['level_1_runs'][0].upper()}{protocol['level_1_runs'][1:]}.\n\n"
            f"## IQM of eval `{metric}`\n\n{md_estimates(methods, 'eval_iqm', fmt_interval)}\n"
            f"## IQM of train `{metric}`\n\n{md_estimates(methods, 'train_iqm', fmt_interval)}\n"
            f"## Drop of `{metric}`\n\n{md_estimates(methods, 'drop_pct', fmt_drop)}\n"
            f"## Probability of improvement of eval `{metric}`\n\n{md_improvements(rows)}\n"
            f"P(X > Y): per pair, the probability that a run of X has a higher eval {metric} than a run of Y (ties "
            "count half), averaged over the pairs both have runs of; 0.5 is no difference. Its interval resamples "
            "each method's runs within each pair, independently of the other method's.\n\n"
            f"## Train success and collapse\n\n{md_training(methods, metric)}\n"
            "Per training run (a run directory, however many pairs it is scored for): its maximum train "
            f"{metric} over the evaluation points scored, and whether it ended collapsed to the never-jump policy "
            "(no jump on its train config at the last evaluation point scored).\n\n"
            f"{explanation(methods[0].estimates)}\n")


def md_training(methods: List[Method], metric: str) -> str:
    rows = []
    for m in methods:
        counts = training_runs.summary(m.training)
        mean = "-" if counts["mean_best"] is None else f"{counts['mean_best']:.2f}"
        rows.append([m.name, counts["runs"], mean, counts["never_learned"], counts["collapsed"]])
    return md_table(["method", "training runs", f"mean of max train {metric}",
                     f"never above {training_runs.NEVER_LEARNED}", "collapsed"], rows, 1)


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
    if not all(name.strip() for name in chosen):
        fail(f"--names {' '.join(repr(n) for n in chosen)}: a method's name is the title of its columns: give "
             "each a non-empty name")
    if len(set(chosen)) < len(chosen):
        fail(f"two methods would be named alike ({', '.join(chosen)}): name them with --names")
    return chosen


def compare(dirs: List[str], names: Optional[List[str]] = None, out_dir: Optional[str] = None,
            protocol: str = "max", reps: int = intervals.REPS, metric: str = SUCCESS_SHOWN,
            seeds: Optional[List[int]] = None, pairs: Optional[List[str]] = None,
            max_step: Optional[int] = None, cache: Optional[dict] = None) -> dict:
    """Compares the benchmark directories `dirs` (see the module's docstring) on `seeds` (--seeds), `pairs`
    (--pairs) and up to step `max_step` (--max-step) where given, writes the tables and plots into `out_dir`
    (default dirs[0]/compare) and returns compare.json's content. `cache`: a dict kept between calls that compare
    the same directories again, unchanged in between (load_once)."""
    if len(dirs) < 2:
        fail("give two or more benchmark directories")
    if protocol not in report.PROTOCOLS:
        fail(f"unknown protocol '{protocol}': choose {' or '.join(report.PROTOCOLS)}")
    if metric not in INTERVAL_METRICS:
        fail(f"--metric takes {', '.join(INTERVAL_METRICS)}, not '{metric}'")
    if intervals.reps_problem(reps):
        fail(intervals.reps_problem(reps))
    if max_step is not None and (not isinstance(max_step, int) or isinstance(max_step, bool) or max_step <= 0):
        fail(f"--max-step takes a number of steps above 0, not {max_step!r}")
    methods = [load_once(cache, d, name, protocol, max_step) for d, name in zip(dirs, method_names(dirs, names))]
    chosen_seeds = choose_seeds(methods, seeds)
    chosen_pairs = choose_pairs(methods, pairs)
    check_pairs(methods, chosen_pairs)
    check_protocol(methods, max_step)
    restrict(methods, chosen_pairs, chosen_seeds, protocol, reps, metric, max_step)
    for m in methods:
        m.trains_on = trains_on(m, chosen_pairs)
    rows = improvements(methods, reps)
    out_dir = out_dir or os.path.join(dirs[0], "compare")
    totals = {m.schedule.get("total_timesteps") for m in methods}
    result = {"kage_bench_compare": 1, "suite": methods[0].suite.get("suite", "suite"), "out_dir": out_dir,
              "protocol": {"score": protocol, "level_1_runs": level_1_text(protocol, max_step), "max_step": max_step,
                           **methods[0].schedule, "total_timesteps": totals.pop() if len(totals) == 1 else None},
              "seeds": methods[0].seeds, "seeds_chosen": seeds is not None,
              "pairs": chosen_pairs, "pairs_chosen": bool(pairs),
              "results_compared": len(methods[0].results) - len(methods[0].left_out),
              "methods": [{"name": m.name, "bench_dir": m.bench_dir,
                           "total_timesteps": m.schedule.get("total_timesteps"), "trains_on": m.trains_on,
                           "last_evaluation_steps": m.last_steps if max_step is not None else None,
                           "training": {p: m.pairs[p]["train"].get("spec_sha256") for p in chosen_pairs},
                           "pairs_left_out": m.pairs_left_out, "results_finished": len(m.results),
                           "left_out": [{"pair": p, "seed": s} for p, s in m.left_out], "estimates": m.estimates,
                           "training_runs": {**training_runs.summary(m.training),
                                             "runs_listed": [dataclasses.asdict(o) for o in m.training]}}
                          for m in methods],
              "improvement": rows}
    try:
        write(out_dir, methods, result)
    except OSError as e:
        fail(f"cannot write into {out_dir} ({e}): give a writable directory with --out")
    return result


def write(out_dir: str, methods: List[Method], result: dict) -> None:
    output_folder(out_dir, "plots")
    files = {"compare.md": markdown(methods, result["improvement"], result).encode(),
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
    parser.add_argument("--seeds", help="compare only these seeds of every directory: 1-5, 1,3,5 or 7 (default: all, "
                                        "which must be the same in every directory)")
    parser.add_argument("--pairs", nargs="+", metavar="NAME",
                        help="compare only these plain pairs, which every directory ran (default: those all ran)")
    parser.add_argument("--max-step", type=int, metavar="N",
                        help="score every run on its evaluations at or before step N only (needed where the "
                             "directories trained for other total steps)")
    args = parser.parse_args(argv)
    seeds = None
    if args.seeds is not None:
        try:
            seeds = parse_seeds(args.seeds)
        except SystemExit as e:  # parse_seeds speaks for kage.bench
            fail(str(e).split(": ", 1)[1])
    result = compare(args.dirs, args.names, args.out, args.protocol, args.reps, args.metric, seeds, args.pairs,
                     args.max_step)
    with open(os.path.join(result["out_dir"], "compare.md"), encoding="utf-8") as f:
        sys.stdout.write(f.read())
    print(f"kage.bench compare: wrote {result['out_dir']}", file=sys.stderr)
    return 0
