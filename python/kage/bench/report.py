"""python3 -m kage.bench report DIR: the benchmark's tables and plots from a directory of training runs.

Input, as `python3 -m kage.bench run` writes it:

    DIR/suite.json                 the suite's pairs (kagec suite): names, axes, sweeps, certificates
    DIR/bench.json                 the seeds and units asked for, and under --share-training each
                                   pair's shared run and label (optional here)
    DIR/runs/<unit>/seed_<s>/      a kage.ppo.train run directory: a plain pair's (unit = the pair's name, eval
                                   label "eval"), a sweep's (unit = the sweep's name, one eval label per
                                   eval config: its name in the sweep), or a shared run's (several plain
                                   pairs with one train config, one eval label per pair)

The protocol is the paper's (kage-ppo-baseline.md §5), in three levels:
1. per run (`protocol` "max", the default): each value's maximum over the run's evaluation points (summary.json's
   "max"), the train side (train/<m>), each eval side (eval/<label>/<m>) and each absolute difference
   (diff/<label>/<m>) maximised independently, so a run's best train and best eval values may come from
   different checkpoints (§5.1). The maximum of 32 noisy evaluations flatters a run; `protocol` "final" takes
   instead each value at the run's last evaluation point (the final checkpoint: metrics.jsonl's last row);
2. per pair: the mean and SEM over seeds, SEM = s / sqrt(n) with s the sample standard deviation
   (divisor n - 1), and SEM = 0 for n = 1 (§5.2);
3. per axis: the mean and SEM (same formula) of the axis's per-pair means, each pair weighted equally, the
   seed-level SEMs discarded (§5.3). Only plain pairs enter the axes; a sweep gets its own table, one row
   per eval config, at level 2.
At every level, gap = train - eval and drop = 100 * (train - eval) / train are computed on the aggregated
means of that level, not averaged from the level below. The paper's per-axis drops match this formula; the
original code does not compute it (§5.4). The drop is undefined (null in JSON, empty in CSV, "n/a" in
Markdown) where the train mean is 0. `max_abs_diff` is the original's own gap measure: per run, the largest
|train - eval| at a single evaluation point, then averaged like any other value.

Beside these, interval estimates of success (kage.bench.intervals, after rliable; of progress or success with
`metric`): per axis and over all plain pairs, the IQM of eval and train success with 95 % stratified-bootstrap
intervals and the drop with a paired ratio bootstrap, and the performance profile of eval success.

Only finished runs (with summary.json) enter the tables; unfinished ones are counted and listed. With `partial`
(--partial), unfinished runs enter too, scored over the evaluation points they have logged (their maximum, or
their latest under "final"): an interim report, written by default into DIR/report_interim/ (report_final_interim/
under "final") so that it never replaces the final one. Every Markdown file of an interim report is titled
interim and lists how far each unfinished run got (evaluations, latest step, of how many); every CSV gets a first
column "interim"; every plot says so in red above it. A pair, sweep or axis without a run in the tables appears
with n = 0 and empty values. A side's mean is over the values
that exist: return and length are null where every listed episode returned exactly 0; report.json gives
each side's n.

The Markdown tables show `success_once` in their "success" column (the episode reached the goal at some
step: what the paper's success-rate plots show); `success` (past the goal at the episode's end) is in the
CSV and JSON files with every other metric.

Output, in DIR/report/ (or out_dir), each file replaced atomically:

    axes.md, axes.csv        level 3 (if the suite has plain pairs): the headline table
    intervals.md, .csv       IQM and drop with 95 % intervals per axis and over all pairs (if plain pairs)
    pairs.md, pairs.csv      level 2, plain pairs (if any)
    sweeps.md, sweeps.csv    level 2, per sweep and eval config (if the suite has sweeps)
    runs.csv                 level 1, one row per run, eval config and metric
    report.md                all the Markdown tables, the axes first
    report.json              everything above, the runs found and the protocol
    plots/*.png              see kage.bench.plots

With `protocol` "final" the default directory is DIR/report_final/; with an interval `metric` other than
success_once, its name is appended (DIR/report_progress/), so that no report of another metric is replaced.
"""
import json
import math
import os
import re
import statistics
import sys
from dataclasses import dataclass, field
from typing import Dict, List, NoReturn, Optional, Sequence, Set, Tuple

