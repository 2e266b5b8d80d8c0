"""What the JSON records of a benchmark folder must hold to be read: bench.json (the units, seeds and trainer
flags, written by kage.bench run) and suite.json (each pair's name and spec hashes). One answer for every
reader (run, status, report, compare), each of which refuses a damaged record in its own words.

A unit's runs are folders DIR/runs/<unit>/seed_<s>/, so a unit name must stay inside DIR/runs/ (unit_name_problem)
and a seed be one that kage.ppo.train takes (0 <= s < 2**63)."""
import re
from typing import List, Optional, Sequence

MAX_SEED = 2**63  # kage.ppo.train's --seed is below it
MAX_SEEDS = 1_000_000  # a list of seeds beyond this is a typo (1-10000000000), not a benchmark


def parse_seeds(text: str) -> List[int]:
    """"1-10", "1,3,5" or "7": at most MAX_SEEDS seeds, each below 2**63 (kage.ppo.train's --seed)."""
    seeds: List[int] = []
    for part in text.split(","):
        m = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", part)
        if not m:
            raise SystemExit(f"kage.bench: --seeds {text!r}: use a range like 1-10, a list like 1,3,5, or one seed")
        first, last = int(m[1]), int(m[2] or m[1])
        if last < first:
            raise SystemExit(f"kage.bench: --seeds {text!r}: the range {first}-{last} is empty")
        if last >= MAX_SEED:
            raise SystemExit(f"kage.bench: --seeds {text!r}: seed {last} is too large: seeds are below 2**63")
        if len(seeds) + last - first + 1 > MAX_SEEDS:
            raise SystemExit(f"kage.bench: --seeds {text!r:.80}: more than {MAX_SEEDS:,} seeds, a run each per pair: "
                             "give fewer seeds")
        seeds.extend(range(first, last + 1))
    return sorted(set(seeds))


def seeds_text(seeds: Sequence[int]) -> str:
    """parse_seeds' syntax for sorted `seeds`: [1, 2, 3, 5] -> "1-3,5"."""
    parts: List[str] = []
    for seed in seeds:
        if parts and seed == last + 1:
            parts[-1] = f"{parts[-1].split('-')[0]}-{seed}"
        else:
            parts.append(str(seed))
        last = seed
    return ",".join(parts)


def unit_name_problem(name) -> Optional[str]:
    """Why `name` cannot be a folder inside DIR/runs/ (absolute, a "." or ".." part, an empty part, a backslash
    or a control character), or None."""
    if not isinstance(name, str):
        return f"{name!r:.60} is not a string"
    if not name or name.startswith("/") or "\\" in name or any(p in ("", ".", "..") for p in name.split("/")) or \
            any(ord(c) < 32 or ord(c) == 127 for c in name):
        return (f"{name!r:.60} is not a relative path of plain parts (no leading '/', no '.' or '..' parts, no empty "
                "part, no backslash or control character)")
    return None


def _strings(value) -> Optional[str]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        return "not a list of strings"
    return None


def _units(value) -> Optional[str]:
    if not isinstance(value, list):
        return "not a list of unit names"
    for name in value:
        problem = unit_name_problem(name)
        if problem:
            return problem
    if len(set(value)) < len(value):
        return f"{sorted(v for v in set(value) if value.count(v) > 1)[0]!r:.60} is listed twice"
    return None


def _seeds(value) -> Optional[str]:
    if not isinstance(value, list) or not all(isinstance(v, int) and not isinstance(v, bool) for v in value):
        return "not a list of integers"
    bad = [v for v in value if not 0 <= v < MAX_SEED]
    if bad:
        return f"seed {str(bad[0])[:60]} is outside [0, 2**63), the seeds kage.ppo.train takes"
    if len(set(value)) < len(value):
        return f"seed {next(v for v in value if value.count(v) > 1)} is listed twice"
    return None


def _shared(value) -> Optional[str]:
    """--share-training's {pair: [unit, label]}."""
    if not isinstance(value, dict):
        return "not an object {pair: [unit, label]}"
    for pair, where in value.items():
        if not (isinstance(where, list) and len(where) == 2 and all(isinstance(v, str) for v in where)):
            return f"the entry of {pair!r:.60} is not [unit, label]"
        problem = unit_name_problem(where[0])
        if problem:
            return problem
    return None


