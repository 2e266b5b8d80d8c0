"""kage.bench.stats: rliable's published values, closed forms worked out here, rliable's own functions on random
matrices, reproducibility, and the bootstrap's coverage on synthetic data whose true value is known."""
import numpy as np
import pytest

from kage.bench import stats

# rliable's reference scores (its metrics_test.py), [runs, tasks].
X = [[1, 2], [2, 2], [1, 1], [2, 1]]
Y = [[1, 1], [2, 2], [3, 3]]


def test_rliable_reference_values():
    for metric in ("median", "mean", "iqm"):
        assert stats.aggregate(X, metric) == 1.5
        assert stats.aggregate(Y, metric) == 2.0
    # Each task of X holds 1, 1, 2, 2 and of Y 1, 2, 3. Over the 12 pairs, an X run of 1 ties Y's 1 (1/2) and
    # loses to 2 and 3; a 2 beats 1, ties 2 and loses to 3 (3/2): U = 2 (1/2) + 2 (3/2) = 4, 4/12 = 1/3.
    assert stats.probability_of_improvement(X, Y, reps=100).point == pytest.approx(1 / 3)


def test_iqm_closed_forms():
    one_to_eight = np.arange(1.0, 9.0)
    # 8 values: 2 cut at each end, the mean of 3, 4, 5, 6; pooled over runs and tasks, whatever the shape.
    assert stats.aggregate(one_to_eight.reshape(8, 1), "iqm") == 4.5
    assert stats.aggregate(one_to_eight.reshape(2, 4), "iqm") == 4.5
    assert stats.aggregate(one_to_eight[::-1].reshape(4, 2), "iqm") == 4.5
    # 10 values: int(2.5) = 2 cut at each end, the mean of 3..8.
    assert stats.aggregate(np.arange(1.0, 11.0).reshape(5, 2), "iqm") == 5.5
    # 5 values with ties: one cut at each end of 1, 1, 3, 5, 5 leaves 1, 3, 5.
    assert stats.aggregate([[5, 1, 5, 1, 3]], "iqm") == 3.0


def test_optimality_gap_by_hand():
    # min(x, 1): 0.5, 1, 0.9, 0.2, mean 0.65, gap 0.35.
    assert stats.aggregate([[0.5, 1.2], [0.9, 0.2]], "optimality_gap") == pytest.approx(0.35)


def test_missing_runs():
    # NaN is a run the task does not have. Task means 2, 4, 1: mean 7/3, median 2. Pooled 0, 1, 2, 3, 4: one cut
    # at each end, IQM 2; the clipped mean 1 - (0 + 1 + 1 + 1 + 1) / 5 = 0.2 gives the gap 0.2.
    scores = [[1, 4, 0], [3, np.nan, 2]]
    assert stats.aggregate(scores, "mean") == pytest.approx(7 / 3)
    assert stats.aggregate(scores, "median") == 2.0
    assert stats.aggregate(scores, "iqm") == 2.0
    assert stats.aggregate(scores, "optimality_gap") == pytest.approx(0.2)


def test_performance_profile_by_hand():
    # Four scores 0.1, 0.5, 0.9, 0.3; strictly above 0: all, above 0.3: 0.5 and 0.9, above 0.5: 0.9, above 1: none.
    profile = stats.performance_profile([[0.1, 0.5], [0.9, 0.3]], [0, 0.3, 0.5, 1], reps=200)
    assert profile.point.tolist() == [1.0, 0.5, 0.25, 0.0]
    assert np.all(profile.low <= profile.point) and np.all(profile.point <= profile.high)
    assert (profile.low[0], profile.high[0], profile.low[-1], profile.high[-1]) == (1.0, 1.0, 0.0, 0.0)


def test_tasks_are_strata():
    # Runs are resampled within each task, never tasks: identical runs leave nothing to resample.
    estimate = stats.interval_estimates({"a": [[1, 2], [1, 2], [1, 2]]}, ["mean", "iqm"], reps=500)["a"]
    assert estimate["mean"] == (1.5, 1.5, 1.5)
    assert estimate["iqm"] == (1.5, 1.5, 1.5)


def test_probability_of_improvement_extremes():
    # Every run of x beats every run of y: 1 in every resample. Identical scores: every comparison half a win.
    assert stats.probability_of_improvement([[2], [3]], [[0], [1]], reps=300) == (1.0, 1.0, 1.0)
    assert stats.probability_of_improvement([[1], [2]], [[1], [2]], reps=300).point == 0.5


