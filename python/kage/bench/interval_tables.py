"""Markdown and CSV of interval estimates (kage.bench.intervals' rows): the report's table and, one block per
method, kage.bench compare's. An estimate reads "0.42 [0.31, 0.55]": the point, then the 95 % interval."""
from typing import List, Optional

from kage.util.tables import csv_text, md_table

CSV_COLUMNS = ("scope", "name", "n_pairs", "n_runs", "eval_iqm", "eval_iqm_low", "eval_iqm_high", "train_iqm",
               "train_iqm_low", "train_iqm_high", "drop_pct", "drop_pct_low", "drop_pct_high",
               "drop_undefined_fraction")


def fmt_interval(estimate: Optional[dict]) -> str:
    """Shares (success, progress), so two decimals."""
    if estimate is None:
        return "-"
    return f"{estimate['point']:.2f} [{estimate['low']:.2f}, {estimate['high']:.2f}]"


def fmt_drop(drop: Optional[dict]) -> str:
    """"-" without runs, "n/a" where the train mean is 0, no interval where a resample's train mean is 0."""
    if drop is None:
        return "-"
    if drop["point"] is None:
        return "n/a"
    if drop["low"] is None:
        share = 100 * drop["undefined_fraction"]
        # A few resamples in 50,000 are under 0.1 %: "0.0 %" would read as none.
        shown = f"{share:.1f} %" if share >= 0.1 else "< 0.1 %"
        return f"{drop['point']:.1f} % [n/a: train 0 in {shown} of resamples]"
    return f"{drop['point']:.1f} % [{drop['low']:.1f}, {drop['high']:.1f}]"


def explanation(estimates: dict) -> str:
    return (f"IQM: the interquartile mean of the runs' `{estimates['metric']}` values (each run's value as above), "
            "the row's pairs and seeds pooled. drop: 100 (train - eval) / train of the mean over pairs of the mean "
            "over seeds, as in the axes table. Brackets: 95 % percentile intervals of "
            f"{estimates['reps']:,} stratified bootstrap resamples (seed {estimates['seed']}): runs resampled within "
            "each pair, the pairs of one train config together (their runs train the same agent), each run's "
            "train and eval values together. n/a: "
            "the train mean is 0 (in the sample, or in some resamples: then no interval).")


def md_rows(rows: List[dict]) -> str:
    table = [[r["name"], r["n_pairs"], r["n_runs"], fmt_interval(r["eval_iqm"]), fmt_interval(r["train_iqm"]),
              fmt_drop(r["drop_pct"])] for r in rows]
    return md_table(("axis", "pairs", "runs", "eval IQM", "train IQM", "drop"), table, 1)


def md_intervals(estimates: dict, level: int) -> str:
    """The report's section: one row per axis and one over all pairs."""
    return (f"{'#' * level} Interval estimates of `{estimates['metric']}`\n\n{md_rows(estimates['rows'])}\n"
            f"{explanation(estimates)}\n")


def csv_cells(row: dict) -> list:
    def triple(e: Optional[dict]) -> list:
        return [None, None, None] if e is None else [e["point"], e["low"], e["high"]]
    drop = row["drop_pct"]
    return [row["scope"], row["name"], row["n_pairs"], row["n_runs"], *triple(row["eval_iqm"]),
            *triple(row["train_iqm"]), *triple(drop), None if drop is None else drop["undefined_fraction"]]


def intervals_csv(rows: List[dict], methods: Optional[List[str]] = None) -> str:
    """One line per row; with `methods` (one per row), a first column naming each row's method."""
    if methods is None:
        return csv_text(CSV_COLUMNS, [csv_cells(r) for r in rows])
    return csv_text(("method",) + CSV_COLUMNS, [[m, *csv_cells(r)] for m, r in zip(methods, rows)])
