"""kage.bench.stats: aggregates and bootstrap interval estimates of benchmark scores, with the definitions of
rliable (Agarwal et al., "Deep RL at the edge of the statistical precipice", NeurIPS 2021), in numpy only.

Scores are a `[runs, tasks]` matrix (in the benchmark a task is a train/eval pair and a run a seed). NaN marks a
run that a task does not have, so that tasks may have different numbers of runs; every task needs at least one.

Aggregates (`aggregate`), as rliable's metrics.py defines them:
- "mean": the mean over tasks of each task's mean over its runs;
- "median": the median over tasks of the per-task means;
- "iqm": the interquartile mean, `scipy.stats.trim_mean(scores, 0.25)` over all runs and tasks pooled: the
  values sorted, int(0.25 N) cut at each end, the rest averaged;
- "optimality_gap": 1 - mean(min(scores, 1)) over all runs and tasks pooled.

The bootstrap is stratified, as rliable's: each resample draws, within each task, as many runs as the task has,
with replacement, and a percentile interval is read off the resamples' statistics. The tasks are the strata,
never resampled themselves: the interval says how much the result would move with other seeds on the same
tasks. Two choices differ from rliable's:
- Shared runs (`groups`). rliable resamples every task on its own, which is right when each task's runs are
  independent trainings. Under --share-training one run per (train config, seed) is evaluated on every pair of
  that train config (and without it, each pair's own run of that config and seed trains the same agent), so
  those pairs' scores come from the same trainings and move together; resampling them separately would
  average that shared luck away and give intervals too narrow. `groups` gives each task a label; tasks with the
  same label share runs (row i is the same run in each, NaN in all of them where it is missing) and are
  resampled with one draw of rows. None, the default, is one group per task: rliable's bootstrap. Resampling
  independent tasks together is still a valid bootstrap (of the rows as vectors), so a group declared where the
  runs turn out independent costs little. `kage.bench report` groups the pairs by train config: a run depends
  only on its train config, seed and flags, so the pairs of one train config have the same runs even when each
  pair trained its own.
- Reproducibility. rliable draws its resamples from numpy's global generator, so its `random_state` does not
  fix them. Here every call builds its own `numpy.random.Generator` from `seed` (and, in `interval_estimates`,
  from each name, so that a method's interval does not depend on which other methods are in the dict): the
  same arguments give the same intervals, and the global generator is never touched.

A resample is represented by how many times it draws each run (a multinomial count per group, the same
distribution as drawing indices), so every statistic is a weighted sum over the original scores, computed for
many resamples at once: all four metrics over 50,000 resamples of a 34-pair, 10-seed benchmark take about a
second of one CPU core (rliable's loop takes about 19 s per metric).
"""
import zlib
from typing import Dict, Hashable, Iterator, List, Mapping, NamedTuple, Optional, Sequence, Union

import numpy as np

AGGREGATES = ("iqm", "mean", "median", "optimality_gap")  # statistics over runs and tasks, not episode metrics
RATIO_AGGREGATES = ("iqm", "mean", "median")  # an optimality gap is not a level a drop can be taken of
CHUNK_VALUES = 1 << 20  # resamples are computed in chunks of about this many weights (8 MB)

Groups = Optional[Sequence[Hashable]]


class Estimate(NamedTuple):
    """A point estimate and its percentile interval [low, high]."""

    point: float
    low: float
    high: float


class Profile(NamedTuple):
    """A performance profile: per threshold, the fraction of runs scoring above it, and its interval."""

    taus: np.ndarray
    point: np.ndarray
    low: np.ndarray
    high: np.ndarray


class Drop(NamedTuple):
    """A relative drop 100 (train - eval) / train in percent; None where undefined (see `relative_drop`)."""

    point: Optional[float]
    low: Optional[float]
    high: Optional[float]
    undefined_fraction: float  # the share of resamples whose train aggregate was 0


