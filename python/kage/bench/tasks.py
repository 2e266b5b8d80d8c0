"""The task table of a benchmark: the suite's runs, (unit, seed) in manifest order, in tasks of up to K runs
(--pack K) that one process trains together. A task index names the same runs wherever it is decoded (a
Slurm array task, a GPU worker, `kage.bench run --task I`): the table is a pure function of the units, the
seeds and K, and DIR/tasks.json records it for `kage.bench status`."""
import json
import os
from typing import Dict, List, Sequence, Tuple

from kage.util.files import LOG_LIMIT, open_regular, write_json

Job = Tuple[object, int, str]  # (units.Unit, seed, run directory)


def run_dir(out: str, unit_name: str, seed: int) -> str:
    return os.path.join(out, "runs", unit_name, f"seed_{seed}")


def task_table(units: Sequence, seeds: Sequence[int], pack: int, out: str,
               mix_eval_counts: bool = False) -> List[List[Job]]:
    """Runs that evaluate the same number of configs share tasks, unless `mix_eval_counts` (--mix-eval-counts: a
    pack's evaluation pads each run to its runs' most configs, kage.ppo.evaluation, so that tasks of K runs in
    manifest order can end together); within that, manifest order, seeds innermost."""
    groups: Dict[int, List[Job]] = {}
    for unit in units:
        for seed in seeds:
            count = 0 if mix_eval_counts else len(unit.evals)
            groups.setdefault(count, []).append((unit, seed, run_dir(out, unit.name, seed)))
    return [group[i:i + pack] for group in groups.values() for i in range(0, len(group), pack)]


def describe(task: List[Job]) -> str:
    return ", ".join(f"{unit.name} seed {seed}" for unit, seed, _ in task)


def write_task_table(out: str, table: List[List[Job]], pack: int) -> None:
    write_json(os.path.join(out, "tasks.json"), {
        "pack": pack, "tasks": [[{"unit": unit.name, "seed": seed} for unit, seed, _ in task] for task in table]})


def is_finished(job: Job) -> bool:
    return os.path.exists(os.path.join(job[2], "summary.json"))


def last_progress(metrics_path: str):
    """The global step and steps/s of a run's last training row (0, None before the first)."""
    try:
        with open_regular(metrics_path, LOG_LIMIT) as f:
            f.seek(max(0, os.fstat(f.fileno()).st_size - 65536))
            lines = f.read(65536).decode(errors="replace").splitlines()
    except OSError:
        return 0, None
    for line in reversed(lines):
        try:
            row = json.loads(line)
        except (ValueError, RecursionError):
            continue
        if isinstance(row, dict) and row.get("kind") == "train" and \
                all(isinstance(row.get(k), (int, float)) for k in ("global_step", "charts/SPS")):
            return row["global_step"], row["charts/SPS"]
    return 0, None


def task_progress(task: List[Job], steps_per_run: int) -> float:
    """The share of a task's training done, 0 to 1: its runs' steps so far (their metrics.jsonl), a finished
    run's all of them, over its runs' steps in all."""
    done = sum(steps_per_run if is_finished(job) else min(last_progress(os.path.join(job[2], "metrics.jsonl"))[0],
                                                          steps_per_run) for job in task)
    return done / (steps_per_run * len(task))
