"""What the runner knows about each run of a benchmark, for `kage.bench status`: RUN_DIR/bench_state.json
holds "running" (with a heartbeat the runner refreshes while the run trains), "failed" (exit code, log,
the log's last error line) or "stopped" (the runner was told to stop: Slurm's scancel, preemption, Ctrl-C).
A run whose heartbeat is older than STALE_S was killed without a word (SIGKILL, a lost node); a run with
summary.json is finished whatever its state file says."""
import json
import math
import os
import socket
import time
from typing import List, Optional

from kage.util.files import LOG_LIMIT, NotRegularFile, open_regular, read_regular, write_json

STATE_FILE = "bench_state.json"
HEARTBEAT_S = 30.0
STALE_S = 4 * HEARTBEAT_S


def where() -> dict:
    """The host, process and device a run is trained by."""
    return {"host": socket.gethostname(), "pid": os.getpid(), "gpu": os.environ.get("CUDA_VISIBLE_DEVICES"),
            "slurm_job": os.environ.get("SLURM_ARRAY_JOB_ID") or os.environ.get("SLURM_JOB_ID")}


def mark(run_dirs: List[str], state: str, **details) -> None:
    for run_dir in run_dirs:
        write_json(os.path.join(run_dir, STATE_FILE), {"state": state, "time": time.time(), **where(), **details})


def last_error(log_path: str) -> str:
    """The last non-empty line of a log: a traceback's exception, or kage.ppo.train's message."""
    try:
        with open_regular(log_path, LOG_LIMIT) as f:
            f.seek(max(0, os.fstat(f.fileno()).st_size - 16384))
            lines = [line.strip() for line in f.read(16384).decode(errors="replace").splitlines() if line.strip()]
    except OSError as e:
        return f"(no log: {e.strerror})"
    return lines[-1][:500] if lines else "(the log is empty)"


class Damaged(Exception):
    """A state file that exists but is not one (not JSON, or without its keys): what is wrong with it."""


# The keys every state has, with their types; the others depend on the state.
_REQUIRED = {"state": str, "time": (int, float), "host": str}


def read(run_dir: str) -> Optional[dict]:
    """The run's state, None where it has none; Damaged for a file that is not a state."""
    try:
        state = json.loads(read_regular(os.path.join(run_dir, STATE_FILE)))
    except FileNotFoundError:
        return None
    except NotRegularFile as e:  # a FIFO or a device, which reading would wait on or never finish
        raise Damaged(e.strerror) from None
    except (OSError, ValueError, RecursionError) as e:
        raise Damaged(str(e)) from None
    if not isinstance(state, dict):
        raise Damaged(f"a JSON {type(state).__name__}, not an object")
    for key, kind in _REQUIRED.items():
        if not isinstance(state.get(key), kind) or isinstance(state.get(key), bool):
            raise Damaged(f"no valid '{key}'")
    if not math.isfinite(state["time"]):
        raise Damaged(f"'time' is {state['time']}, not a time")
    return state
