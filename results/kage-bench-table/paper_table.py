"""The whole table beside the paper (issue 27): reads a benchmark directory that `kage.bench report` has
reported on (DIR/report/report.json), the paper's figures (results/kage-bench-table/paper.json) and each run's
metrics.jsonl, and writes a Markdown page of
- how many of the 340 (pair, seed) results are in;
- per axis: train -> eval success_once, its drop with the report's bootstrap interval, the eval IQM, and the
  distance drop, beside the paper's figures;
- per pair: the same from the report's pairs level;
- per train config: each seed's train success_once (max over training, and at the last evaluation point) and
  whether it collapsed to the never-jump optimum (policy entropy below COLLAPSED_ENTROPY at the end, train
  success_once 0 at the last evaluation point), beside the paper's train success of 0.82 to 0.90.

usage: python3 results/kage-bench-table/paper_table.py DIR PAPER_JSON OUT_MD"""
import json
import os
import sys

SUCCESS = "success_once"
DISTANCE = "passed_distance"
AXES = ("background", "agent", "distractors", "filters", "effects", "layout")
COLLAPSED_ENTROPY = 0.01
TABLE_RESULTS = 340


def rows_of(path: str) -> list:
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def mean_sem(entry: dict) -> str:
    return f"{entry['mean']:.2f} ± {entry['sem']:.2f}"


def interval(entry: dict, digits: int = 2, unit: str = "") -> str:
    if entry is None or entry.get("point") is None:
        return "n/a"
    bounds = "" if entry.get("low") is None else f" [{entry['low']:.{digits}f}, {entry['high']:.{digits}f}]"
    return f"{entry['point']:.{digits}f}{unit}{bounds}"


def paper_axis(paper: dict, axis: str) -> str:
    parts = []
    if axis in paper["success"]:
        train, evaluated = paper["success"][axis]
        parts.append(f"{train:.2f} → {evaluated:.2f}")
    parts.append(f"drop {paper['success_drop_pct'][axis]} %")
    if axis in paper["distance_and_progress_drop_pct"]:
        parts.append(f"distance drop {paper['distance_and_progress_drop_pct'][axis]} %")
    return "; ".join(parts)


def axis_table(report: dict, paper: dict) -> list:
    axes = {a["axis"]: a for a in report["levels"]["axes"]}
    intervals = {r["name"]: r for r in report["intervals"]["rows"] if r["scope"] == "axis"}
    lines = ["| axis | pairs in | train → eval success | drop [95 % CI] | eval IQM [95 % CI] | distance drop | "
             "paper |", "|---|---:|---|---|---|---:|---|"]
    for axis in AXES:
        a = axes.get(axis)
        if a is None or not a["n_pairs"]:
            lines.append(f"| {axis} | 0 | not yet run | | | | {paper_axis(paper, axis)} |")
            continue
        s, d, i = a["metrics"][SUCCESS], a["metrics"][DISTANCE], intervals[axis]
        lines.append(f"| {axis} | {a['n_pairs']} of {len(a['pairs'])} | {mean_sem(s['train'])} → "
                     f"{mean_sem(s['eval'])} | {interval(i['drop_pct'], 1, ' %')} | {interval(i['eval_iqm'])} | "
                     f"{d['drop_pct']:.1f} % | {paper_axis(paper, axis)} |")
    return lines


def pair_table(report: dict, paper: dict) -> list:
    lines = ["| pair | seeds | train success | eval success | drop | distance train → eval | paper's axis drop |",
             "|---|---:|---|---|---:|---|---:|"]
    for p in report["levels"]["pairs"]:
        if not p["n_seeds"]:
            lines.append(f"| {p['pair']} | 0 | not yet run | | | | {paper['success_drop_pct'][p['axis']]} % |")
            continue
        s, d = p["metrics"][SUCCESS], p["metrics"][DISTANCE]
        drop = "n/a" if s["drop_pct"] is None else f"{s['drop_pct']:.1f} %"
        paper_drop = paper["success_drop_pct"][p["axis"]]
        lines.append(f"| {p['pair']} | {p['n_seeds']} | {mean_sem(s['train'])} | {mean_sem(s['eval'])} | {drop} | "
                     f"{d['train']['mean']:.0f} → {d['eval']['mean']:.0f} | {paper_drop} % |")
    return lines


def seed_table(bench_dir: str, report: dict) -> tuple:
    """Per train run: (unit, seed, max train success, last train success, final entropy, collapsed)."""
    runs = sorted({(r["unit"], r["seed"]) for r in report["levels"]["runs"]})
    found = []
    for unit, seed in runs:
        rows = rows_of(os.path.join(bench_dir, "runs", unit, f"seed_{seed}", "metrics.jsonl"))
        train_success = [r["train"][SUCCESS] for r in rows if r["kind"] == "eval"]
        entropy = [r["losses/entropy"] for r in rows if r["kind"] == "train"][-1]
        collapsed = entropy is not None and entropy < COLLAPSED_ENTROPY and train_success[-1] == 0
        found.append((unit, seed, max(train_success), train_success[-1], entropy, collapsed))
    lines = ["| train run | seed | train success, max | at the end | final entropy | collapsed |",
             "|---|---:|---:|---:|---:|---|"]
    lines += [f"| {u} | {s} | {m:.2f} | {last:.2f} | {e:.3f} | {'yes' if c else ''} |"
              for u, s, m, last, e, c in found]
    return lines, found


def main() -> None:
    if len(sys.argv) != 4:
        sys.exit(__doc__.splitlines()[-1])
    bench_dir, paper_path, out_path = sys.argv[1:]
    with open(os.path.join(bench_dir, "report", "report.json")) as f:
        report = json.load(f)
    with open(paper_path) as f:
        paper = json.load(f)
    results = sum(p["n_seeds"] for p in report["levels"]["pairs"])
    seeds, found = seed_table(bench_dir, report)
    collapsed = sum(c for *_, c in found)
    never = sum(m < 0.1 for _, _, m, *_ in found)
    mean_max = sum(m for _, _, m, *_ in found) / len(found)
    low, high = paper["train_success_axis_means"]
    lines = [
        "# The whole table beside the paper",
        "",
        f"Written by `results/kage-bench-table/publish.sh` from `kage.bench report`'s report.json. Results in: "
        f"{results} of {TABLE_RESULTS} (pair, seed); {len(found)} training runs. Paper: {paper['source']}.",
        "Success is `success_once`, each run's maximum over training, as in the paper; ± is the SEM over pairs "
        "(axes) or seeds (pairs); brackets are the report's 95 % stratified-bootstrap intervals.",
        "",
        "## Per axis", "", *axis_table(report, paper), "",
        "## Per pair", "", *pair_table(report, paper), "",
        "## Train success and collapse", "",
        f"Mean over training runs of the max train success: {mean_max:.2f} (paper's axis means: {low:.2f} to "
        f"{high:.2f}). Never above 0.1: {never} of {len(found)}. Collapsed at the end (entropy below "
        f"{COLLAPSED_ENTROPY}, train success 0 at the last evaluation point): {collapsed} of {len(found)}.",
        "", *seeds, ""]
    with open(out_path, "w") as f:
        f.write("\n".join(lines))
    print(f"paper_table: {results} of {TABLE_RESULTS} results; wrote {out_path}")


if __name__ == "__main__":
    main()
