"""What a run trains on, as stages: one config (--train-config-path), a mixture of configs split by weights
(--train-config-paths, --train-weights), or a curriculum whose mixture changes at given iterations
(--train-schedule FILE). Every stage's batch is a kage.make_vec mixture of the same hidden game; the configs of
all stages are certified together as one mixture (kagec diff --mixture) before anything is written.

A schedule file is a YAML list of stages, in order of start:

    - start: 1                      # the first iteration (counted from 1) of the stage; the first starts at 1
      configs: [a.yaml, b.yaml]     # paths relative to this file, or shipped configs' names
      weights: [3, 1]               # optional: one non-negative number per config (default: equal)
    - start: 200
      configs: [c.yaml]

A stage trains from its start to the iteration before the next one's. At a stage boundary the run's training
environments are made anew for the new mixture and reset (the episodes under way end there, uncounted), with the
seeds of the stage (`stage_seed`); the network, optimizer and random streams go on."""
import os
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

import yaml

from kage import mixture, resources

STAGE_KEYS = ("start", "configs", "weights")
MAX_SCHEDULE_BYTES = 1 << 20


@dataclass(frozen=True)
class Stage:
    start: int  # its first iteration, from 1
    configs: Tuple[str, ...]  # paths to open
    weights: Optional[Tuple[float, ...]] = None  # None: equal
    line: Optional[int] = field(default=None, compare=False)  # its start's line in a schedule file

    def describe(self) -> dict:
        return {"start": self.start, "configs": list(self.configs),
                "weights": None if self.weights is None else list(self.weights)}


class ScheduleError(ValueError):
    """A schedule or mixture that cannot train, with the one located line that says why and how to fix it."""


def stages_of(args) -> List[Stage]:
    """The run's stages from its flags (kage.ppo.args has checked that exactly one way is given)."""
    if args.train_schedule:
        return read_schedule(args.train_schedule)
    if args.train_config_paths:
        weights = None
        if args.train_weights:
            try:
                weights = tuple(float(w) for w in args.train_weights)
                mixture.weights_of(weights, len(args.train_config_paths))
            except ValueError as e:
                raise ScheduleError(f"--train-weights: {e}") from None
        return [Stage(1, tuple(args.train_config_paths), weights)]
    return [Stage(1, (args.train_config_path,))]


def stage_at(stages: Sequence[Stage], iteration: int) -> int:
    """The index of the stage that trains `iteration` (iteration 0, before the first, is the first stage's)."""
    index = 0
    for i, stage in enumerate(stages):
        if stage.start <= max(iteration, 1):
            index = i
    return index


def distinct_configs(stages: Sequence[Stage]) -> List[str]:
    """Every config the stages train on, once each, in order of first appearance."""
    seen: List[str] = []
    for stage in stages:
        for config in stage.configs:
            if config not in seen:
                seen.append(config)
    return seen


def is_mixture(stages: Sequence[Stage]) -> bool:
    """Whether the run trains on anything but one config: its training batch is then a mixture."""
    return len(stages) > 1 or len(stages[0].configs) > 1


def stage_seed(seed: int, stage: int) -> int:
    """The seed of stage `stage`'s training environments (kage.env_seeds): the run's seed for the first stage,
    a distinct one for each later stage, below 2**63."""
    return seed if stage == 0 else (seed + stage * 0x9E3779B97F4A7C15) % (1 << 63)


def check_iterations(stages: Sequence[Stage], num_iterations: int, where: str) -> None:
    """Refuses a stage that starts after the run's last iteration: it would never train."""
    late = [(i, s) for i, s in enumerate(stages) if s.start > num_iterations]
    if late:
        i, stage = late[0]
        at = f"{where}:{stage.line}: stages[{i}].start {stage.start}" if stage.line else \
            f"{where}: a stage starts at iteration {stage.start}"
        raise ScheduleError(f"{at}, but the run has {num_iterations} iterations: start it earlier, or raise "
                            "--total-timesteps")


# ---- the schedule file ----

