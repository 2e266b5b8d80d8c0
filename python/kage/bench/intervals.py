"""The report's interval estimates of success (kage.bench.stats, after rliable), per axis and over all plain pairs:

- the IQM of the eval side's and the train side's per-run scores, all the scope's pairs and seeds pooled, each with
  a 95 % percentile interval from a stratified bootstrap of the runs within each pair;
- the relative drop 100 (train - eval) / train of the mean over pairs of the mean over seeds (the axes table's
  drop), its interval from resampling each run's (train, eval) pair together; no point where the train mean is 0,
  and no interval where a resample's train mean is 0 (the share of such resamples is given);
- the performance profile over all plain pairs: the fraction of runs whose score is above each threshold.

A run's score is the report's level-1 value (kage.bench.report: the maximum over training or the last evaluation) of
`success_once`, or of another metric of kage.fields.INTERVAL_METRICS (--metric: at a few thousand steps no agent
succeeds, while its progress already differs).
The pairs are the tasks and the seeds the runs; a pair missing a seed has a gap there. A run depends only on its
train config, seed and flags, so the pairs of one train config have the same runs: one shared run under
--share-training, or identical separate runs without it (the 34 KAGE-Bench pairs have 7 train configs). Their
scores move together, and they are resampled together (stats' groups: one per train config Spec and set of seeds
run; a pair of that config whose runs are not all there yet is resampled on its own, which narrows the intervals
a little until they are). The bootstrap draws from its own generator, seeded with SEED, so a report is the same
every time.
"""
from typing import Dict, List, NamedTuple, Optional

import numpy as np

from kage.bench import stats
from kage.fields import SUCCESS_SHOWN

CONFIDENCE = 0.95
REPS = 50000
MAX_REPS = 10_000_000  # beyond it the bounds move in the fourth digit only, and the time grows without end
SEED = 0
TAUS = np.arange(101) / 100  # 0, 0.01, ..., 1: each the double nearest its decimal
ALL_PAIRS = "all pairs"


class Scores(NamedTuple):
    """One scope's per-run scores: [seeds, pairs] matrices, NaN where a pair lacks a seed."""

    pairs: List[str]
    seeds: List[int]
    groups: List[str]  # per pair, its train config and the seeds it has: pairs alike share their runs
    train: np.ndarray
    eval: np.ndarray


def scores_of(level1: List[dict], pairs: List[dict], metric: str = SUCCESS_SHOWN) -> Scores:
    """The level-1 values of `metric` of the runs of `pairs` (level-2 entries: "pair" and "train_spec"); pairs
    without a run are left out."""
    train_of = {p["pair"]: p["train_spec"] for p in pairs}
    records = [r for r in level1 if r["pair"] in train_of and r["metrics"][metric]["train"] is not None
               and r["metrics"][metric]["eval"] is not None]
    names = [p["pair"] for p in pairs if any(r["pair"] == p["pair"] for r in records)]
    seeds = sorted({r["seed"] for r in records})
    train = np.full((len(seeds), len(names)), np.nan)
    evaluated = np.full((len(seeds), len(names)), np.nan)
    for r in records:
        i, j = seeds.index(r["seed"]), names.index(r["pair"])
        train[i, j], evaluated[i, j] = r["metrics"][metric]["train"], r["metrics"][metric]["eval"]
    groups = [f"{train_of[name]} seeds {np.flatnonzero(~np.isnan(evaluated[:, j])).tolist()}"
              for j, name in enumerate(names)]
    return Scores(names, seeds, groups, train, evaluated)


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


def reps_problem(reps) -> Optional[str]:
    """Why `reps` (--reps of report and compare) is not a number of bootstrap resamples to draw, or None."""
    if isinstance(reps, bool) or not isinstance(reps, int) or not 1 <= reps <= MAX_REPS:
        return f"--reps {reps}: a number of bootstrap resamples from 1 to {MAX_REPS:,} (default {REPS:,})"
    return None


def interval_report(level1: List[dict], pairs: List[dict], reps: int = REPS, metric: str = SUCCESS_SHOWN) -> dict:
    """report.json's "intervals" of `metric`: a row per axis (in the order of `pairs`, the plain pairs of level 2)
    and one over all plain pairs, and the profile over all of them."""
    axes: Dict[str, List[dict]] = {}
    for p in pairs:
        axes.setdefault(p["axis"], []).append(p)
    everything = scores_of(level1, pairs, metric)
    rows = [estimate("axis", axis, scores_of(level1, members, metric), reps) for axis, members in axes.items()]
    rows.append(estimate("all", ALL_PAIRS, everything, reps))
    return {"metric": metric, "confidence": CONFIDENCE, "reps": reps, "seed": SEED,
            "iqm": "interquartile mean of the per-run scores, the scope's pairs and seeds pooled (rliable)",
            "drop_pct": "100 (train - eval) / train of the mean over pairs of the mean over seeds; the bootstrap "
                        "resamples each run's (train, eval) pair together",
            "bootstrap": "stratified: runs resampled within each pair, the pairs of one train config together; "
                         "percentile intervals",
            "rows": rows, "profile": profile(everything, reps)}
