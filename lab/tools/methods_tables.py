"""Writes the tables of results/methods/README.md from the published packs: each method's packs
(results/methods/METHOD/packs, the layout of results/kage-bench-table/packs) and the baseline's are unpacked with
their checksums (table_unpack), each method is compared with the baseline on seeds 1-5 by `kage.bench compare`
(on the (pair, seed) results both have), and two tables are made from its compare.json:

- per axis: each method's IQM of eval success_once, its drop and P(method > baseline), each with its 95 % interval,
  under the baseline's row;
- per pair of methods and axis: P(one method > the other), with its 95 % interval, from their own compare;
- per method: the pairs and results it covers, its training runs' mean best train success, how many never passed
  0.1 and how many ended collapsed (kage.bench.training_runs);
- per method: its GPU time from its runs' metrics (pack_gpu_time), the baseline's over all its seeds.

The baseline's row is of all its pairs: from the first method compared on all of them, else from the baseline
compared with itself. A method compared on fewer results also gets the baseline's row on those results where it
differs. The intervals come from compare's own bootstrap at REPS resamples and its fixed seed
(kage.bench.intervals.SEED), so the tables are the same on every run. Only the lines between the README's markers
(generated_block) are written; the prose around them is left as it is.

usage: python3 lab/tools/methods_tables.py [METHOD ...] [--methods-root DIR] [--baseline-packs DIR] [--work DIR]
                                           [--check]"""
import argparse
import difflib
import os
import sys
import tempfile
from typing import Dict, List, Optional, Tuple

import generated_block  # beside this file, as table_unpack
from pack_gpu_time import devices, gpu_time
from table_unpack import unpack_all

from kage.bench import intervals
from kage.bench.compare import compare
from kage.bench.interval_tables import explanation, fmt_drop, fmt_interval
from kage.bench.training_runs import NEVER_LEARNED
from kage.util.files import atomic_write
from kage.util.tables import md_table

TOOL = "lab/tools/methods_tables.py"
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
METHODS_ROOT = os.path.join(ROOT, "results/methods")
BASELINE_PACKS = os.path.join(ROOT, "results/kage-bench-table/packs")
BASELINE = "baseline"
SEEDS = [1, 2, 3, 4, 5]  # the methods' seeds (kage.bench run --seeds 1-5); the baseline has 1-10
REPS = intervals.REPS  # compare's default: the CI test regenerates the tables at it in well under two minutes


def fail(message: str):
    sys.exit(f"methods_tables: {message}")


def published(methods_root: str) -> List[str]:
    """The methods of `methods_root` that have packs (METHOD/packs/task_I.tar.gz), by name."""
    if not os.path.isdir(methods_root):
        return []
    return sorted(name for name in os.listdir(methods_root)
                  if os.path.isdir(os.path.join(methods_root, name, "packs"))
                  and any(f.endswith(".tar.gz") for f in os.listdir(os.path.join(methods_root, name, "packs"))))


def compared(dirs: List[str], names: List[str], out: str, cache: dict) -> dict:
    """compare.json of `kage.bench compare DIRS --names NAMES --seeds 1-5 --reps REPS --out OUT`, each directory
    read once for all the compares that share `cache`."""
    try:
        return compare(dirs, names, out, reps=REPS, seeds=SEEDS, cache=cache)
    except SystemExit as e:  # compare's refusal, naming the methods it was comparing
        fail(f"{names[0]} against {names[1]}: {e}")


def entry(result: dict, name: str) -> dict:
    return next(m for m in result["methods"] if m["name"] == name)


def covers_all(result: dict) -> bool:
    """Whether the compare scored every baseline result of seeds 1-5."""
    baseline = entry(result, BASELINE)
    return not baseline["pairs_left_out"] and not baseline["left_out"]


def rows_by_name(method_entry: dict) -> Dict[str, dict]:
    return {row["name"]: row for row in method_entry["estimates"]["rows"]}


def estimate_cells(row: Optional[dict]) -> list:
    if row is None:
        return [0, 0, "-", "-"]
    return [row["n_pairs"], row["n_runs"], fmt_interval(row["eval_iqm"]), fmt_drop(row["drop_pct"])]


def axis_table(full: dict, results: Dict[str, dict]) -> str:
    """One row per axis (and over all pairs) for the baseline, then for each method, preceded by the baseline's row
    on the method's results where those differ from all of the baseline's."""
    baseline_rows = rows_by_name(entry(full, BASELINE))
    table = []
    for axis, base in baseline_rows.items():
        table.append([axis, BASELINE, *estimate_cells(base), "-"])
        for method, result in results.items():
            own = rows_by_name(entry(result, BASELINE)).get(axis)
            if own is not None and own != base:
                table.append([axis, f"{BASELINE}, on {method}'s results", *estimate_cells(own), "-"])
            p = next((r["p"] for r in result["improvement"]
                      if (r["name"], r["x"], r["y"]) == (axis, method, BASELINE)), None)
            table.append([axis, method, *estimate_cells(rows_by_name(entry(result, method)).get(axis)),
                          fmt_interval(p)])
    return md_table(["axis", "method", "pairs", "results", "eval IQM [95 % CI]", "drop [95 % CI]",
                     f"P(method > {BASELINE}) [95 % CI]"], table, 2)