from kage.bench import intervals, plots
from kage.bench.records import bench_problem, suite_problem
from kage.bench.units import Unit, units_of
from kage.bench.tables import PROTOCOL_TEXTS, write_tables
from kage.fields import DIFF_METRICS, INTERVAL_METRICS, REPORT_METRICS, SUCCESS_SHOWN
from kage.util.files import LOG_LIMIT, RECORD_LIMIT, atomic_write, open_regular, output_folder, read_regular, safe

PROTOCOLS = ("max", "final")
LEVEL_1 = {"max": "per run, each value's maximum over its evaluation points (summary.json max), every side maximised "
                  "independently",
           "final": "per run, each value at its last evaluation point (the final checkpoint)"}


def fail(message: str) -> NoReturn:
    raise SystemExit(f"kage.bench report: {message}")


# ---- reading the benchmark directory ----

@dataclass
class Run:
    seed: int
    path: str
    stats: Optional[dict]  # summary.json's stats; None while the run is unfinished
    evaluations: List[dict]  # the evaluation rows of metrics.jsonl
    args: dict = field(default_factory=dict)  # run.json's: the trainer's arguments
    last_step: Optional[int] = None  # summary.json's last evaluation's global step, where it records one


def read_json(path: str, remedy: str):
    """A JSON record of at most RECORD_LIMIT bytes in a regular file, or one line naming `path` and `remedy`."""
    try:
        return json.loads(read_regular(path, RECORD_LIMIT))
    except FileNotFoundError:
        fail(f"{path} not found: {remedy}")
    except OSError as e:  # NotRegularFile too: a FIFO, a device (a symlink to /dev/zero), too large
        fail(f"{path}: {e.strerror or e}: {remedy}")
    except (ValueError, RecursionError) as e:
        fail(f"{path} is not readable JSON ({e}): {remedy}")


def load_suite(bench_dir: str) -> dict:
    if not os.path.isdir(bench_dir):
        fail(f"{bench_dir} is not a directory: give the --out directory of `python3 -m kage.bench run`")
    path = os.path.join(bench_dir, "suite.json")
    if not os.path.exists(path):
        fail(f"{path} not found: is {bench_dir} a directory written by `python3 -m kage.bench run`?")
    rerun = "delete it and rerun `python3 -m kage.bench run` with the same suite and --out to write it again " \
            "(finished runs are kept)"
    suite = read_json(path, rerun)
    pair_keys = ("pair", "declared_axis", "sweep", "sweep_eval", "train", "eval")
    if not (isinstance(suite, dict) and suite.get("kagec_suite_report") == 1 and isinstance(suite.get("pairs"), list)
            and all(isinstance(p, dict) and all(k in p for k in pair_keys) and isinstance(p["train"], dict)
                    for p in suite["pairs"])):
        fail(f"{path} is not a suite report of kagec (\"kagec_suite_report\": 1 with pairs {', '.join(pair_keys)}): "
             f"{rerun}")
    problem = suite_problem(suite)
    if problem:
        fail(f"{path} is damaged: {problem}: {rerun}")
    return suite


def read_bench(bench_dir: str) -> dict:
    """bench.json: {} where it is absent, unless runs were shared between pairs (--share-training), whose pairs
    only its "shared" names."""
    path = os.path.join(bench_dir, "bench.json")
    shared_runs = os.path.isdir(os.path.join(bench_dir, "runs", "shared"))
    remedy = ("restore it: its 'shared' names the pairs of the runs in runs/shared/ (--share-training)" if shared_runs
              else "fix or delete it (the report reads only its seeds, units and trainer flags)")
    if not os.path.exists(path):
        if shared_runs:
            fail(f"{path} not found: {remedy}")
        return {}
    bench = read_json(path, remedy)
    problem = bench_problem(bench, [k for k in ("units", "seeds", "trainer_args")
                                    if isinstance(bench, dict) and k in bench])
    if not problem and shared_runs and "shared" not in bench:
        problem = "no 'shared'"
    if problem:
        fail(f"{path} is damaged ({problem}): {remedy}")
    return bench