def read_schedule(path: str) -> List[Stage]:
    """A schedule file's stages, each config resolved to a path to open. ScheduleError naming the file, the line
    and the key for anything else."""
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_SCHEDULE_BYTES + 1)
    except OSError as e:
        raise ScheduleError(f"--train-schedule {path}: {e.strerror or e}: give a YAML schedule file") from None
    if len(data) > MAX_SCHEDULE_BYTES:
        raise ScheduleError(f"{path}: larger than {MAX_SCHEDULE_BYTES} bytes: not a schedule")
    try:
        text = data.decode("utf-8")
        root = yaml.compose(text, Loader=yaml.SafeLoader)
        value = yaml.safe_load(text)
    except (UnicodeDecodeError, yaml.YAMLError) as e:
        mark = getattr(e, "problem_mark", None)
        line = f":{mark.line + 1}" if mark else ""
        raise ScheduleError(f"{path}{line}: not YAML ({getattr(e, 'problem', None) or e}): write the schedule as a "
                            "YAML list of stages") from None
    if not isinstance(value, list) or not value:
        raise ScheduleError(f"{path}:{_line(root) if root is not None else 1}: a schedule is a YAML list of stages "
                            "(each with start, configs and optional weights)")
    duplicate = _duplicate_key(root)
    if duplicate is not None:
        raise ScheduleError(f"{path}:{_line(duplicate)}: key {duplicate.value!r} appears twice in one mapping: YAML "
                            "would keep only the last; write each key once")
    base = os.path.dirname(os.path.abspath(path))
    stages: List[Stage] = []
    for i, (node, stage) in enumerate(zip(root.value, value)):
        stages.append(_stage(path, base, i, node, stage))
        if i == 0 and stages[0].start != 1:
            raise ScheduleError(f"{path}:{_line(_child(node, 'start'))}: stages[0].start is {stages[0].start}: the "
                                "first stage starts at iteration 1")
        if i > 0 and stages[i].start <= stages[i - 1].start:
            raise ScheduleError(f"{path}:{_line(_child(node, 'start'))}: stages[{i}].start {stages[i].start} is not "
                                f"after stages[{i - 1}].start {stages[i - 1].start}: list the stages in order of start")
    return stages


def _stage(path: str, base: str, i: int, node, stage) -> Stage:
    where = f"{path}:{_line(node)}: stages[{i}]"
    if not isinstance(stage, dict):
        raise ScheduleError(f"{where}: a stage is a mapping with start, configs and optional weights")
    unknown = [k for k in stage if k not in STAGE_KEYS]
    if unknown:
        raise ScheduleError(f"{path}:{_line(_key(node, unknown[0]))}: stages[{i}]: unknown key {unknown[0]!r}: a "
                            f"stage has {', '.join(STAGE_KEYS)}")
    start = stage.get("start")
    if "start" not in stage or not isinstance(start, int) or isinstance(start, bool) or start < 1:
        raise ScheduleError(f"{path}:{_line(_child(node, 'start') or node)}: stages[{i}].start: "
                            f"{'missing' if 'start' not in stage else repr(start)}: the stage's first iteration, an "
                            "integer >= 1")
    configs = stage.get("configs")
    if not isinstance(configs, list) or not configs or not all(isinstance(c, str) and c for c in configs):
        raise ScheduleError(f"{path}:{_line(_child(node, 'configs') or node)}: stages[{i}].configs: a list of one "
                            "or more config paths (relative to this file) or shipped configs' names")
    resolved = []
    for j, config in enumerate(configs):
        candidate = os.path.join(base, config)
        try:
            resolved.append(candidate if os.path.exists(candidate) else resources.config_path(config))
        except FileNotFoundError:
            item = _child(node, "configs").value[j]
            raise ScheduleError(f"{path}:{_line(item)}: stages[{i}].configs[{j}] {config!r}: not found (relative to "
                                f"{base}, or a shipped config's name): fix the path") from None
    weights = stage.get("weights")
    if "weights" in stage:
        weights_node = _child(node, "weights")
        if weights is None:  # `weights:` with no value would read as equal weights
            raise ScheduleError(f"{path}:{_line(weights_node)}: stages[{i}].weights: no value: a list of "
                                f"{len(configs)} non-negative numbers, one per config, or leave the key out for "
                                "equal weights")
        try:
            mixture.weights_of(weights, len(configs))
        except mixture.WeightsError as e:
            at = weights_node
            if e.index is not None and isinstance(weights_node, yaml.SequenceNode):
                at = weights_node.value[e.index]
            raise ScheduleError(f"{path}:{_line(at)}: stages[{i}].{e}") from None
        weights = tuple(float(w) for w in weights)
    return Stage(start, tuple(resolved), weights, _line(_child(node, "start")))


def _line(node) -> int:
    return node.start_mark.line + 1


def _duplicate_key(node):
    """The first key node that repeats a key of its mapping, anywhere under `node`, or None (as kagec's
    yaml-duplicate-key rule, which the suite's copy of a schedule meets)."""
    if isinstance(node, yaml.MappingNode):
        seen = set()
        for key, value in node.value:
            if getattr(key, "value", None) in seen:
                return key
            seen.add(getattr(key, "value", None))
            found = _duplicate_key(value)
            if found is not None:
                return found
    elif isinstance(node, yaml.SequenceNode):
        for item in node.value:
            found = _duplicate_key(item)
            if found is not None:
                return found
    return None


def _key(node, name: str):
    """The key node `name` of a mapping node."""
    return next((k for k, _ in node.value if getattr(k, "value", None) == name), node)


def _child(node, name: str):
    """The value node of key `name` in a mapping node, or None."""
    if not isinstance(node, yaml.MappingNode):
        return None
    return next((v for k, v in node.value if getattr(k, "value", None) == name), None)
