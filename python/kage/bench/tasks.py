"""The task table of a benchmark: the suite's runs, (unit, seed) in manifest order, in tasks of up to K runs
(--pack K) that one process trains together. A task index names the same runs wherever it is decoded (a
Slurm array task, a GPU worker, `kage.bench run --task I`): the table is a pure function of the units, the
seeds and K, and DIR/tasks.json records it for `kage.bench status`."""
import os
from typing import Dict, List, Sequence, Tuple

from kage.util.files import write_json

Job = Tuple[object, int, str]  # (units.Unit, seed, run directory)


def run_dir(out: str, unit_name: str, seed: int) -> str:
    return os.path.join(out, "runs", unit_name, f"seed_{seed}")


def task_table(units: Sequence, seeds: Sequence[int], pack: int, out: str) -> List[List[Job]]:
    """Runs that evaluate the same number of configs share tasks (a pack steps in lockstep); within that,
    manifest order, seeds innermost."""
    groups: Dict[int, List[Job]] = {}
    for unit in units:
        for seed in seeds:
            groups.setdefault(len(unit.evals), []).append((unit, seed, run_dir(out, unit.name, seed)))
    return [group[i:i + pack] for group in groups.values() for i in range(0, len(group), pack)]


def describe(task: List[Job]) -> str:
    return ", ".join(f"{unit.name} seed {seed}" for unit, seed, _ in task)


def write_task_table(out: str, table: List[List[Job]], pack: int) -> None:
    write_json(os.path.join(out, "tasks.json"), {
        "pack": pack, "tasks": [[{"unit": unit.name, "seed": seed} for unit, seed, _ in task] for task in table]})


def is_finished(job: Job) -> bool:
    return os.path.exists(os.path.join(job[2], "summary.json"))