def find_runs(bench_dir: str, unit: Unit) -> List[Run]:
    """The unit's run directories (runs/<unit>/seed_<s>/), by seed."""
    unit_dir = os.path.join(bench_dir, "runs", unit.name)
    if not os.path.isdir(unit_dir):
        return []
    runs: Dict[int, Run] = {}
    for entry in sorted(os.listdir(unit_dir)):
        match = re.fullmatch(r"seed_(\d+)", entry)
        path = os.path.join(unit_dir, entry)
        if match and os.path.isdir(path):
            seed = int(match[1])
            if seed in runs:  # seed_1 and seed_01: one seed's results twice would count twice
                fail(f"{runs[seed].path} and {path} are both seed {seed} of {unit.name}: remove the one that "
                     f"kage.bench run did not write (it names its runs seed_{seed})")
            runs[seed] = read_run(seed, path)
    return [runs[seed] for seed in sorted(runs)]


def read_run(seed: int, path: str) -> Run:
    summary = os.path.join(path, "summary.json")
    metrics = os.path.join(path, "metrics.jsonl")
    run_json = os.path.join(path, "run.json")
    stats, last_step = read_summary(summary) if os.path.exists(summary) else (None, None)
    evaluations = read_evaluations(metrics) if os.path.exists(metrics) else []
    remedy = "delete the run directory and rerun `python3 -m kage.bench run` to train it again"
    record = read_json(run_json, remedy) if os.path.exists(run_json) else {"args": {}}
    args = record.get("args") if isinstance(record, dict) else None
    if not isinstance(args, dict):
        fail(f"{run_json} is not a kage.ppo.train run record ({{\"args\": {{...}}}}): {remedy}")
    return Run(seed, path, stats, evaluations, args, last_step)


def is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


# Values that are shares of episodes, on either side: a summary outside [0, 1] is not a run's.
SHARES = ("success", "success_once")


def read_summary(path: str) -> Tuple[dict, Optional[int]]:
    """summary.json's stats ({key: {"max": ..., ...} or null}) and its last evaluation's global step (None where
    it records none)."""
    remedy = "delete it and rerun `python3 -m kage.bench run` on the directory to write it again from the run's " \
             "last checkpoint"
    summary = read_json(path, remedy)
    stats = summary.get("stats") if isinstance(summary, dict) else None
    if not (isinstance(summary, dict) and summary.get("kage_summary") == 1 and isinstance(stats, dict)
            and all(v is None or (isinstance(v, dict) and is_number(v.get("max"))) for v in stats.values())):
        fail(f"{path} is not a kage.ppo.train summary ({{\"kage_summary\": 1, \"stats\": {{key: {{\"max\": number, ...}} "
             f"or null}}}}): {remedy}")
    for key, value in stats.items():
        side, _, metric = key.rpartition("/")
        if value is not None and metric in SHARES and not side.startswith("diff") and not 0 <= value["max"] <= 1:
            fail(f"{path}: {key} has max {value['max']}, outside [0, 1] (a share of episodes): {remedy}")
    steps = summary.get("global_steps")
    last = steps[-1] if isinstance(steps, list) and steps and is_number(steps[-1]) else None
    return stats, last


MAX_LINE = 64 << 20  # bytes of one log row: a real one is a few KB


def _value_problem(side) -> Optional[str]:
    """Why an evaluation row's side ({metric: value}) is not one: not an object, or a value that is neither a
    number nor null (a string, a list, a boolean)."""
    if not isinstance(side, dict):
        return f"is {json.dumps(side)[:40]}, not an object of values"
    for metric, value in side.items():
        if value is not None and not (isinstance(value, (int, float)) and not isinstance(value, bool)):
            return f"has {metric} = {json.dumps(value)[:40]}, not a number or null"
    return None


def eval_row_problem(row: dict) -> Optional[str]:
    """What an evaluation row lacks of what kage.ppo.train writes: a global_step, the train side and each eval
    side (and the differences) as objects of numbers or nulls; None where it has them."""
    if not (is_number(row.get("global_step")) and isinstance(row.get("train"), dict)
            and isinstance(row.get("evals"), dict)):
        return "an evaluation row without global_step, train and evals"
    parts = [("train", row["train"])] + [(f"evals[{json.dumps(k)}]", v) for k, v in row["evals"].items()]
    diffs = row.get("diffs", {})
    if not isinstance(diffs, dict):
        return f"an evaluation row whose diffs are {json.dumps(diffs)[:40]}, not an object"
    parts += [(f"diffs[{json.dumps(k)}]", v) for k, v in diffs.items()]
    for where, side in parts:
        problem = _value_problem(side)
        if problem:
            return f"an evaluation row whose {where} {problem}"
    return None


