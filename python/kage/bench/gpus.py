"""kage.bench run --gpus all|0,2,...: every GPU of one host busy until the benchmark is done. One worker per
GPU takes the longest unfinished task left (task_weight: its runs times the configs each evaluates, plus its
training), so that the GPUs finish together, and trains it in a child process
(`kage.bench run ... --task I`, its log in DIR/tasks/task_<I>.log) that sees that GPU alone, until no task
is left: the same tasks as a Slurm array, resumable the same way, one report. Tasks joined by `+` in --tasks
(`12+13`) train as one: one process, one pack of all their runs (a GPU that one task's pack leaves idle), each
task still the table's own. As each task ends it prints the tasks left and an ETA: the running tasks' ends at
the rates their runs have trained at (their metrics.jsonl), the waiting tasks' by weight at the seconds per unit
of weight the finished ones took.

KAGE_BENCH_FAKE_GPUS=N stands for N GPUs that do not exist, for testing the scheduler on a machine without
one (with --device cpu): `all` means 0..N-1 and each worker's CUDA_VISIBLE_DEVICES names its fake device."""
import heapq
import os
import re
import signal
import subprocess
import sys
import threading
import time
from typing import List, Optional, Tuple

from kage.bench import tasks
from kage.util.stop import child_environment, stop_children
from kage.util.text import plural

FAKE_GPUS = "KAGE_BENCH_FAKE_GPUS"


def device_count() -> int:
    fake = os.environ.get(FAKE_GPUS)
    if fake is not None:
        if not fake.isdigit():
            raise SystemExit(f"kage.bench run: {FAKE_GPUS}={fake!r}: a number of fake GPUs (for tests)")
        return int(fake)
    import torch
    return torch.cuda.device_count()


def parse_gpus(text: str, trainer_device: str) -> List[str]:
    """'all' or '0,2' -> the CUDA_VISIBLE_DEVICES value of each worker. Indices count the GPUs this process
    sees, so under an outer CUDA_VISIBLE_DEVICES (a Slurm allocation) index 0 is its first GPU."""
    count = device_count()
    if count == 0:
        raise SystemExit("kage.bench run: --gpus, but torch sees no CUDA GPU: run without --gpus (one process)")
    if trainer_device != "cuda" and os.environ.get(FAKE_GPUS) is None:
        raise SystemExit(f"kage.bench run: --gpus trains on the GPUs: remove --device {trainer_device}, or --gpus")
    indices = list(range(count)) if text == "all" else index_list(
        "--gpus", text, count, "use 'all' or GPU indices like 0,2", "this machine's GPUs are")
    outer = os.environ.get("CUDA_VISIBLE_DEVICES")
    visible = outer.split(",") if outer and os.environ.get(FAKE_GPUS) is None else None
    return [visible[i] if visible else str(i) for i in indices]


# A run's training costs about as much as evaluating this many configs over its 32 evaluation points, since the
# evaluation steps on the device: on 4 x H200 (lab/2026-11-29-h200x4-drac-random-conv-tasks-5-8) DrAC's packs of 5
# trained 160-167 s a run and evaluated 3.3-4.8 s a run and config (2 to 7 configs; 35-48 to one), the baseline's
# trainer 202 s a run in packs of 2 against 5.5 s (37). (The table's packs, evaluated from the host: 6-13.)
TRAINING_AS_CONFIGS = 40


def task_weight(task: List[tasks.Job]) -> int:
    """A task's expected time in units of one run's evaluation of one config: per run, its configs (the train
    config and its eval configs) plus its training (TRAINING_AS_CONFIGS)."""
    return sum(1 + len(unit.evals) + TRAINING_AS_CONFIGS for unit, _, _ in task)


Group = List[int]  # task indices trained as one (--tasks 12+13), most often one


def group_jobs(table: List[List[tasks.Job]], group: Group) -> List[tasks.Job]:
    return [job for index in group for job in table[index]]


def group_name(group: Group) -> str:
    """[12, 13] -> '12+13', as --task and --tasks take it and as the group's logs and pack files are named."""
    return "+".join(map(str, group))


def every_task(table: List[List[tasks.Job]]) -> List[Group]:
    return [[index] for index in range(len(table))]


