"""The benchmark report's tables: CSV and Markdown text of the three levels kage.bench.report computes,
and their files (see its docstring for the protocol). Numbers in Markdown: mean ± SEM to 3 significant
digits (at most 2 decimals); "-" where a value is missing, "n/a" for an undefined drop."""
import os
from typing import List, Optional

from kage.bench.interval_tables import intervals_csv, md_intervals
from kage.fields import MARKDOWN_METRICS, REPORT_METRICS, SUCCESS_NOTE, SUCCESS_SHOWN
from kage.util.files import atomic_write
from kage.util.tables import csv_text, decimals, fmt_value, md_table

RETURN_NOTE = ("The return is negative for most policies, so its drop is a percentage of a negative train return: "
               "read the gap.")
NOTES = {SUCCESS_SHOWN: SUCCESS_NOTE, "return": RETURN_NOTE}


VALUE_COLUMNS = ("train_mean", "train_sem", "eval_mean", "eval_sem", "gap", "drop_pct")
DIFF_COLUMNS = ("max_abs_diff_mean", "max_abs_diff_sem")


def value_cells(v: dict) -> list:
    diff = v["max_abs_diff"] or {}
    return [v["train"]["mean"], v["train"]["sem"], v["eval"]["mean"], v["eval"]["sem"], v["gap"], v["drop_pct"],
            diff.get("mean"), diff.get("sem")]


def pairs_csv(pairs: List[dict]) -> str:
    rows = [[p["pair"], p["axis"], m, p["n_seeds"], *value_cells(p["metrics"][m])]
            for p in pairs for m in REPORT_METRICS]
    return csv_text(("pair", "axis", "metric", "n_seeds") + VALUE_COLUMNS + DIFF_COLUMNS, rows)


def axes_csv(axes: List[dict]) -> str:
    rows = [[a["axis"], m, a["n_pairs"], *value_cells(a["metrics"][m])] for a in axes for m in REPORT_METRICS]
    return csv_text(("axis", "metric", "n_pairs") + VALUE_COLUMNS + DIFF_COLUMNS, rows)


def sweeps_csv(sweeps: List[dict]) -> str:
    rows = [[s["sweep"], e["sweep_eval"], s["axis"], m, e["n_seeds"], *value_cells(e["metrics"][m])]
            for s in sweeps for e in s["evals"] for m in REPORT_METRICS]
    return csv_text(("sweep", "sweep_eval", "axis", "metric", "n_seeds") + VALUE_COLUMNS + DIFF_COLUMNS, rows)


def runs_csv(level1: List[dict], score: str = "max") -> str:
    """One row per run and metric: its values under the protocol `score` ("max" or "final"), whether the run
    finished, and the step of its latest evaluation."""
    rows = [[r["pair"], r["unit"], r["seed"], m, v["train"], v["eval"], v["gap"], v["drop_pct"], v["max_abs_diff"],
             r["finished"], r["step"]] for r in level1 for m, v in r["metrics"].items()]
    return csv_text(("pair", "unit", "seed", "metric", f"train_{score}", f"eval_{score}", "gap", "drop_pct",
                     "max_abs_diff", "finished", "step"), rows)


def mark_interim(text: str) -> str:
    """An interim report's CSV: a first column "interim", "yes" on every row."""
    lines = text.splitlines()
    return "\n".join(["interim," + lines[0]] + ["yes," + line for line in lines[1:]]) + "\n"


# ---- Markdown ----

def fmt_stat(stat: dict) -> str:
    """"0.83 ± 0.02": the SEM to the mean's decimals."""
    if stat["mean"] is None:
        return "-"
    d = decimals(stat["mean"])
    return f"{stat['mean']:.{d}f} ± {stat['sem']:.{d}f}"


def fmt_drop(v: dict) -> str:
    """"-" where a side has no value, "n/a" where the train mean is 0."""
    if v["gap"] is None:
        return "-"
    return "n/a" if v["drop_pct"] is None else f"{v['drop_pct']:.1f} %"


def metric_title(name: str, metric: str) -> str:
    return name if name == metric else f"{name} (`{metric}`)"