def read_evaluations(path: str) -> List[dict]:
    """The evaluation rows of a metrics.jsonl, in the order of their steps. A last line that does not parse is a
    row the run was killed while writing, and is skipped; a damaged line before it is an error, and so is an
    evaluation row that is not after the one before it (a duplicated or out-of-order row: the trainer writes each
    once, in order, and drops on resume what it writes again), which the final protocol would misread. The file
    must be a regular file of at most LOG_LIMIT bytes."""
    redo = "delete the run directory and rerun `python3 -m kage.bench run` to train the run again"
    rows: List[dict] = []
    torn: Optional[int] = None  # a line that did not parse: an error unless it is the last
    previous = (0, None)  # the line and step of the last evaluation row
    try:
        with open_regular(path, LOG_LIMIT) as f:
            number = 0
            while True:
                data = f.readline(MAX_LINE + 1)
                if not data:
                    break
                number += 1
                if torn is not None:
                    break
                line = data.decode("utf-8", errors="replace")
                if len(data) > MAX_LINE:
                    fail(f"{path}, line {number}: over {MAX_LINE:,} bytes, not a log row: the log is damaged: {redo}")
                if not line.strip():
                    continue
                try:
                    row = json.loads(line)
                except (ValueError, RecursionError):
                    torn = number
                    continue
                if not isinstance(row, dict) or "kind" not in row:
                    fail(f"{path}, line {number}: not a kage.ppo.train log row (no \"kind\"): delete that line, or "
                         f"{redo}")
                if row["kind"] != "eval":
                    continue
                problem = eval_row_problem(row)
                if problem:
                    fail(f"{path}, line {number}: {problem}: delete that line, or {redo}")
                if previous[1] is not None and not row["global_step"] > previous[1]:
                    fail(f"{path}, line {number}: an evaluation row at step {row['global_step']}, not after the one "
                         f"of line {previous[0]} (step {previous[1]}): the log has duplicated or out-of-order rows, "
                         f"which kage.ppo.train never writes (an edit, or two trainers in one run directory): delete "
                         f"the rows out of order, or {redo}")
                previous = (number, row["global_step"])
                rows.append(row)
    except OSError as e:  # NotRegularFile too: a FIFO or a device (a symlink to /dev/zero), too large
        fail(f"cannot read {path} ({e.strerror or e}): replace it by the run's log, or {redo}")
    if torn is not None and torn != number:
        fail(f"{path}, line {torn}: not a JSON row, the log is damaged: delete that line, or {redo}")
    return rows


# ---- the three levels (§5.1-5.3) ----

def mean_sem(values: Sequence[Optional[float]]) -> dict:
    """{"mean", "sem", "n"} of the values that exist: SEM = sample standard deviation / sqrt(n), 0 for n = 1."""
    present = [v for v in values if v is not None]
    n = len(present)
    if n == 0:
        return {"mean": None, "sem": None, "n": 0}
    sem = statistics.stdev(present) / math.sqrt(n) if n > 1 else 0.0
    return {"mean": statistics.fmean(present), "sem": sem, "n": n}


def gap_and_drop(train: Optional[float], evaluated: Optional[float]) -> Tuple[Optional[float], Optional[float]]:
    """train - eval, and the drop 100 * (train - eval) / train in percent (None where train is 0)."""
    if train is None or evaluated is None:
        return None, None
    gap = train - evaluated
    return gap, (100.0 * gap / train if train != 0 else None)


def flat_row(row: dict) -> Dict[str, Optional[float]]:
    """An evaluation row under summary.json's keys, train/<m>, eval/<label>/<m> and diff/<label>/<m>, as
    kage.ppo.rundir.summarize flattens it (that module needs torch, the report does not)."""
    flat = {f"train/{m}": v for m, v in row["train"].items()}
    for label, side in row["evals"].items():
        flat.update({f"eval/{label}/{m}": v for m, v in side.items()})
    for label, diff in row.get("diffs", {}).items():
        flat.update({f"diff/{label}/{m}": v for m, v in diff.items()})
    return {k: (float(v) if is_number(v) else None) for k, v in flat.items()}