def longest_first(table: List[List[tasks.Job]], groups: List[Group]) -> List[Group]:
    """The groups of tasks, the heaviest first (task_weight), ties in table order: the
    longest-processing-time-first schedule, whose GPUs end close together."""
    return sorted(groups, key=lambda group: -task_weight(group_jobs(table, group)))


def hand_out(durations: List[float], free_at: List[float]) -> Tuple[List[List[int]], List[float]]:
    """The waiting tasks (their durations, in the order they are handed out) each taken by the first worker to come
    free (workers free at `free_at`; ties to the lowest index), as run_on_gpus does: each worker's task indices,
    and when it ends."""
    free = [(at, worker) for worker, at in enumerate(free_at)]
    heapq.heapify(free)
    taken: List[List[int]] = [[] for _ in free_at]
    ends = list(free_at)
    for index, duration in enumerate(durations):
        at, worker = heapq.heappop(free)
        taken[worker].append(index)
        ends[worker] = at + duration
        heapq.heappush(free, (ends[worker], worker))
    return taken, ends


# The share of its training a running task must have done in this process before its own rate, rather than its
# weight, says when it ends: past its start (the kernels compiled, the batches opened) and its first iterations.
MEASURED_PROGRESS = 0.02


def running_rest(unit_seconds: float, weight: int, elapsed: float, done_before: float, done_now: float) -> float:
    """Seconds left of a running task: at the rate its runs have trained at so far in this process (from done_before
    to done_now, shares of its training, in `elapsed` seconds), or, before that says much, as its weight says.
    The weights' estimate errs by whole minutes where the pack size or the method changes what a run costs."""
    gained = done_now - done_before
    if gained >= MEASURED_PROGRESS:
        return elapsed * (1.0 - done_now) / gained
    return max(weight * unit_seconds - elapsed, 0.0)


def eta_seconds(unit_seconds: float, waiting: List[int], running: List[tuple], workers: int) -> float:
    """Seconds until the last task ends if a waiting task of weight w takes w * unit_seconds: the running tasks
    ((weight, seconds elapsed, share done when it began, share done now) each, running_rest) end first, and the
    workers take the waiting tasks (their weights, in the order they are handed out) as they come free."""
    free = [running_rest(unit_seconds, *task) for task in running]
    free += [0.0] * (workers - len(free))
    return max(hand_out([weight * unit_seconds for weight in waiting], free)[1])


def parse_tasks(text: Optional[str], count: int, out: str, flag: str = "--tasks") -> Optional[List[Group]]:
    """--tasks '0,3+4' -> [[0], [3, 4]]: indices of the task table of `count` tasks, those joined by '+' trained
    as one (None: every task, each alone)."""
    if text is None:
        return None
    table = os.path.join(out, "tasks.json")
    see = f"see {table}" if os.path.isfile(table) else "--dry-run lists them"
    return group_list(flag, text, count, f"use task indices like 0,3,4, or 3+4 to train tasks 3 and 4 as one ({see})",
                      f"the task table of {out} has {count} tasks,", f" ({see})")


def group_list(flag: str, text: str, count: int, usage: str, extent: str, see: str = "") -> List[Group]:
    """`flag`'s '0,2+3' -> [[0], [2, 3]]: groups of distinct indices below `count` (those joined by '+' one
    group), or an error naming the flag and the fix."""
    groups = [item.split("+") for item in text.split(",")]
    if not all(re.fullmatch("[0-9]+", part) for group in groups for part in group):  # int() takes ' 1', '1_0'
        raise SystemExit(f"kage.bench run: {flag} {text}: {usage}")
    groups = [[int(part) for part in group] for group in groups]
    indices = [index for group in groups for index in group]
    if any(not 0 <= i < count for i in indices) or len(set(indices)) != len(indices):
        raise SystemExit(f"kage.bench run: {flag} {text}: {extent} 0 to {count - 1}, each named once{see}")
    return groups


def index_list(flag: str, text: str, count: int, usage: str, extent: str, see: str = "") -> List[int]:
    """`flag`'s '0,2' -> [0, 2]: distinct indices below `count`, or an error naming the flag and the fix."""
    if "+" in text:
        raise SystemExit(f"kage.bench run: {flag} {text}: {usage}")
    return [index for group in group_list(flag, text, count, usage, extent, see) for index in group]