def md_section(level: int, name: str, metric: str, table: str) -> str:
    """A metric's table under its heading, and the metric's note (which success, what a return drop means)."""
    note = f"\n{NOTES[metric]}\n" if metric in NOTES else ""
    return f"{'#' * level} {metric_title(name, metric)}\n\n{table}{note}"


def md_axes(axes: List[dict], level: int) -> str:
    sections = []
    for name, m in MARKDOWN_METRICS:
        rows = [[a["axis"], a["n_pairs"], fmt_stat(v["train"]), fmt_stat(v["eval"]), fmt_value(v["gap"]), fmt_drop(v)]
                for a in axes for v in [a["metrics"][m]]]
        table = md_table(("axis", "pairs", "train", "eval", "gap", "drop"), rows, 1)
        sections.append(md_section(level, name, m, table))
    return "\n".join(sections)


def md_pairs(pairs: List[dict], level: int) -> str:
    sections = []
    for name, m in MARKDOWN_METRICS:
        rows = [[p["pair"], p["axis"], p["n_seeds"], fmt_stat(v["train"]), fmt_stat(v["eval"]), fmt_value(v["gap"]),
                 fmt_drop(v), fmt_stat(v["max_abs_diff"])] for p in pairs for v in [p["metrics"][m]]]
        table = md_table(("pair", "axis", "seeds", "train", "eval", "gap", "drop", "max abs diff"), rows, 2)
        sections.append(md_section(level, name, m, table))
    uncertified = [p["pair"] for p in pairs if p["certified"] is False]
    if uncertified:
        sections.append(f"Pairs that kagec did not certify (see suite.json): {', '.join(uncertified)}.\n")
    several = [f"{p['pair']} ({p['trains_on']})" for p in pairs if p.get("trains_on")]
    if several:
        sections.append(f"Pairs that train on several configs: {', '.join(several)}.\n")
    return "\n".join(sections)


def md_sweeps(sweeps: List[dict], level: int) -> str:
    sections = []
    for s in sweeps:
        first = s["evals"][0]["metrics"]
        train = ", ".join(f"{name} {fmt_stat(first[m]['train'])}" for name, m in MARKDOWN_METRICS)
        header = ["eval"]
        for name, _ in MARKDOWN_METRICS:
            header += [name, f"{name} drop"]
        rows = [[e["sweep_eval"]] + [cell for _, m in MARKDOWN_METRICS
                                     for cell in (fmt_stat(e["metrics"][m]["eval"]), fmt_drop(e["metrics"][m]))]
                for e in s["evals"]]
        sections.append(f"{'#' * level} {s['sweep']} ({s['axis']})\n\n"
                        f"Train config `{s['train_config']}`, mean ± SEM over {s['n_seeds']} seeds: {train}.\n\n"
                        + md_table(header, rows, 1))
    return "\n".join(sections) + f"\n{SUCCESS_NOTE} {RETURN_NOTE}\n"


PROTOCOL_TEXT = (
    "Per run, each value's maximum over training (train and eval sides maximised independently); per pair, the "
    "mean ± SEM over seeds; per axis, the mean ± SEM of the pairs' means, each pair weighted equally. gap = train "
    "- eval and drop = 100 (train - eval) / train, both on the means of the row; n/a where train is 0. "
    "\"max abs diff\" is the mean ± SEM of each run's largest |train - eval| at one evaluation point.")
FINAL_TEXT = (
    "Per run, each value at its last evaluation point (the final checkpoint); per pair, the mean ± SEM over seeds; "
    "per axis, the mean ± SEM of the pairs' means, each pair weighted equally. gap = train - eval and drop = 100 "
    "(train - eval) / train, both on the means of the row; n/a where train is 0. \"max abs diff\" is the mean ± "
    "SEM of each run's |train - eval| at its last evaluation point.")
PROTOCOL_TEXTS = {"max": PROTOCOL_TEXT, "final": FINAL_TEXT}  # by kage.bench report --protocol