def test_relative_drop_keeps_each_runs_pair():
    # Each run's eval score is half its train score, so every resample of runs has eval mean = train mean / 2:
    # a 50 % drop with no spread. Resampling the two means separately would spread it.
    train = [[1.0, 0.2], [0.5, 0.8], [0.9, 0.4]]
    evaluated = [[0.5, 0.1], [0.25, 0.4], [0.45, 0.2]]
    drop = stats.relative_drop(train, evaluated, reps=2000)
    assert (drop.point, drop.low, drop.high, drop.undefined_fraction) == pytest.approx((50.0, 50.0, 50.0, 0.0))


def test_relative_drop_undefined_where_train_is_zero():
    zero = stats.relative_drop([[0.0], [0.0]], [[0.5], [0.0]], reps=100)
    assert zero == (None, None, None, 1.0)
    # Run 1 has train 0: a resample that draws it twice (probability 1/4) has train mean 0, so the interval is
    # undefined although the sample's drop, 100 (0.5 - 0.25) / 0.5 = 50 %, is not.
    partly = stats.relative_drop([[0.0], [1.0]], [[0.0], [0.5]], reps=4000)
    assert (partly.point, partly.low, partly.high) == (50.0, None, None)
    assert partly.undefined_fraction == pytest.approx(0.25, abs=0.03)  # binomial sd 0.007 at 4000 resamples


def test_same_seed_same_intervals_and_no_global_state():
    rng = np.random.default_rng(3)
    scores = {"a": rng.random((5, 4)), "b": rng.random((5, 4))}
    before = np.random.get_state()[1].copy()
    first = stats.interval_estimates(scores, stats.AGGREGATES, reps=2000, seed=7)
    assert np.array_equal(np.random.get_state()[1], before)  # numpy's global generator untouched
    assert stats.interval_estimates(scores, stats.AGGREGATES, reps=2000, seed=7) == first
    # A name's interval does not depend on the other names in the dict.
    assert stats.interval_estimates({"b": scores["b"]}, stats.AGGREGATES, reps=2000, seed=7)["b"] == first["b"]
    assert stats.interval_estimates(scores, stats.AGGREGATES, reps=2000, seed=8) != first
    x, y = scores["a"], scores["b"]
    assert stats.probability_of_improvement(x, y, reps=500, seed=1) == stats.probability_of_improvement(
        x, y, reps=500, seed=1)
    assert stats.performance_profile(x, [0.5], reps=500, seed=1).low == stats.performance_profile(
        x, [0.5], reps=500, seed=1).low


def test_refusals():
    with pytest.raises(ValueError, match="unknown metric 'max'"):
        stats.aggregate(X, "max")
    with pytest.raises(ValueError, match="task 1 has no run"):
        stats.aggregate([[1.0, np.nan]], "mean")
    with pytest.raises(ValueError, match="share runs .* but not the same runs"):
        stats.interval_estimates({"a": [[1.0, 2.0], [3.0, np.nan]]}, ["mean"], reps=10, groups=["g", "g"])
    with pytest.raises(ValueError, match="groups has 1 labels for 2 tasks"):
        stats.interval_estimates({"a": X}, ["mean"], reps=10, groups=["g"])
    with pytest.raises(ValueError, match="same tasks"):
        stats.probability_of_improvement(X, [[1.0], [2.0]], reps=10)
    with pytest.raises(ValueError, match="one \\(train, eval\\) pair per run"):
        stats.relative_drop([[1.0], [2.0]], [[1.0], [np.nan]], reps=10)


# ---- against rliable's own code ----

def rliable_modules():
    """rliable's metrics and library modules; a missing package fails the test (it is a test requirement)."""
    from rliable import library, metrics
    return library, metrics


@pytest.mark.parametrize("shape", [(5, 3), (10, 7), (3, 1), (7, 13)])
def test_point_estimates_equal_rliables(shape):
    _, metrics = rliable_modules()
    rng = np.random.default_rng(sum(shape))
    x, y = rng.random(shape), rng.random((shape[0] + 2, shape[1]))
    assert stats.aggregate(x, "iqm") == pytest.approx(metrics.aggregate_iqm(x), rel=1e-12)
    assert stats.aggregate(x, "mean") == pytest.approx(metrics.aggregate_mean(x), rel=1e-12)
    assert stats.aggregate(x, "median") == pytest.approx(metrics.aggregate_median(x), rel=1e-12)
    assert stats.aggregate(x, "optimality_gap") == pytest.approx(metrics.aggregate_optimality_gap(x), rel=1e-12)
    # Discrete scores, so that ties occur in the IQM's cut and in P(X > Y).
    xd, yd = np.round(x * 4) / 4, np.round(y * 4) / 4
    assert stats.aggregate(xd, "iqm") == pytest.approx(metrics.aggregate_iqm(xd), rel=1e-12)
    assert stats.probability_of_improvement(xd, yd, reps=10).point == pytest.approx(
        metrics.probability_of_improvement(xd, yd), rel=1e-12)