def run_values(run: Run, protocol: str, partial: bool = False,
               max_step: Optional[float] = None) -> Optional[Dict[str, Optional[float]]]:
    """A run's value per summary key under `protocol`: "max", summary.json's maxima (over the rows logged so far
    for an unfinished run); "final", its last evaluation row. None for a run that is not in the tables: an
    unfinished one, unless `partial` and it has an evaluation row. With `max_step` (kage.bench compare), only the
    evaluation rows at or before that step count: their maxima, or the last of them."""
    if run.stats is None and not (partial and run.evaluations):
        return None
    rows = [r for r in run.evaluations if max_step is None or r["global_step"] <= max_step]
    if protocol == "max" and run.stats is not None and max_step is None:
        return {k: (None if v is None else float(v["max"])) for k, v in run.stats.items()}
    if protocol == "max":
        series: Dict[str, List[float]] = {}
        for row in rows:
            for key, value in flat_row(row).items():
                series.setdefault(key, [])
                if value is not None:
                    series[key].append(value)
        return {key: (max(values) if values else None) for key, values in series.items()}
    if not rows:
        fail(f"{os.path.join(run.path, 'metrics.jsonl')} has no evaluation row, which --protocol final reads: use "
             "--protocol max, or delete the run directory and rerun `python3 -m kage.bench run`")
    if max_step is None and run.last_step is not None and rows[-1]["global_step"] < run.last_step:
        fail(f"{os.path.join(run.path, 'metrics.jsonl')} ends at the evaluation of step {rows[-1]['global_step']}, "
             f"before the last that summary.json counts (step {run.last_step}): the log lost its last rows, which "
             "--protocol final reads: restore it, or use --protocol max (summary.json alone)")
    return flat_row(rows[-1])


def value_of(values: dict, key: str, where: str) -> Optional[float]:
    if key not in values:
        fail(f"{where} has no '{key}': the run was not evaluated on this suite's configs (evaluation off, or other "
             "eval labels); delete the run directory and rerun `python3 -m kage.bench run`")
    return values[key]


def run_scores(values: dict, label: str, where: str = "summary.json") -> Dict[str, dict]:
    """Level 1: per metric, the run's value (run_values) of the train side, of the eval side `label` and of
    their absolute difference, each on its own; and the gap and drop of the two."""
    scores = {}
    for m in REPORT_METRICS:
        train = value_of(values, f"train/{m}", where)
        evaluated = value_of(values, f"eval/{label}/{m}", where)
        if (train is None) != (evaluated is None):  # the pair's means would be over different seeds
            empty = f"train/{m}" if train is None else f"eval/{label}/{m}"
            fail(f"{where}: {empty} has no value where the other side has one, so the pair's gap would compare "
                 "different runs: the file is damaged; restore it, or delete the run directory and rerun "
                 "`python3 -m kage.bench run`")
        gap, drop = gap_and_drop(train, evaluated)
        diff = value_of(values, f"diff/{label}/{m}", where) if m in DIFF_METRICS else None
        scores[m] = {"train": train, "eval": evaluated, "gap": gap, "drop_pct": drop, "max_abs_diff": diff}
    return scores


def combine(samples: List[Dict[str, dict]]) -> Dict[str, dict]:
    """Per metric, the mean and SEM of each side over `samples` ({metric: {"train", "eval", "max_abs_diff"}}
    numbers), and the gap and drop of the two means."""
    combined = {}
    for m in REPORT_METRICS:
        train = mean_sem([s[m]["train"] for s in samples])
        evaluated = mean_sem([s[m]["eval"] for s in samples])
        gap, drop = gap_and_drop(train["mean"], evaluated["mean"])
        diff = mean_sem([s[m]["max_abs_diff"] for s in samples]) if m in DIFF_METRICS else None
        combined[m] = {"train": train, "eval": evaluated, "gap": gap, "drop_pct": drop, "max_abs_diff": diff}
    return combined


def over_seeds(run_values: List[Dict[str, dict]]) -> Dict[str, dict]:
    """Level 2: a pair's runs' values (run_scores), over seeds."""
    return combine(run_values)


def over_pairs(pair_values: List[Dict[str, dict]]) -> Dict[str, dict]:
    """Level 3: the per-pair means of an axis's pairs (over_seeds), each pair weighted equally."""
    means = [{m: {side: (v[m][side]["mean"] if v[m][side] else None) for side in ("train", "eval", "max_abs_diff")}
              for m in REPORT_METRICS} for v in pair_values]
    return combine(means)


def sweep_order(names: List[str]) -> List[str]:
    """A sweep's eval names by value where all are numbers, else in manifest order."""
    try:
        return sorted(names, key=float)
    except ValueError:
        return list(names)