def status_text(status: dict) -> str:
    def listed(runs: List[dict]) -> str:
        names = [f"{r['unit']} seed {r['seed']}" for r in runs]
        return ", ".join(names[:10]) + (f" and {len(names) - 10} more" if len(names) > 10 else "")
    text = f"Runs: {status['finished']} finished"
    inside = [r for r in status["unfinished"] if r.get("in_tables")]
    outside = [r for r in status["unfinished"] if not r.get("in_tables")]
    if inside:
        text += f"; {len(inside)} unfinished, in the tables at their latest evaluation: {listed(inside)}"
    if outside:
        why = " (no evaluation yet)" if status.get("partial") else ""
        text += f"; {len(outside)} unfinished, not in the tables{why}: {listed(outside)}"
    if status["not_started"]:
        text += f"; {len(status['not_started'])} not started: {listed(status['not_started'])}"
    return text + "."


def steps_text(steps: Optional[float]) -> str:
    return "-" if steps is None else f"{steps / 1e6:.3g} M"


def interim_text(status: dict) -> str:
    """An interim report's notice: what it includes, and how far each unfinished run got."""
    rows = [[r["unit"], r["seed"], r["evaluations"], steps_text(r["step"]), steps_text(r["total_steps"]),
             "yes" if r["in_tables"] else "no"] for r in status["unfinished"]]
    table = md_table(("unfinished run", "seed", "evaluations", "latest step", "of", "in the tables"), rows, 1) \
        if rows else "No run is unfinished.\n"
    return ("**Interim report** (`--partial`): unfinished runs are in the tables at their latest evaluation point, "
            "so the numbers will change as they finish.\n\n" + table)


def md_document(title: str, status: dict, body: str, protocol: str = PROTOCOL_TEXT) -> str:
    if status.get("partial"):
        return f"# {title} (interim)\n\n{interim_text(status)}\n{protocol}\n\n{status_text(status)}\n\n{body}"
    return f"# {title}\n\n{protocol}\n\n{status_text(status)}\n\n{body}"


# ---- writing ----

def write_tables(out_dir: str, suite_name: str, levels: dict, status: dict, protocol: str = PROTOCOL_TEXT,
                 estimates: Optional[dict] = None, score: str = "max") -> List[str]:
    """The CSV and Markdown files; returns their names. `protocol` is the paragraph that says what a value is
    (kage.ppo.evaluate's differs: one checkpoint instead of maxima over training) and `score` its name in
    runs.csv; `estimates`, the interval estimates of kage.bench.intervals, where there are any. Under
    status["partial"] every file is marked interim."""
    files = {"runs.csv": runs_csv(levels["runs"], score)}
    combined = []
    if levels["pairs"]:
        files["axes.csv"] = axes_csv(levels["axes"])
        files["pairs.csv"] = pairs_csv(levels["pairs"])
        files["axes.md"] = md_document(f"{suite_name}: per axis", status, md_axes(levels["axes"], 2), protocol)
        files["pairs.md"] = md_document(f"{suite_name}: per pair", status, md_pairs(levels["pairs"], 2), protocol)
        combined.append(f"## Per axis\n\n{md_axes(levels['axes'], 3)}")
        if estimates:
            files["intervals.csv"] = intervals_csv(estimates["rows"])
            files["intervals.md"] = md_document(f"{suite_name}: interval estimates", status,
                                                md_intervals(estimates, 2), protocol)
            combined.append(md_intervals(estimates, 2))
        combined.append(f"## Per pair\n\n{md_pairs(levels['pairs'], 3)}")
    if levels["sweeps"]:
        files["sweeps.csv"] = sweeps_csv(levels["sweeps"])
        files["sweeps.md"] = md_document(f"{suite_name}: sweeps", status, md_sweeps(levels["sweeps"], 2), protocol)
        combined.append(f"## Sweeps\n\n{md_sweeps(levels['sweeps'], 3)}")
    files["report.md"] = md_document(f"{suite_name}: benchmark report", status, "\n".join(combined), protocol)
    if status.get("partial"):
        files = {name: mark_interim(text) if name.endswith(".csv") else text for name, text in files.items()}
    for name, text in files.items():
        atomic_write(os.path.join(out_dir, name), text.encode())
    return sorted(files)