def test_intervals_agree_with_rliables():
    # The same stratified bootstrap from other random draws: the bounds agree within the resampling noise. At
    # these sizes a bound's Monte Carlo sd is about 0.003 with rliable's 5,000 resamples; 0.015 is 5 of them.
    library, _ = rliable_modules()
    x = np.random.default_rng(11).random((6, 3))
    iqm = lambda s: np.array([stats.aggregate(s, "iqm")])  # noqa: E731 (rliable takes a function)
    state = np.random.get_state()
    np.random.seed(0)  # rliable draws from numpy's global generator
    try:
        _, theirs = library.get_interval_estimates({"x": x}, iqm, reps=5000)
    finally:
        np.random.set_state(state)
    ours = stats.interval_estimates({"x": x}, ["iqm"], reps=20000)["x"]["iqm"]
    assert ours.low == pytest.approx(theirs["x"][0][0], abs=0.015)
    assert ours.high == pytest.approx(theirs["x"][1][0], abs=0.015)


# ---- coverage ----

TRIALS = 600
# A percentile bootstrap estimates the variance with divisor n (not n - 1) and reads normal quantiles where a
# t quantile would be exact, so with n = 20 runs per task its 95 % interval covers the mean of normal scores
# with probability P(|t_df| < 1.96 sqrt(19 / 20)): 0.941 for five independent tasks (df = 5 x 19 = 95), 0.929
# when all tasks share their runs (df = 19). Over 600 trials the observed coverage has a binomial sd of about
# 0.010; 0.035 is 3.5 of them, so a correct bootstrap passes for almost any seed, and one whose interval is 20 %
# too narrow (coverage about 0.87) fails.
TOLERANCE = 0.035


def covered(estimate: stats.Estimate, truth: float) -> bool:
    return estimate.low <= truth <= estimate.high


def test_coverage_independent_tasks():
    # Five tasks centred at -1, -0.5, 0, 0.5, 1 with normal noise: the mean of the task means is 0, and so is the
    # pooled IQM, the mixture being symmetric about 0.
    rng = np.random.default_rng(2024)
    centres = np.array([-1.0, -0.5, 0.0, 0.5, 1.0])
    hits = {"mean": 0, "iqm": 0}
    for trial in range(TRIALS):
        scores = centres + rng.normal(size=(20, 5))
        estimates = stats.interval_estimates({"s": scores}, ["mean", "iqm"], reps=1000, seed=trial)["s"]
        for metric in hits:
            hits[metric] += covered(estimates[metric], 0.0)
    for metric, count in hits.items():
        assert abs(count / TRIALS - 0.941) <= TOLERANCE, (metric, count / TRIALS)


def test_coverage_needs_shared_runs_resampled_together():
    # Four tasks evaluated on the same 20 runs: each run adds its own luck (sd 1) to all four, plus noise (sd
    # 0.3). Resampled jointly the interval covers the true mean 0 as a bootstrap should; resampled task by task
    # it misses the shared luck's variance: 2 Phi(1.96 sqrt(1.09 / 4 / 1.0225)) - 1 = 0.69 coverage.
    rng = np.random.default_rng(7)
    joint = separate = 0
    for trial in range(TRIALS):
        scores = rng.normal(size=(20, 1)) + 0.3 * rng.normal(size=(20, 4))
        joint += covered(stats.interval_estimates({"s": scores}, ["mean"], reps=1000, seed=trial,
                                                  groups=["run"] * 4)["s"]["mean"], 0.0)
        separate += covered(stats.interval_estimates({"s": scores}, ["mean"], reps=1000, seed=trial)["s"]["mean"],
                            0.0)
    assert abs(joint / TRIALS - 0.929) <= TOLERANCE, joint / TRIALS
    assert separate / TRIALS < 0.8, separate / TRIALS


# ---- unequal numbers of runs (issue 40, item 0) ----

def exact_improvement(x, y):
    """P(X > Y) of two [runs, tasks] matrices, by counting: per task the share of the n_x n_y pairs of runs where
    x's beats y's, a tie counting half; then the mean over tasks."""
    x, y = np.asarray(x), np.asarray(y)
    per_task = [np.mean([(a > b) + 0.5 * (a == b) for a in x[:, t] for b in y[:, t]]) for t in range(x.shape[1])]
    return float(np.mean(per_task))


