"""python3 -m kage.bench status DIR: where a benchmark stands, from the files its processes write (any
number of them, on any hosts: a Slurm array, GPU workers, plain runs): runs done, running (with their steps and
the time left at their rate), failed (with the last error of each), stopped or killed (they resume when run
again), and not started."""
import json
import os
import socket
import time
from typing import Dict, List, TextIO

from kage.bench import run_state
from kage.bench.records import bench_problem
from kage.bench.run import checkpoint_iteration
from kage.bench.tasks import last_progress, run_dir
from kage.util.files import process_alive, read_json_record, read_regular
from kage.util.text import plural

ORDER = ("done", "running", "failed", "interrupted", "not started")


def progress(path: str) -> str:
    """A running run's steps so far and what is left at its rate, from its metrics.jsonl and run.json ("" before
    its first training row, or where run.json names no total)."""
    step, rate = last_progress(os.path.join(path, "metrics.jsonl"))
    try:
        total = json.loads(read_regular(os.path.join(path, "run.json")))["args"]["total_timesteps"]
    except (OSError, ValueError, KeyError, TypeError, RecursionError):  # absent, damaged, not a run description
        return ""
    if not rate or not isinstance(total, int) or total <= 0:
        return ""
    left = max(total - step, 0) / rate / 60
    return f"step {step:,} of {total:,}, about {left:,.0f} min left at its {rate:,.0f} steps/s; "


def classify(path: str, now: float) -> tuple:
    """(category, detail) of one run directory."""
    if os.path.exists(os.path.join(path, "summary.json")):
        return "done", ""
    iteration = checkpoint_iteration(path)
    at = f"checkpoint at iteration {iteration}" if iteration else "no checkpoint yet"
    try:
        state = run_state.read(path)
    except run_state.Damaged as e:
        return "interrupted", (f"{os.path.join(path, run_state.STATE_FILE)} is damaged ({e}); it is rewritten when "
                               f"the run runs again; {at}")
    if state is None:
        return ("interrupted", at) if iteration else ("not started", "")
    where = f"host {state['host']}" + (f", task {state['task']}" if state.get("task") is not None else "") + \
        (f", GPU {state['gpu']}" if state.get("gpu") else "") + \
        (f", Slurm job {state['slurm_job']}" if state.get("slurm_job") else "")
    age = now - state["time"]
    if age < -run_state.STALE_S:  # written by a host whose clock runs ahead (or damaged): no heartbeat to trust
        return "interrupted", (f"its state was written {-age / 60:,.0f} min in the future (another host's clock?); "
                               f"{at}; {where}")
    if state["state"] == "running" and age <= run_state.STALE_S:
        pid = state.get("pid")
        if state["host"] == socket.gethostname() and isinstance(pid, int) and not process_alive(pid):
            return "interrupted", f"its runner (pid {pid}, this host) is gone (killed?); {at}; {where}"
        return "running", f"{progress(path)}{at}; {where}"
    if state["state"] == "failed":
        return "failed", (f"exit {state.get('exit_code', '?')} ({where}, log {state.get('log', '?')}): "
                          f"{state.get('error', '?')}")
    if state["state"] == "running":
        return "interrupted", f"no heartbeat for {age / 60:,.0f} min (killed?); {at}; {where}"
    if state["state"] == "stopped":
        return "interrupted", f"stopped {age / 60:,.0f} min ago; {at}; {where}"
    if state["state"] != "done":
        return "interrupted", f"state {state['state']!r}, not one kage.bench run writes; {at}; {where}"
    return "interrupted", f"{at}; {where}"  # "done" without summary.json: ended early


def status(bench_dir: str, out: TextIO) -> Dict[str, List[str]]:
    """Prints the benchmark's state; returns category -> the runs in it."""
    path = os.path.join(bench_dir, "bench.json")
    try:
        bench, problem = read_json_record(path, lambda value: bench_problem(value, ("units", "seeds")))
    except FileNotFoundError:
        raise SystemExit(f"{path}: error: no such file: {bench_dir} is not a directory written by python3 -m "
                         "kage.bench run (or slurm): give the --out of a benchmark") from None
    except OSError as e:
        problem = e.strerror or str(e)
    if problem:
        raise SystemExit(f"{path}: error: {problem}: not a directory written by python3 -m kage.bench run (or slurm), "
                         "or that file is damaged (restore it, or run the benchmark's command again to rewrite it)")
    now = time.time()
    found: Dict[str, List[tuple]] = {c: [] for c in ORDER}
    for unit in bench["units"]:
        for seed in bench["seeds"]:
            category, detail = classify(run_dir(bench_dir, unit, seed), now)
            found[category].append((f"{unit} seed {seed}", detail))
    total = sum(map(len, found.values()))
    out.write(f"{bench_dir}: {plural(total, 'run')}: " + ", ".join(f"{len(found[c])} {c}" for c in ORDER) + "\n")
    for category in ORDER[1:-1]:
        if found[category]:
            out.write(f"{category}:\n" + "".join(f"  {name}: {detail}\n" for name, detail in found[category]))
    if found["interrupted"]:
        out.write("interrupted runs resume from their checkpoints when their task runs again "
                  "(kage.bench run, or the Slurm array task)\n")
    return {c: [name for name, _ in runs] for c, runs in found.items()}