BENCH_KEYS = {"units": _units, "seeds": _seeds, "trainer_args": _strings}
OPTIONAL_KEYS = {"shared": _shared}  # checked where present


def bench_problem(bench, keys: Sequence[str] = tuple(BENCH_KEYS)) -> Optional[str]:
    """What bench.json's content lacks of `keys` (its units, seeds and trainer flags), or where one is not what
    kage.bench run writes (a seed it would not train, a unit name outside DIR/runs/, an entry twice); None when
    it holds them. "shared" is checked where present."""
    if not isinstance(bench, dict):
        return f"a JSON {type(bench).__name__}, not an object"
    for key in keys:
        if key not in bench:
            return f"no '{key}'"
        problem = BENCH_KEYS[key](bench[key])
        if problem:
            return f"no valid '{key}': {problem}"
    for key, check in OPTIONAL_KEYS.items():
        problem = check(bench[key]) if key in bench else None
        if problem:
            return f"no valid '{key}': {problem}"
    return None


def _side_problem(side) -> Optional[str]:
    if not (isinstance(side, dict) and isinstance(side.get("spec_sha256"), str) and isinstance(side.get("name"), str)):
        return "without its name and spec_sha256"
    if "stages" in side:
        return _stages_problem(side)
    return None


def _stages_problem(side: dict) -> Optional[str]:
    """A mixture's or schedule's "stages" ([{"start", "configs": [{"name", "spec_sha256", "weight"}]}]) and
    "schedule" (a path or null), as kagec suite writes them."""
    stages, schedule = side["stages"], side.get("schedule")
    if schedule is not None and not isinstance(schedule, str):
        return "a mixture whose 'schedule' is neither a path nor null"
    if not isinstance(stages, list) or not stages:
        return "a mixture without a list of stages"
    for stage in stages:
        configs = stage.get("configs") if isinstance(stage, dict) else None
        start = stage.get("start") if isinstance(stage, dict) else None
        if not isinstance(start, int) or isinstance(start, bool) or not isinstance(configs, list) or not configs:
            return "a mixture with a stage that lacks its start or configs"
        for c in configs:
            weight = c.get("weight") if isinstance(c, dict) else None
            if not (isinstance(c, dict) and isinstance(c.get("name"), str) and isinstance(c.get("spec_sha256"), str)
                    and isinstance(weight, (int, float)) and not isinstance(weight, bool)):
                return "a mixture with a config that lacks its name, spec_sha256 or weight"
    return None


def suite_problem(suite) -> Optional[str]:
    """What suite.json's content lacks: each pair's name (a unit name, once), its sweep and sweep eval name,
    declared axis and its two sides' names and spec hashes; None when it holds them."""
    detail = _suite_detail(suite)
    return f"not a suite report with each pair's name and spec hashes ({detail})" if detail else None


def _suite_detail(suite) -> Optional[str]:
    pairs = suite.get("pairs") if isinstance(suite, dict) else None
    if not isinstance(pairs, list):
        return "no list of pairs"
    seen = set()
    for index, p in enumerate(pairs):
        if not isinstance(p, dict):
            return f"pair {index} is a JSON {type(p).__name__}, not an object"
        name = p.get("pair")
        problem = unit_name_problem(name) or (f"{name!r} is listed twice" if name in seen else None)
        if problem:
            return f"pair {index}: {problem}"
        seen.add(name)
        sweep, sweep_eval, axis = p.get("sweep"), p.get("sweep_eval"), p.get("declared_axis")
        if sweep is not None and (unit_name_problem(sweep) or not isinstance(sweep_eval, str)):
            return f"pair {name!r}: a sweep without a valid sweep name and sweep_eval"
        if axis is not None and not isinstance(axis, str):
            return f"pair {name!r}: declared_axis is not a string or null"
        for side in ("train", "eval"):
            problem = _side_problem(p.get(side))
            if problem:
                return f"pair {name!r}: its {side} config is {problem}"
    return None