def aggregate(units: List[Unit], runs: Dict[str, List[Run]], protocol: str = "max", partial: bool = False,
              keep: Optional[Set[Tuple[str, int]]] = None, max_step: Optional[float] = None) -> dict:
    """The three levels: {"runs": level 1, "pairs": level 2 (plain pairs), "axes": level 3, "sweeps": level 2
    per sweep}; `protocol` and `partial` choose the runs and their values (run_values), and `keep`, where
    given, the (pair, seed) results that enter (kage.bench compare: those of every method), scored on their rows
    up to `max_step` where given (run_values)."""
    level1, pairs, sweeps = [], [], []
    for unit in units:
        scored = [(r, v) for r in runs[unit.name] for v in [run_values(r, protocol, partial, max_step)]
                  if v is not None]
        if keep is not None:
            scored = [(r, v) for r, v in scored if any((p["pair"], r.seed) in keep for p in unit.pairs)]
        included = [r for r, _ in scored]
        results = {}
        for pair in unit.pairs:
            label = unit.label(pair)
            per_run = []
            kept = [(r, v) for r, v in scored if keep is None or (pair["pair"], r.seed) in keep]
            for run, run_value in kept:
                from_summary = protocol == "max" and run.stats is not None and max_step is None
                where = os.path.join(run.path, "summary.json" if from_summary else "metrics.jsonl")
                values = run_scores(run_value, label, where)
                level1.append({"pair": pair["pair"], "unit": unit.name, "seed": run.seed, "label": label,
                               "path": run.path, **progress(run), "metrics": values})
                per_run.append(values)
            results[pair["pair"]] = {
                "pair": pair["pair"], "axis": pair["declared_axis"], "certified": pair.get("certified"),
                "train_spec": pair["train"].get("spec_sha256", pair["train"].get("name")),
                "trains_on": unit.train if "stages" in unit.training else None,
                "n_seeds": len(kept), "seeds": [r.seed for r, _ in kept], "metrics": over_seeds(per_run)}
        if not unit.is_sweep:
            pairs.extend(results[p["pair"]] for p in unit.pairs)
            continue
        by_name = {p["sweep_eval"]: results[p["pair"]] for p in unit.pairs}
        evals = [dict(by_name[name], sweep_eval=name) for name in sweep_order(list(by_name))]
        sweeps.append({"sweep": unit.name, "axis": unit.pairs[0]["declared_axis"],
                       "train_config": unit.pairs[0]["train"].get("name"), "n_seeds": len(included),
                       "seeds": [r.seed for r in included], "evals": evals})
    return {"runs": level1, "pairs": pairs, "axes": axes_of(pairs), "sweeps": sweeps}


def axes_of(pairs: List[dict]) -> List[dict]:
    """Level 3 per axis, axes in the order of their first pair."""
    names: List[str] = []
    for p in pairs:
        if p["axis"] not in names:
            names.append(p["axis"])
    axes = []
    for name in names:
        members = [p for p in pairs if p["axis"] == name]
        axes.append({"axis": name, "n_pairs": sum(1 for p in members if p["n_seeds"] > 0),
                     "pairs": [p["pair"] for p in members], "metrics": over_pairs([p["metrics"] for p in members])})
    return axes


def progress(run: Run) -> dict:
    """How far a run got: finished or not, its evaluation points, the latest one's step, and its total steps."""
    total = run.args.get("total_timesteps")
    return {"finished": run.stats is not None, "evaluations": len(run.evaluations),
            "step": run.evaluations[-1]["global_step"] if run.evaluations else None,
            "total_steps": total if is_number(total) else None}


def run_status(units: List[Unit], runs: Dict[str, List[Run]], seeds: List[int], partial: bool = False) -> dict:
    """Finished runs, unfinished ones (in the tables with `partial` where they have an evaluation point) and
    seeds of bench.json without a run directory."""
    finished, unfinished, not_started = 0, [], []
    for unit in units:
        found = {r.seed for r in runs[unit.name]}
        for run in runs[unit.name]:
            if run.stats is not None:
                finished += 1
            else:
                unfinished.append({"unit": unit.name, "seed": run.seed, "path": run.path, **progress(run),
                                   "in_tables": partial and bool(run.evaluations)})
        not_started += [{"unit": unit.name, "seed": s} for s in seeds if s not in found]
    return {"finished": finished, "unfinished": unfinished, "not_started": not_started, "partial": partial}


