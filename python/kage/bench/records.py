"""What the JSON records of a benchmark folder must hold to be read: bench.json (the units, seeds and trainer
flags, written by kage.bench run) and suite.json (each pair's name and spec hashes). One answer for every
reader (run, status, report), each of which refuses a damaged record in its own words."""
from typing import Optional, Sequence


def _strings(value) -> bool:
    return isinstance(value, list) and all(isinstance(v, str) for v in value)


def _integers(value) -> bool:
    return isinstance(value, list) and all(isinstance(v, int) and not isinstance(v, bool) for v in value)


BENCH_KEYS = {"units": _strings, "seeds": _integers, "trainer_args": _strings}


def bench_problem(bench, keys: Sequence[str] = tuple(BENCH_KEYS)) -> Optional[str]:
    """What bench.json's content lacks of `keys` (its units, seeds and trainer flags), or None."""
    if not isinstance(bench, dict):
        return f"a JSON {type(bench).__name__}, not an object"
    for key in keys:
        if not BENCH_KEYS[key](bench.get(key)):
            return f"no valid '{key}'"
    return None


def suite_problem(suite) -> Optional[str]:
    """What suite.json's content lacks: each pair's name and its two sides' spec hashes, or None."""
    pairs = suite.get("pairs") if isinstance(suite, dict) else None
    if not isinstance(pairs, list) or not all(
            isinstance(p, dict) and isinstance(p.get("pair"), str) and
            all(isinstance(p.get(side), dict) and isinstance(p[side].get("spec_sha256"), str)
                for side in ("train", "eval")) for p in pairs):
        return "not a suite report with each pair's name and spec hashes"
    return None
