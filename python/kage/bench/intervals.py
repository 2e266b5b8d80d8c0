"""The report's interval estimates of success (kage.bench.stats, after rliable), per axis and over all plain pairs:

- the IQM of the eval side's and the train side's per-run scores, all the scope's pairs and seeds pooled, each with
  a 95 % percentile interval from a stratified bootstrap of the runs within each pair;
- the relative drop 100 (train - eval) / train of the mean over pairs of the mean over seeds (the axes table's
  drop), its interval from resampling each run's (train, eval) pair together; no point where the train mean is 0,
  and no interval where a resample's train mean is 0 (the share of such resamples is given);
- the performance profile over all plain pairs: the fraction of runs whose score is above each threshold.

A run's score is the report's level-1 value (kage.bench.report: the maximum over training or the last evaluation).
The pairs are the tasks and the seeds the runs; a pair missing a seed has a gap there. Under --share-training the
pairs that one shared run evaluates have the same runs, and are resampled together (stats' groups, one per run
unit). The bootstrap draws from its own generator, seeded with SEED, so a report is the same every time.
"""
from typing import Dict, List, NamedTuple, Optional

import numpy as np

from kage.bench import stats
from kage.util.tables import SUCCESS_SHOWN

CONFIDENCE = 0.95
REPS = 50000
SEED = 0
TAUS = np.arange(101) / 100  # 0, 0.01, ..., 1: each the double nearest its decimal
ALL_PAIRS = "all pairs"


class Scores(NamedTuple):
    """One scope's per-run scores: [seeds, pairs] matrices, NaN where a pair lacks a seed."""

    pairs: List[str]
    seeds: List[int]
    groups: List[str]  # per pair, the run unit that trained it
    train: np.ndarray
    eval: np.ndarray


def scores_of(level1: List[dict], pair_names: List[str], metric: str = SUCCESS_SHOWN) -> Scores:
    """The level-1 values of `metric` of the named pairs' runs; pairs without a run are left out."""
    records = [r for r in level1 if r["pair"] in pair_names and r["metrics"][metric]["train"] is not None
               and r["metrics"][metric]["eval"] is not None]
    pairs = [p for p in pair_names if any(r["pair"] == p for r in records)]
    seeds = sorted({r["seed"] for r in records})
    train = np.full((len(seeds), len(pairs)), np.nan)
    evaluated = np.full((len(seeds), len(pairs)), np.nan)
    groups = [""] * len(pairs)
    for r in records:
        i, j = seeds.index(r["seed"]), pairs.index(r["pair"])
        train[i, j], evaluated[i, j] = r["metrics"][metric]["train"], r["metrics"][metric]["eval"]
        groups[j] = r["unit"]
    return Scores(pairs, seeds, groups, train, evaluated)


def estimate(scope: str, name: str, scores: Scores, reps: int) -> dict:
    """One row: the scope's IQMs and drop with their intervals; None where it has no run."""
    row = {"scope": scope, "name": name, "n_pairs": len(scores.pairs), "n_runs": int(np.sum(~np.isnan(scores.eval)))}
    if not scores.pairs:
        return {**row, "eval_iqm": None, "train_iqm": None, "drop_pct": None}
    iqm = stats.interval_estimates({"eval": scores.eval, "train": scores.train}, ["iqm"], reps, CONFIDENCE, SEED,
                                   groups=scores.groups)
    drop = stats.relative_drop(scores.train, scores.eval, "mean", reps, CONFIDENCE, SEED, scores.groups)
    return {**row, "eval_iqm": iqm["eval"]["iqm"]._asdict(), "train_iqm": iqm["train"]["iqm"]._asdict(),
            "drop_pct": drop._asdict()}


def profile(scores: Scores, reps: int) -> Optional[dict]:
    """The performance profiles of both sides over TAUS; None without a run."""
    if not scores.pairs:
        return None
    curves = {}
    for side, matrix in (("eval", scores.eval), ("train", scores.train)):
        p = stats.performance_profile(matrix, TAUS, reps, CONFIDENCE, SEED, scores.groups)
        curves[side] = {"point": p.point.tolist(), "low": p.low.tolist(), "high": p.high.tolist()}
    return {"taus": TAUS.tolist(), **curves}


def interval_report(level1: List[dict], pairs: List[dict], reps: int = REPS) -> dict:
    """report.json's "intervals": a row per axis (in the order of `pairs`, the plain pairs of level 2) and one
    over all plain pairs, and the profile over all of them."""
    axes: Dict[str, List[str]] = {}
    for p in pairs:
        axes.setdefault(p["axis"], []).append(p["pair"])
    everything = scores_of(level1, [p["pair"] for p in pairs])
    rows = [estimate("axis", axis, scores_of(level1, names), reps) for axis, names in axes.items()]
    rows.append(estimate("all", ALL_PAIRS, everything, reps))
    return {"metric": SUCCESS_SHOWN, "confidence": CONFIDENCE, "reps": reps, "seed": SEED,
            "iqm": "interquartile mean of the per-run scores, the scope's pairs and seeds pooled (rliable)",
            "drop_pct": "100 (train - eval) / train of the mean over pairs of the mean over seeds; the bootstrap "
                        "resamples each run's (train, eval) pair together",
            "bootstrap": "stratified: runs resampled within each pair, the pairs of one shared run together; "
                         "percentile intervals",
            "rows": rows, "profile": profile(everything, reps)}