def head_to_head_table(matches: Dict[Tuple[str, str], dict]) -> str:
    """Per pair of methods (A, B) and axis: the pairs both have and P(A > B) with its interval."""
    rows = [[r["name"], a, b, r["n_pairs"], fmt_interval(r["p"])]
            for (a, b), result in matches.items() for r in result["improvement"] if (r["x"], r["y"]) == (a, b)]
    return md_table(["axis", "A", "B", "pairs", "P(A > B) [95 % CI]"], rows, 3)


def training_table(full: dict, results: Dict[str, dict]) -> str:
    """Per method (the baseline first), the pairs and results it covers (its row over all pairs) and its training
    runs' outcomes."""
    whole = rows_by_name(entry(full, BASELINE))[intervals.ALL_PAIRS]
    rows = []
    for name, result in [(BASELINE, full)] + list(results.items()):
        covered = rows_by_name(entry(result, name))[intervals.ALL_PAIRS]
        runs = entry(result, name)["training_runs"]
        mean = "-" if runs["mean_best"] is None else f"{runs['mean_best']:.2f}"
        rows.append([name, f"{covered['n_pairs']} of {whole['n_pairs']}", f"{covered['n_runs']} of {whole['n_runs']}",
                     runs["runs"], mean, runs["never_learned"], runs["collapsed"]])
    return md_table(["method", "pairs", "results", "training runs", "mean of max train success",
                     f"never above {NEVER_LEARNED}", "ended collapsed"], rows, 1)


def cost_table(costs: Dict[str, tuple]) -> str:
    """Per method (the baseline first): its packs, training and evaluation GPU-hours, the packs' wall time, and
    devices."""
    rows = [[name, time["packs"], f"{time['train_hours']:.2f}", f"{time['eval_hours']:.2f}",
             f"{time['train_hours'] + time['eval_hours']:.2f}", f"{time['wall_hours']:.2f}", "; ".join(named)]
            for name, (time, named) in costs.items()]
    return md_table(["method", "packs", "training GPU-hours", "evaluation GPU-hours", "together",
                     "packs' wall GPU-hours", "devices"], rows, 1)


def tables(full: dict, results: Dict[str, dict], matches: Dict[Tuple[str, str], dict],
           costs: Dict[str, tuple]) -> str:
    """The generated part of the README."""
    estimates = entry(full, BASELINE)["estimates"]
    return (f"\n### Eval success per axis (seeds {SEEDS[0]}-{SEEDS[-1]})\n\n{axis_table(full, results)}\n"
            "pairs, results: the train/eval pairs and the (pair, seed) results of the row, those that the method "
            f"and the baseline both have. P(method > {BASELINE}): per pair, the probability that a run of the "
            "method has a higher eval success than a run of the baseline (ties count half), averaged over the "
            "pairs; 0.5 is no difference. Each run's value is its maximum over training. "
            f"{explanation(estimates)}\n\n"
            + (f"### Methods head to head (seeds {SEEDS[0]}-{SEEDS[-1]})\n\n{head_to_head_table(matches)}\n"
               "P(A > B): as P(method > baseline) above, between two methods, on the pairs and seeds both have "
               "(`kage.bench compare A_DIR B_DIR --names A B`).\n\n" if matches else "") +
            f"### Training runs (seeds {SEEDS[0]}-{SEEDS[-1]})\n\n{training_table(full, results)}\n"
            "Per training run (a run directory, however many pairs it is scored for): its maximum train success "
            "over the evaluation points, whether it stayed below 0.1, and whether it ended collapsed to the "
            "never-jump policy (no jump on its train config at the last evaluation point). 45 runs: shape_black's "
            "and image_skeleton's pairs in two parts of at most 10 eval configs, each part a run of its own of the "
            "same config and seed; 35: one run a training and seed (the runner since 00c502b).\n\n"
            f"### GPU time (from the runs' metrics and files)\n\n{cost_table(costs)}\n"
            "Per pack (the runs one trainer process trained side by side on one GPU): the training seconds of its "
            "first run (its steps over its `charts/SPS`) and its evaluation points' seconds, summed over the "
            f"method's packs; the {BASELINE}'s over all its packs (seeds 1-10). Packs trained before 2086d34 (their "
            "checksum lists' `# commit:`) count each iteration's host time only, not the device's unfinished work, "
            "the logging or the checkpoints (lab/2026-11-29-h200-train-clock). packs' wall: each pack's first run from "
            "its run.json (the pack opened: its kernels compiled and batches opened before it) to its summary.json, "
            "as the archives' file times give them, summed. devices: as the packs' checksum lists name them."
            "\n\n"
            f"Generated by `python3 {TOOL}` from the packs: `kage.bench compare METHOD_DIR BASELINE_DIR --names "
            f"METHOD {BASELINE} --seeds {SEEDS[0]}-{SEEDS[-1]} --reps {REPS}` per method.\n")


