"""How each training run fared on its own train config, as the published table gives it per run and
`kage.bench compare` per method: its best train success over the evaluation points, its train success at the last
one, and whether it ended collapsed to the never-jump policy (no jump on its train config at its last evaluation
point: the agent stands, or walks into a wall, for the whole episode). A training run is one run directory,
however many pairs it is scored for (--share-training)."""
from dataclasses import dataclass
from typing import Iterable, List, Optional

JUMPS = "jump_count"
NEVER_LEARNED = 0.1  # a best train success below this: the run never learned its train config


@dataclass(frozen=True)
class Outcome:
    unit: str
    seed: int
    best: Optional[float]  # the maximum train success over the evaluation points read (None: none had episodes)
    last: Optional[float]  # the train success at the last of them
    collapsed: bool  # no jump on the train config at the last of them


def outcome(unit: str, seed: int, evaluations: List[dict], metric: str,
            max_step: Optional[int] = None) -> Optional[Outcome]:
    """Run (`unit`, `seed`)'s outcome from its evaluation rows (kage.bench.report.read_evaluations) at or before
    `max_step` where given; None where there is no such row."""
    rows = [r for r in evaluations if max_step is None or r["global_step"] <= max_step]
    if not rows:
        return None
    success = [r["train"].get(metric) for r in rows]
    seen = [s for s in success if s is not None]
    return Outcome(unit, seed, max(seen) if seen else None, success[-1], rows[-1]["train"].get(JUMPS) == 0)


def summary(outcomes: Iterable[Outcome]) -> dict:
    """The counts the tables give: training runs, the mean of their best train success, those whose best stayed
    below NEVER_LEARNED, and those that ended collapsed."""
    outcomes = list(outcomes)
    best = [o.best for o in outcomes if o.best is not None]
    return {"runs": len(outcomes), "mean_best": sum(best) / len(best) if best else None,
            "never_learned": sum(o.best is not None and o.best < NEVER_LEARNED for o in outcomes),
            "collapsed": sum(o.collapsed for o in outcomes)}
