"""The whole table beside the paper (issue 27): reads a benchmark directory that `kage.bench report` has
reported on (DIR/report/report.json), the paper's figures (results/kage-bench-table/paper.json) and each
training run's evaluation rows, and writes a Markdown page of
- how many of the 340 (pair, seed) results are in;
- per axis: train -> eval success_once, its drop with the report's bootstrap interval, the eval IQM, and the
  distance drop, beside the paper's figures;
- per pair: the same from the report's pairs level;
- per training run: its train success_once (max over training, and at the last evaluation point) and whether
  it collapsed to the never-jump policy (no jump on its train config at the last evaluation point), beside
  the paper's train success of 0.82 to 0.90.
Numbers are formatted as the report formats them (kage.bench.tables, kage.bench.interval_tables).

usage: python3 lab/tools/table_paper.py DIR PAPER_JSON OUT_MD"""
import json
import os
import sys

from kage.bench import interval_tables, tables, training_runs
from kage.bench.report import read_evaluations
from kage.util.tables import md_table

SUCCESS = "success_once"
DISTANCE = "passed_distance"
AXES = ("background", "agent", "distractors", "filters", "effects", "layout")
TABLE_RESULTS = 340


def paper_axis(paper: dict, axis: str) -> str:
    parts = []
    if axis in paper["success"]:
        train, evaluated = paper["success"][axis]
        parts.append(f"{train:.2f} → {evaluated:.2f}")
    parts.append(f"drop {paper['success_drop_pct'][axis]} %")
    if axis in paper["distance_and_progress_drop_pct"]:
        parts.append(f"distance drop {paper['distance_and_progress_drop_pct'][axis]} %")
    return "; ".join(parts)


def axis_table(report: dict, paper: dict) -> str:
    axes = {a["axis"]: a for a in report["levels"]["axes"]}
    estimates = {r["name"]: r for r in report["intervals"]["rows"] if r["scope"] == "axis"}
    rows = []
    for axis in AXES:
        a, i = axes[axis], estimates[axis]
        s = a["metrics"][SUCCESS]
        rows.append([axis, f"{a['n_pairs']} of {len(a['pairs'])}",
                     f"{tables.fmt_stat(s['train'])} → {tables.fmt_stat(s['eval'])}",
                     interval_tables.fmt_drop(i["drop_pct"]), interval_tables.fmt_interval(i["eval_iqm"]),
                     tables.fmt_drop(a["metrics"][DISTANCE]), paper_axis(paper, axis)])
    return md_table(["axis", "pairs in", "train → eval success", "drop [95 % CI]", "eval IQM [95 % CI]",
                     "distance drop", "paper"], rows, 3)


def pair_table(report: dict, paper: dict) -> str:
    rows = []
    for p in report["levels"]["pairs"]:
        s, d = p["metrics"][SUCCESS], p["metrics"][DISTANCE]
        rows.append([p["pair"], p["n_seeds"], tables.fmt_stat(s["train"]), tables.fmt_stat(s["eval"]),
                     tables.fmt_drop(s), f"{tables.fmt_stat(d['train'])} → {tables.fmt_stat(d['eval'])}",
                     f"{paper['success_drop_pct'][p['axis']]} %"])
    return md_table(["pair", "seeds", "train success", "eval success", "drop", "distance train → eval",
                     "paper's axis drop"], rows, 1)


def finished_runs(bench_dir: str, report: dict) -> list:
    """The outcome of each finished training run (kage.bench.training_runs), in unit and seed order."""
    return [training_runs.outcome(unit, seed, read_evaluations(os.path.join(bench_dir, "runs", unit, f"seed_{seed}",
                                                                            "metrics.jsonl")), SUCCESS)
            for unit, seed in sorted({(r["unit"], r["seed"]) for r in report["levels"]["runs"] if r["finished"]})]


def main() -> None:
    if len(sys.argv) != 4:
        sys.exit(__doc__.splitlines()[-1])
    bench_dir, paper_path, out_path = sys.argv[1:]
    with open(os.path.join(bench_dir, "report", "report.json")) as f:
        report = json.load(f)
    with open(paper_path) as f:
        paper = json.load(f)
    results = sum(p["n_seeds"] for p in report["levels"]["pairs"])
    runs = finished_runs(bench_dir, report)
    counts = training_runs.summary(runs)
    low, high = paper["train_success_axis_means"]
    seeds = md_table(["training run", "seed", "train success, max", "at the end", "collapsed"],
                     [[o.unit, o.seed, f"{o.best:.2f}", f"{o.last:.2f}", "yes" if o.collapsed else ""] for o in runs],
                     1)
    lines = [
        "# The whole table beside the paper",
        "",
        f"Written by `bash lab/tools/table_publish.sh` from `kage.bench report`'s report.json. Results in: "
        f"{results} of {TABLE_RESULTS} (pair, seed); {len(runs)} training runs. Paper: {paper['source']}.",
        "Success is `success_once`, each run's maximum over training, as in the paper; ± is the SEM over pairs "
        "(axes) or seeds (pairs); brackets are the report's 95 % stratified-bootstrap intervals; - where no "
        "pair of the row has run yet.",
        "",
        "## Per axis", "", axis_table(report, paper),
        "## Per pair", "", pair_table(report, paper),
        "## Train success and collapse", "",
        f"Mean over training runs of the max train success: {counts['mean_best']:.2f} (paper's axis means: "
        f"{low:.2f} to {high:.2f}). Never above {training_runs.NEVER_LEARNED}: {counts['never_learned']} of "
        f"{len(runs)}. Collapsed to never jumping (no jump on the train config at the last evaluation point): "
        f"{counts['collapsed']} of {len(runs)}.",
        "", seeds]
    with open(out_path, "w") as f:
        f.write("\n".join(lines))
    print(f"table_paper: {results} of {TABLE_RESULTS} results; wrote {out_path}")


if __name__ == "__main__":
    main()
