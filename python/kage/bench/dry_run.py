"""kage.bench run --dry-run: the task table a benchmark would train, and how --gpus would share it, without
training or writing anything: for choosing --pack and --tasks so that a lease's GPUs end together."""
from typing import List, Optional

from kage.bench import gpus, tasks
from kage.util.text import plural


def describe(bench, devices: Optional[List[int]], only: Optional[List[gpus.Group]]) -> str:
    """The task table of `bench`, then, for the GPUs `devices` (the indices --gpus names), the tasks each would
    train (longest first; tasks joined by '+' as one) and its share of the busiest GPU's work."""
    table = bench.table()
    lines = [f"kage.bench run --dry-run: {plural(len(table), 'task')}, {plural(sum(map(len, table)), 'run')} "
             f"(--pack {bench.pack}"
             f"{', --share-training' if bench.share_training else ''}"
             f"{', --mix-eval-counts' if bench.mix_eval_counts else ''}); nothing trained or written"]
    for i, task in enumerate(table):
        units = sorted({unit.name for unit, _, _ in task})
        counts = sorted({1 + len(unit.evals) for unit, _, _ in task})
        configs = f"{counts[0]}" if len(counts) == 1 else f"{counts[0]}-{counts[-1]}"
        lines.append(f"task {i}: {plural(len(task), 'run')} x {configs} configs, weight {gpus.task_weight(task)}: "
                     f"{', '.join(units)}")
    if devices:
        order = gpus.longest_first(table, only if only is not None else gpus.every_task(table))
        taken, loads = gpus.hand_out([gpus.task_weight(gpus.group_jobs(table, group)) for group in order],
                                     [0] * len(devices))
        busiest = max(loads) or 1
        lines.append(f"on {plural(len(devices), 'GPU')}, longest first (weight: a run's evaluation of one config, "
                     f"a run's training counting {gpus.TRAINING_AS_CONFIGS}):")
        for g, worker, load in zip(devices, taken, loads):
            names = f"{'task' if len(worker) == 1 else 'tasks'} {', '.join(gpus.group_name(order[j]) for j in worker)}"
            lines.append(f"  GPU {g}: {names if worker else 'no task'}, weight {load} "
                         f"({100 * load / busiest:.0f} % of the busiest)")
    return "\n".join(lines)


def devices_of(text: str) -> List[int]:
    """--gpus for a dry run: the indices of a list, or 'all': this machine's GPUs (none needed for a list)."""
    if text == "all":
        count = gpus.device_count()
        if count == 0:
            raise SystemExit("kage.bench run --dry-run: --gpus all, but torch sees no CUDA GPU here: give the lease's "
                             "GPUs as a list, e.g. --gpus 0,1,2,3")
        return list(range(count))
    return gpus.index_list("--gpus", text, 1 << 16, "use 'all' or GPU indices like 0,2", "indices are")


def tasks_of(text: Optional[str], table: List[List[tasks.Job]]) -> Optional[List[gpus.Group]]:
    """--tasks for a dry run: checked against the table, as the runner checks them."""
    if text is None:
        return None
    return gpus.group_list("--tasks", text, len(table), "a list like 0,3,4, or 3+4 to train tasks 3 and 4 as one",
                           "the task table's indices are")