def interim_line(status: dict) -> Optional[str]:
    """An interim report's one-line mark for its plots; None for a report of finished runs only."""
    included = [r for r in status["unfinished"] if r["in_tables"]]
    if not status["partial"]:
        return None
    if not included:
        return "INTERIM (--partial): no unfinished run has an evaluation yet"
    steps = [r["step"] for r in included]
    totals = {r["total_steps"] for r in included}
    of = f" of {totals.pop() / 1e6:.3g} M" if len(totals) == 1 and None not in totals else ""
    reached = f"{min(steps) / 1e6:.3g}" + (f"-{max(steps) / 1e6:.3g}" if max(steps) > min(steps) else "")
    return (f"INTERIM (--partial): {len(included)} unfinished runs included at their latest evaluation, "
            f"{reached} M steps{of}")


# ---- plots ----

def curve(evaluations: List[List[dict]], label: Optional[str], metric: str) -> List[Tuple[float, dict]]:
    """Per evaluation step, the mean and SEM over the runs evaluated at that step of `metric` on the train
    config (label None) or on eval config `label`; `evaluations` holds each run's evaluation rows."""
    by_step: Dict[float, List[Optional[float]]] = {}
    for rows in evaluations:
        for row in rows:
            side = row["train"] if label is None else row["evals"].get(label)
            value = side.get(metric) if isinstance(side, dict) else None
            by_step.setdefault(row["global_step"], []).append(value if is_number(value) else None)
    return [(step, mean_sem(values)) for step, values in sorted(by_step.items())]


def write_plots(out_dir: str, units: List[Unit], runs: Dict[str, List[Run]], levels: dict,
                estimates: Optional[dict], interim: Optional[str] = None) -> List[str]:
    """The PNG files under plots/ (see kage.bench.plots), each marked with `interim` where given; returns their
    names relative to out_dir."""
    figures: Dict[str, bytes] = {}
    for unit in units:
        evaluations = [r.evaluations for r in runs[unit.name] if r.evaluations]
        if unit.is_sweep or not evaluations:
            continue
        unfinished = sum(1 for r in runs[unit.name] if r.evaluations and r.stats is None)
        for pair in unit.pairs:
            title = pair["pair"] + (f" ({len(evaluations)} runs, {unfinished} unfinished)" if unfinished else "")
            for metric, suffix, ylabel, ylim in ((SUCCESS_SHOWN, "", "success rate (success_once)", (0, 1.1)),
                                                 ("return", "_return", "return", None)):
                figures[f"plots/curves_{safe(pair['pair'])}{suffix}.png"] = plots.training_curves(
                    title, curve(evaluations, None, metric), curve(evaluations, unit.label(pair), metric), ylabel,
                    ylim, interim)
    if levels["axes"]:
        drops = [a["metrics"][SUCCESS_SHOWN]["drop_pct"] for a in levels["axes"]]
        figures["plots/drop_per_axis.png"] = plots.drop_per_axis([a["axis"] for a in levels["axes"]], drops, interim)
    if estimates and estimates["profile"]:
        metric, profile = estimates["metric"], estimates["profile"]
        figures["plots/intervals.png"] = plots.interval_estimates({"": estimates["rows"]}, metric, interim)
        figures[f"plots/profile_{metric}.png"] = plots.performance_profiles(
            profile["taus"], {"eval": profile["eval"], "train": profile["train"]}, {"train"}, metric, interim)
    for s in levels["sweeps"]:
        figures[f"plots/sweep_{safe(s['sweep'])}.png"] = plots.sweep_response(
            f"{s['sweep']} ({s['axis']})", [e["sweep_eval"] for e in s["evals"]],
            [e["metrics"][SUCCESS_SHOWN]["eval"] for e in s["evals"]], s["evals"][0]["metrics"][SUCCESS_SHOWN]["train"],
            interim)
    for name, png in figures.items():
        atomic_write(os.path.join(out_dir, name), png)
    return sorted(figures)


# ---- the command ----

def read_benchmark(bench_dir: str) -> Tuple[dict, dict, List[Unit], Dict[str, List[Run]]]:
    """suite.json, bench.json, the units that were run (bench.json's "units": what `run --pairs` chose, when it
    chose) and their runs by unit name."""
    suite = load_suite(bench_dir)
    bench = read_bench(bench_dir)
    selected = bench.get("units")
    units = [u for u in units_of(suite, bench.get("shared")) if selected is None or u.name in selected]
    return suite, bench, units, {unit.name: find_runs(bench_dir, unit) for unit in units}