def run_on_gpus(bench, table: List[List[tasks.Job]], devices: List[str], only: Optional[List[Group]] = None) -> int:
    """Trains the unfinished tasks of `table` (or of `only`, groups of task indices, each trained as one), one
    worker per device; prints each group's start and end."""
    chosen = every_task(table) if only is None else only
    unfinished = [group for group in chosen if not all(map(tasks.is_finished, group_jobs(table, group)))]
    todo = longest_first(table, unfinished)
    finished = sum(all(map(tasks.is_finished, task)) for task in table)
    scope = "" if only is None else f" (of tasks {','.join(map(group_name, only))})"
    print(f"kage.bench run: {plural(len(table), 'task')}, {finished} finished earlier; {len(todo)} to train{scope} on "
          f"GPUs {','.join(devices)}", file=sys.stderr, flush=True)
    log_dir = os.path.join(bench.out, "tasks")
    os.makedirs(log_dir, exist_ok=True)
    lock = threading.Lock()
    children = {}
    failed: List[Group] = []
    stopping = threading.Event()
    began = {}  # device -> (its group's jobs, weight, when it began, share of its training done then)
    finished_time, finished_weight = [0.0], [0]  # of tasks trained to the end: a stopped task says nothing

    def worker(device: str) -> None:
        while True:
            with lock:
                if stopping.is_set() or not todo:
                    return
                group = todo.pop(0)
                name, jobs = group_name(group), group_jobs(table, group)
                print(f"[gpu {device}] task {name}: {tasks.describe(jobs)}", file=sys.stderr, flush=True)
                log = open(os.path.join(log_dir, f"task_{name}.log"), "ab")
                began[device] = (jobs, task_weight(jobs), time.monotonic(),
                                 tasks.task_progress(jobs, bench.steps_per_run))
                children[device] = subprocess.Popen([*bench.run_command(), "--task", name], stdout=log,
                                                    stderr=log, env=child_environment(CUDA_VISIBLE_DEVICES=device))
            code = children[device].wait()
            log.close()
            with lock:
                now = time.monotonic()
                if code == 0:
                    finished_time[0] += now - began[device][2]
                    finished_weight[0] += began[device][1]
                if code != 0 and not stopping.is_set():
                    failed.append(group)
                running = [(weight, now - start, done_before, tasks.task_progress(running_jobs, bench.steps_per_run))
                           for d, (running_jobs, weight, start, done_before) in began.items()
                           if children[d].poll() is None]
                left = len(todo) + len(running)
                eta = ""
                if finished_weight[0] and not stopping.is_set():
                    unit_seconds = finished_time[0] / finished_weight[0]
                    waiting = [task_weight(group_jobs(table, group)) for group in todo]
                    eta = f" · ETA {eta_seconds(unit_seconds, waiting, running, len(devices)) / 60:,.0f} min"
                status = ("done" if code == 0 else "stopped" if stopping.is_set()
                          else f"FAILED (exit {code}); see {log.name}")
                print(f"[gpu {device}] task {name}: {status} · tasks left {left}{eta}", file=sys.stderr, flush=True)

    threads = [threading.Thread(target=worker, args=(d,), daemon=True) for d in devices]
    for thread in threads:
        thread.start()
    try:
        while any(t.is_alive() for t in threads):
            time.sleep(0.5)
    except BaseException:  # Stop (SIGTERM) or Ctrl-C: the children stop their runs and keep the checkpoints
        stopping.set()
        with lock:
            running = list(children.values())
        stop_children(running)
        for thread in threads:
            thread.join(timeout=60)
        print("kage.bench run: stopped; run again to resume", file=sys.stderr, flush=True)
        return 128 + signal.SIGTERM
    if failed:
        print(f"kage.bench run: task(s) {', '.join(map(group_name, sorted(failed)))} failed (kage.bench status "
              f"{bench.out}); rerun to resume them", file=sys.stderr)
        return 1
    runs = sum(len(group_jobs(table, group)) for group in chosen)
    print(f"kage.bench run: {plural(runs, 'run')} in {bench.out}; tables and plots: python3 -m kage.bench report "
          f"{bench.out}", file=sys.stderr)
    return 0