class _Layout:
    """A score matrix as a flat list of its present scores, and for each the column of the run-count array
    that weights it: a task's scores are weighted by its group's counts, one count per row the group has."""

    def __init__(self, scores, groups: Groups, name: str = "scores"):
        try:
            x = np.asarray(scores, dtype=float)
        except (TypeError, ValueError) as e:
            raise ValueError(f"{name} must be a [runs, tasks] matrix of numbers (NaN where a run is missing): "
                             f"{type(scores).__name__} {str(scores)[:60]!r} is not one ({e})") from None
        if x.ndim != 2 or x.shape[0] == 0 or x.shape[1] == 0:
            raise ValueError(f"{name} must be a [runs, tasks] matrix with at least one run and one task, "
                             f"got shape {x.shape}")
        if np.isinf(x).any():
            raise ValueError(f"{name} has an infinite score: give finite scores (NaN marks a missing run)")
        present = ~np.isnan(x)
        empty = np.flatnonzero(~present.any(axis=0))
        if empty.size:
            raise ValueError(f"{name}: task {int(empty[0])} has no run (its column is all NaN): leave it out")
        labels = list(range(x.shape[1])) if groups is None else list(groups)
        if len(labels) != x.shape[1]:
            raise ValueError(f"groups has {len(labels)} labels for {x.shape[1]} tasks: give one label per task")
        self.present = present
        self.task_sizes = present.sum(axis=0)
        self.group_sizes: List[int] = []
        values, rows_of, tasks, columns = [], [], [], []
        for label in dict.fromkeys(labels):
            members = [t for t in range(x.shape[1]) if labels[t] == label]
            rows = np.flatnonzero(present[:, members[0]])
            for t in members[1:]:
                if not np.array_equal(present[:, t], present[:, members[0]]):
                    raise ValueError(
                        f"{name}: tasks {members[0]} and {t} share runs (group {label!r}) but not the same runs: "
                        "row i must be the same run in every task of a group, NaN in all of them where it is missing")
            offset = sum(self.group_sizes)
            for t in members:
                values.append(x[rows, t])
                rows_of.append(rows)
                tasks.append(np.full(rows.size, t))
                columns.append(offset + np.arange(rows.size))
            self.group_sizes.append(int(rows.size))
        # In the order of the values, so that the IQM needs no sort per resample.
        order = np.argsort(np.concatenate(values), kind="stable")
        self.values = np.concatenate(values)[order]
        self.row = np.concatenate(rows_of)[order]
        self.task = np.concatenate(tasks)[order]
        self.column = np.concatenate(columns)[order]
        self.num_tasks = x.shape[1]

    @property
    def size(self) -> int:
        return self.values.size

    def ones(self) -> np.ndarray:
        """The weights of the original sample: every run once."""
        return np.ones((1, self.size))

    def chunk(self, reps: int) -> int:
        """Resamples per chunk: about CHUNK_VALUES weights."""
        return max(1, min(reps, CHUNK_VALUES // self.size))

    def resamples(self, rng: np.random.Generator, reps: int, chunk: Optional[int] = None) -> Iterator[np.ndarray]:
        """[chunk, size] weights of `reps` stratified resamples, in chunks of `chunk` (default self.chunk(reps)):
        each group draws as many of its rows as it has, with replacement, and a score's weight is how often its row
        was drawn. Two layouts resampled side by side (probability_of_improvement) take one chunk size."""
        sizes = np.array(self.group_sizes)
        total = int(sizes.sum())
        high = np.repeat(sizes, sizes)  # per draw: the number of rows of the group it draws for
        first = np.repeat(np.cumsum(sizes) - sizes, sizes)  # and the column of that group's first row
        chunk = self.chunk(reps) if chunk is None else chunk
        for start in range(0, reps, chunk):
            count = min(chunk, reps - start)
            # floor(u n) of a uniform u is a uniform row of n (the bias of a 53-bit u is below 1e-13); faster
            # than integers() with a bound per column
            rows = (rng.random((count, total)) * high).astype(np.int64)
            draws = rows + first + total * np.arange(count)[:, None]
            counts = np.bincount(draws.ravel(), minlength=count * total).reshape(count, total)
            yield counts[:, self.column].astype(float)

    def task_means(self, weights: np.ndarray, values: Optional[np.ndarray] = None) -> np.ndarray:
        """[chunk, tasks]: each task's weighted mean of `values` (default the scores)."""
        values = self.values if values is None else values
        by_task = np.zeros((self.size, self.num_tasks))
        by_task[np.arange(self.size), self.task] = values / self.task_sizes[self.task]
        return weights @ by_task


def _statistic(layout: _Layout, weights: np.ndarray, metric: str, values: Optional[np.ndarray] = None) -> np.ndarray:
    """[chunk]: `metric` of each weighted sample (rows of `weights`) of `values` (default the layout's)."""
    values = layout.values if values is None else values
    n = layout.size
    if metric == "mean":
        return layout.task_means(weights, values).mean(axis=1)
    if metric == "median":
        return np.median(layout.task_means(weights, values), axis=1)
    if metric == "optimality_gap":
        return 1.0 - weights @ np.minimum(values, 1.0) / n
    if metric == "iqm":
        return _iqm(weights, values)
    raise ValueError(f"unknown metric {metric!r}: choose one of {', '.join(AGGREGATES)}")


def _iqm(weights: np.ndarray, values: np.ndarray) -> np.ndarray:
    """[chunk]: scipy.stats.trim_mean(., 0.25) of the multiset where values[i] appears weights[:, i] times.
    In sorted order value i holds positions [cum_(i-1), cum_i) (cum the running sum of the weights); clipped to
    the kept positions [cut, n - cut) these give C_i - C_(i-1), C = clip(cum, cut, n - cut), and summing by parts
    sum_i (C_i - C_(i-1)) v_i = (n - cut) v_last - cut v_first - sum_(i < last) C_i (v_(i+1) - v_i)."""
    order = np.argsort(values, kind="stable")
    if np.any(order != np.arange(values.size)):
        weights, values = weights[:, order], values[order]
    n = values.size
    cut = int(0.25 * n)
    kept = np.clip(np.cumsum(weights[:, :-1], axis=1), cut, n - cut)
    total = (n - cut) * values[-1] - cut * values[0] - kept @ np.diff(values)
    return total / (n - 2 * cut)


def _check(metrics: Sequence[str], allowed: Sequence[str] = AGGREGATES) -> None:
    """`metrics`: a list (or tuple) of names of `allowed`. A string would be read letter by letter, and a function
    (rliable's aggregate_func) is not taken: both are refused naming the argument."""
    if isinstance(metrics, (str, bytes)) or not isinstance(metrics, (list, tuple)):
        raise ValueError(f"metrics={metrics!r:.60}: a list of metric names, e.g. ['iqm'] (choose from "
                         f"{', '.join(allowed)}), not a {type(metrics).__name__}")
    for metric in metrics:
        if not isinstance(metric, str) or metric not in allowed:
            raise ValueError(f"metrics: unknown metric {metric!r:.60}: choose one of {', '.join(allowed)}")


def _check_metric(metric: str, allowed: Sequence[str] = AGGREGATES) -> None:
    """One metric's name, refused naming the argument `metric` where it is not one of `allowed`."""
    if not isinstance(metric, str) or metric not in allowed:
        raise ValueError(f"metric: unknown metric {metric!r:.60}: give one name of {', '.join(allowed)}")


def _check_bootstrap(reps: int, confidence: float, seed: int = 0) -> None:
    if not (isinstance(reps, (int, np.integer)) and not isinstance(reps, (bool, np.bool_)) and reps >= 1):
        raise ValueError(f"reps must be a positive integer, got {reps!r:.60}")
    if not (isinstance(confidence, (int, float, np.integer, np.floating)) and not isinstance(confidence, bool)
            and 0.0 < confidence < 1.0):
        raise ValueError(f"confidence must be between 0 and 1 (0.95 for a 95 % interval), got {confidence!r:.60}")
    if not (isinstance(seed, (int, np.integer)) and not isinstance(seed, (bool, np.bool_)) and seed >= 0):
        raise ValueError(f"seed={seed!r:.60}: a non-negative integer. The bootstrap draws from a generator of its own "
                         "seeded with it, so that the same call gives the same interval (rliable's random_state=None, "
                         "a fresh draw each time, is not offered): give 0, the default, or another integer")


def _percentiles(samples: np.ndarray, confidence: float):
    """The percentile interval (linear interpolation, as numpy's and arch's default) along axis 0."""
    alpha = 1.0 - confidence
    return np.quantile(samples, [alpha / 2, 1.0 - alpha / 2], axis=0)


def aggregate(scores, metric: str) -> float:
    """`metric` ("iqm", "mean", "median" or "optimality_gap", see the module's docstring) of a [runs, tasks]
    score matrix."""
    _check_metric(metric)
    layout = _Layout(scores, None)
    return float(_statistic(layout, layout.ones(), metric)[0])


def _generator(seed: int, name: str) -> np.random.Generator:
    """A generator of its own for `name`: crc32 keeps it the same from one process to the next."""
    return np.random.default_rng([seed, zlib.crc32(name.encode())])


def interval_estimates(score_dict: Mapping[str, object], metrics: Sequence[str], reps: int = 50000,
                       confidence: float = 0.95, seed: int = 0,
                       groups: Union[Groups, Mapping[str, Groups]] = None) -> Dict[str, Dict[str, Estimate]]:
    """{name: {metric: Estimate}} for each [runs, tasks] matrix of `score_dict`: the point estimate and the
    percentile interval of `reps` stratified resamples (the same resamples for every metric of a name).
    `groups`: one label per task, tasks that share runs having the same label, for every name; or a dict
    {name: labels or None} where the names were run differently; None: no task shares runs."""
    if not isinstance(score_dict, Mapping):
        raise ValueError(f"score_dict: a dict {{name: [runs, tasks] scores}}, got a {type(score_dict).__name__}")
    _check(metrics)
    _check_bootstrap(reps, confidence, seed)
    results = {}
    for name, scores in score_dict.items():
        name_groups = groups.get(name) if isinstance(groups, Mapping) else groups
        layout = _Layout(scores, name_groups, name)
        chunks = {m: [] for m in metrics}
        for weights in layout.resamples(_generator(seed, name), reps):
            for m in metrics:
                chunks[m].append(_statistic(layout, weights, m))
        results[name] = {}
        for m in metrics:
            low, high = _percentiles(np.concatenate(chunks[m]), confidence)
            results[name][m] = Estimate(float(_statistic(layout, layout.ones(), m)[0]), float(low), float(high))
    return results


def _improvement(x: _Layout, y: _Layout, wx: np.ndarray, wy: np.ndarray) -> np.ndarray:
    """[chunk]: per task, the Mann-Whitney U of x over y (a win counts 1, a tie 1/2) over n_x n_y, averaged over
    tasks; the weights count how often each run is drawn."""
    total = np.zeros(wx.shape[0])
    for t in range(x.num_tasks):
        ix, iy = np.flatnonzero(x.task == t), np.flatnonzero(y.task == t)
        vx, vy = x.values[ix][:, None], y.values[iy][None, :]
        wins = (vx > vy) + 0.5 * (vx == vy)
        total += np.sum((wx[:, ix] @ wins) * wy[:, iy], axis=1) / (ix.size * iy.size)
    return total / x.num_tasks


def probability_of_improvement(x, y, reps: int = 50000, confidence: float = 0.95, seed: int = 0,
                               groups_x: Groups = None, groups_y: Groups = None) -> Estimate:
    """P(X > Y), rliable's probability of improvement of the method with scores `x` ([runs_x, tasks]) over the
    one with `y` ([runs_y, tasks], the same tasks): per task, the probability that a run of X scores above a run
    of Y, ties counting half (the Mann-Whitney U over n_x n_y), averaged over tasks. The interval resamples x's
    and y's runs independently, each stratified by task (and by `groups_x`, `groups_y`: see the module); x and y
    may have different numbers of runs."""
    _check_bootstrap(reps, confidence, seed)
    lx, ly = _Layout(x, groups_x, "x"), _Layout(y, groups_y, "y")
    if lx.num_tasks != ly.num_tasks:
        raise ValueError(f"x has {lx.num_tasks} tasks and y {ly.num_tasks}: give both methods' scores on the same "
                         "tasks, in the same order")
    rng = np.random.default_rng(seed)
    chunk = min(lx.chunk(reps), ly.chunk(reps))  # one size for both: each chunk pairs x's resamples with y's
    samples = [_improvement(lx, ly, wx, wy) for wx, wy in zip(lx.resamples(rng, reps, chunk),
                                                               ly.resamples(rng, reps, chunk))]
    low, high = _percentiles(np.concatenate(samples), confidence)
    return Estimate(float(_improvement(lx, ly, lx.ones(), ly.ones())[0]), float(low), float(high))


def performance_profile(scores, taus, reps: int = 50000, confidence: float = 0.95, seed: int = 0,
                        groups: Groups = None) -> Profile:
    """rliable's score distribution: for each threshold tau, the fraction of all runs of all tasks (pooled)
    whose score is strictly above tau, with stratified bootstrap intervals."""
    _check_bootstrap(reps, confidence, seed)
    layout = _Layout(scores, groups)
    try:
        taus = np.asarray(taus, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"taus={taus!r:.60}: the thresholds, numbers (e.g. numpy.linspace(0, 1, 101))") from None
    above = (layout.values[:, None] > taus[None, :]) / layout.size
    samples = np.concatenate([w @ above for w in layout.resamples(np.random.default_rng(seed), reps)])
    low, high = _percentiles(samples, confidence)
    return Profile(taus, (layout.ones() @ above)[0], low, high)


def _drops(layout: _Layout, weights: np.ndarray, train: np.ndarray, evaluated: np.ndarray,
           metric: str) -> np.ndarray:
    """[chunk]: 100 (train - eval) / train of the aggregates; NaN where the train aggregate is 0."""
    a_train = _statistic(layout, weights, metric, train)
    a_eval = _statistic(layout, weights, metric, evaluated)
    safe = np.where(a_train == 0, 1.0, a_train)
    return np.where(a_train == 0, np.nan, 100.0 * (a_train - a_eval) / safe)


def relative_drop(train, evaluated, metric: str = "mean", reps: int = 50000, confidence: float = 0.95,
                  seed: int = 0, groups: Groups = None) -> Drop:
    """The relative drop 100 (A(train) - A(eval)) / A(train), A the aggregate `metric`, of two [runs, tasks]
    matrices where train[i, t] and evaluated[i, t] come from the same run (NaN in both where it is missing).
    The bootstrap resamples runs, each run's (train, eval) pair together, so the two aggregates of a resample
    come from the same runs and their correlation is kept; resampling the two means separately would ignore it.

    Where A(train) is 0 the drop is undefined: the point is None if the sample's train aggregate is 0, and the
    interval is None if any resample's is (for success rates: every resampled run has train success 0), since
    a percentile interval cannot place resamples that have no value; `undefined_fraction` says how many did."""
    _check_metric(metric, RATIO_AGGREGATES)
    _check_bootstrap(reps, confidence, seed)
    t, e = np.asarray(train, dtype=float), np.asarray(evaluated, dtype=float)
    if t.shape != e.shape or not np.array_equal(np.isnan(t), np.isnan(e)):
        raise ValueError(f"train {t.shape} and evaluated {e.shape} must have the same shape and NaN at the same "
                         "places: one (train, eval) pair per run")
    layout = _Layout(t, groups, "train")
    eval_values = e[layout.row, layout.task]  # each run's eval score beside its train score
    samples = np.concatenate([_drops(layout, w, layout.values, eval_values, metric)
                              for w in layout.resamples(np.random.default_rng(seed), reps)])
    point = float(_drops(layout, layout.ones(), layout.values, eval_values, metric)[0])
    undefined = float(np.mean(np.isnan(samples)))
    if undefined > 0:
        return Drop(None if np.isnan(point) else point, None, None, undefined)
    low, high = _percentiles(samples, confidence)
    return Drop(point, float(low), float(high), 0.0)