def default_out_dir(bench_dir: str, protocol: str, partial: bool, metric: str) -> str:
    """DIR/report[_final][_METRIC][_interim]: one folder per protocol, interval metric and interim-ness, so that
    a report never replaces one of another kind."""
    return os.path.join(bench_dir, "report" + ("_final" if protocol == "final" else "")
                        + ("" if metric == SUCCESS_SHOWN else "_" + metric) + ("_interim" if partial else ""))


def report(bench_dir: str, out_dir: Optional[str] = None, protocol: str = "max",
           reps: int = intervals.REPS, partial: bool = False, metric: str = SUCCESS_SHOWN) -> dict:
    """Reads the benchmark directory `bench_dir`, writes the tables, plots and report.json into `out_dir`
    (default_out_dir: bench_dir/report, report_final under `protocol` "final", the metric's name appended
    when it is not success_once, "_interim" under `partial`)
    and returns report.json's content. `reps`: bootstrap resamples of the interval estimates of `metric`."""
    if protocol not in PROTOCOLS:
        fail(f"unknown protocol '{protocol}': choose {' or '.join(PROTOCOLS)}")
    if metric not in INTERVAL_METRICS:
        fail(f"the interval estimates take {', '.join(INTERVAL_METRICS)}, not '{metric}'")
    if intervals.reps_problem(reps):
        fail(intervals.reps_problem(reps))
    suite, bench, units, runs = read_benchmark(bench_dir)
    out_dir = out_dir or default_out_dir(bench_dir, protocol, partial, metric)
    levels = aggregate(units, runs, protocol, partial)
    status = run_status(units, runs, [s for s in bench.get("seeds", []) if isinstance(s, int)], partial)
    result = {
        "kage_bench_report": 1, "suite": suite.get("suite", "suite"), "manifest": suite.get("manifest"),
        "bench_dir": bench_dir, "out_dir": out_dir, "seeds": bench.get("seeds"),
        "protocol": {
            "score": protocol,
            "level_1_runs": LEVEL_1[protocol],
            "level_2_pairs": "per pair, mean and SEM over seeds (SEM = sample sd / sqrt(n), 0 for n = 1)",
            "level_3_axes": "per axis, mean and SEM of the plain pairs' means, each pair weighted equally",
            "gap": "train_mean - eval_mean, on the means of the level",
            "drop_pct": "100 * (train_mean - eval_mean) / train_mean, on the means of the level; null where "
                        "train_mean is 0",
            "max_abs_diff": "per run the largest |train - eval| at one evaluation point, aggregated like a value"
                            if protocol == "max" else "per run |train - eval| at its last evaluation point",
        },
        "metrics": list(REPORT_METRICS), "markdown_success_column": SUCCESS_SHOWN,
        "runs_found": status, "interim": interim_line(status), "levels": levels,
        "intervals": intervals.interval_report(levels["runs"], levels["pairs"], reps, metric) if levels["pairs"]
        else None,
    }
    try:
        write_report(out_dir, result, units, runs)
    except OSError as e:
        fail(f"cannot write into {out_dir} ({e}): give a writable directory with --out")
    return result


def write_report(out_dir: str, result: dict, units: List[Unit], runs: Dict[str, List[Run]]) -> None:
    """The tables, the plots, then report.json (`result`, completed with the files written)."""
    output_folder(out_dir, "plots")
    files = write_tables(out_dir, result["suite"], result["levels"], result["runs_found"],
                         PROTOCOL_TEXTS[result["protocol"]["score"]], result["intervals"], result["protocol"]["score"])
    result["plots_note"] = None
    try:
        files += write_plots(out_dir, units, runs, result["levels"], result["intervals"], result["interim"])
    except ImportError as e:  # the tables do not need matplotlib
        result["plots_note"] = f"no plots: {e}; install matplotlib (pip install matplotlib) and rerun the report"
        print(f"kage.bench report: {result['plots_note']}", file=sys.stderr)
    result["files"] = files + ["report.json"]
    atomic_write(os.path.join(out_dir, "report.json"), (json.dumps(result, indent=1, allow_nan=False) + "\n").encode())