NOTHING_PUBLISHED = (f"\nNo method is published yet: a method's packs go into METHOD/packs beside this page, then "
                     f"`python3 {TOOL}` writes the tables here.\n")


def computed(methods: List[str], methods_root: str, baseline_packs: str, work: str) -> str:
    """The generated part for `methods`, unpacked and compared under `work`."""
    if not methods:
        return NOTHING_PUBLISHED
    baseline_dir = os.path.join(work, BASELINE)
    unpack_all(baseline_packs, baseline_dir, say=lambda line: None)
    costs = {BASELINE: (gpu_time(baseline_dir), devices(baseline_packs))}
    results, method_dirs = {}, {method: os.path.join(work, "methods", method) for method in methods}
    cache: dict = {}  # every directory read once (kage.bench.compare.load_once)
    for method, method_dir in method_dirs.items():
        unpack_all(os.path.join(methods_root, method, "packs"), method_dir, say=lambda line: None)
        costs[method] = (gpu_time(method_dir), devices(os.path.join(methods_root, method, "packs")))
        print(f"methods_tables: comparing {method} with the {BASELINE}", file=sys.stderr)
        results[method] = compared([method_dir, baseline_dir], [method, BASELINE],
                                   os.path.join(work, "compare", method), cache)
    matches = {}
    for i, a in enumerate(methods):
        for b in methods[i + 1:]:
            print(f"methods_tables: comparing {a} with {b}", file=sys.stderr)
            matches[(a, b)] = compared([method_dirs[a], method_dirs[b]], [a, b],
                                       os.path.join(work, "compare", f"{a}-{b}"), cache)
    full = next((r for r in results.values() if covers_all(r)), None)
    if full is None:  # no method has every pair and seed: the baseline's row comes from itself
        full = compared([baseline_dir, baseline_dir], [BASELINE, f"{BASELINE} again"],
                        os.path.join(work, "compare", BASELINE), cache)
    return tables(full, results, matches, costs)


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog=f"python3 {TOOL}", description=__doc__.split("\n\n")[0])
    parser.add_argument("methods", nargs="*", metavar="METHOD",
                        help="the methods tabulated (default: every METHOD of the methods root with packs)")
    parser.add_argument("--methods-root", default=METHODS_ROOT,
                        help="the folder of METHOD/packs and of the README written (default results/methods)")
    parser.add_argument("--baseline-packs", default=BASELINE_PACKS,
                        help="the baseline's packs (default results/kage-bench-table/packs)")
    parser.add_argument("--work", help="where to unpack and compare, kept afterwards (each method's compare.md is "
                                       "in WORK/compare/METHOD, each two methods' in WORK/compare/A-B); default: a "
                                       "temporary folder, removed")
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 where the README's tables differ from those of the packs now")
    args = parser.parse_args(argv)
    available = published(args.methods_root)
    for method in args.methods:
        if method not in available:
            fail(f"{os.path.join(args.methods_root, method, 'packs')} has no task_I.tar.gz: publish the method's "
                 f"packs there, or name one of: {', '.join(available) or 'none is published'}")
    methods = args.methods or available
    readme = os.path.join(args.methods_root, "README.md")
    try:
        with open(readme, encoding="utf-8") as f:
            page = f.read()
    except OSError as e:
        fail(f"cannot read {readme} ({e.strerror}): copy results/methods/README.md there, markers included")
    generated_block.span(page, TOOL, readme)  # refuse a page without its markers before the long part
    if args.work:
        block = computed(methods, args.methods_root, args.baseline_packs, args.work)
    else:
        with tempfile.TemporaryDirectory(prefix="methods_tables.") as work:
            block = computed(methods, args.methods_root, args.baseline_packs, work)
    if args.check:
        written = generated_block.generated(page, TOOL, readme)
        if written != block:
            sys.stdout.writelines(difflib.unified_diff(written.splitlines(True), block.splitlines(True),
                                                       f"{readme} (written)", "from the packs now"))
            fail(f"{readme}: its tables are not those of the packs now (diff above): run python3 {TOOL}"
                 f"{'' if args.methods_root == METHODS_ROOT else ' --methods-root ' + args.methods_root} and commit")
        print(f"methods_tables: {readme}: the tables are those of the packs (methods: {', '.join(methods) or 'none'})")
        return 0
    atomic_write(readme, generated_block.replaced(page, block, TOOL, readme).encode())
    print(f"methods_tables: wrote the tables of {', '.join(methods) or 'no method'} into {readme}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