@pytest.mark.parametrize("runs_x, runs_y, reps", [(10, 8, 50000), (20, 16, 2000), (8, 10, 50000), (3, 40, 50000)],
                         ids=["10-vs-8-default-reps", "20-vs-16", "8-vs-10", "3-vs-40"])
def test_probability_of_improvement_with_unequal_runs(runs_x, runs_y, reps):
    """Each side was resampled in chunks sized by its own number of scores: 10 x 34 against 8 x 34 at the default
    50,000 resamples raised numpy's broadcast error. Discrete scores, so that ties occur."""
    rng = np.random.default_rng(runs_x * 100 + runs_y)
    x, y = np.round(rng.random((runs_x, 34)) * 8) / 8, np.round(rng.random((runs_y, 34)) * 8) / 8
    estimate = stats.probability_of_improvement(x, y, reps=reps)
    assert estimate.point == pytest.approx(exact_improvement(x, y), rel=1e-12)
    assert 0.0 < estimate.low < estimate.point < estimate.high < 1.0
    # The 95 % interval of a mean of 34 tasks' U statistics: about +-2 sd of it, sd well below 0.05 here.
    assert estimate.high - estimate.low < 0.2
    assert stats.probability_of_improvement(x, y, reps=reps) == estimate  # the same resamples each time


def test_probability_of_improvement_with_unequal_runs_agrees_with_rliable():
    """rliable's interval of P(X > Y) resamples each method's runs within each task, independently of the other's,
    as ours does: the bounds agree within the resampling noise (a bound's Monte Carlo sd is about 0.002 with 1,000
    of rliable's resamples here; 0.012 is 6 of them)."""
    library, metrics = rliable_modules()
    rng = np.random.default_rng(40)
    x, y = rng.random((10, 34)), rng.random((8, 34)) * 0.9
    ours = stats.probability_of_improvement(x, y)
    assert ours.point == pytest.approx(metrics.probability_of_improvement(x, y), rel=1e-12)
    state = np.random.get_state()
    np.random.seed(0)  # rliable draws from numpy's global generator
    try:
        _, theirs = library.get_interval_estimates(
            {"x,y": (x, y)}, lambda a, b: np.array([metrics.probability_of_improvement(a, b)]), reps=1000)
    finally:
        np.random.set_state(state)
    assert ours.low == pytest.approx(theirs["x,y"][0][0], abs=0.012)
    assert ours.high == pytest.approx(theirs["x,y"][1][0], abs=0.012)


@pytest.mark.parametrize("call, said", [
    (lambda: stats.probability_of_improvement(X, Y, reps=10, seed=None), r"seed=None: a non-negative integer"),
    (lambda: stats.interval_estimates({"x": X}, ["iqm"], reps=10, seed=None), r"seed=None: a non-negative integer"),
    (lambda: stats.performance_profile(X, [0.5], reps=10, seed=-1), r"seed=-1: a non-negative integer"),
    (lambda: stats.relative_drop(X, X, reps=10, seed=1.5), r"seed=1.5: a non-negative integer"),
    (lambda: stats.interval_estimates({"x": X}, "iqm", reps=10), r"metrics='iqm': a list of metric names, e\.g\. "
                                                                 r"\['iqm'\]"),
    (lambda: stats.interval_estimates({"x": X}, np.mean, reps=10), r"metrics=<function mean.*: a list of metric "
                                                                   r"names"),
    (lambda: stats.aggregate(X, ["iqm"]), r"metric: unknown metric \['iqm'\]: give one name of iqm"),
    (lambda: stats.relative_drop(X, X, metric="optimality_gap", reps=10), r"metric: unknown metric 'optimality_gap'"),
    (lambda: stats.interval_estimates(np.asarray(X), ["iqm"], reps=10), r"score_dict: a dict \{name: \[runs, tasks\] "
                                                                        r"scores\}, got a ndarray"),
    (lambda: stats.probability_of_improvement("abc", Y, reps=10), r"x must be a \[runs, tasks\] matrix of numbers"),
    (lambda: stats.performance_profile(X, "high", reps=10), r"taus='high': the thresholds, numbers"),
    (lambda: stats.probability_of_improvement(X, Y, reps=True), r"reps must be a positive integer, got True"),
    (lambda: stats.probability_of_improvement(X, Y, reps=10, confidence="95%"), r"confidence must be between 0 and 1"),
], ids=["poi-seed-none", "intervals-seed-none", "profile-seed-negative", "drop-seed-float", "metrics-string",
        "metrics-function", "metric-list", "drop-metric", "score-dict-array", "x-string", "taus-string", "reps-bool",
        "confidence-string"])
def test_arguments_of_the_wrong_kind_are_named(call, said):
    with pytest.raises(ValueError, match=said):
        call()
