"""Stopping on request: SIGTERM (a scheduler's preemption, `timeout`, `kill`) or SIGINT (Ctrl-C) lets the
running iteration finish, then the trainer checkpoints and exits, so a rerun resumes with nothing lost.
A second Ctrl-C stops at once (the run then resumes from its previous checkpoint); a repeated SIGTERM
changes nothing, since schedulers and kage.bench may both send one. The runners stop their child processes
through stop_children, and a child started with child_environment() stops with its runner however the runner
ends (die_with_parent)."""
import ctypes
import os
import signal
import subprocess
import sys
from typing import Dict, List, Optional

SIGNALS = (signal.SIGTERM, signal.SIGINT)
PARENT_ENV = "KAGE_PARENT_PID"  # set by a runner for its children: the process whose death stops them
_PR_SET_PDEATHSIG = 1


class StopRequest:
    """Notes the first SIGTERM/SIGINT while active (a context manager; handlers restored on exit)."""

    def __init__(self, who: str, then: str):
        self.who, self.then = who, then
        self.signum: Optional[int] = None
        self._previous = {}

    def __enter__(self) -> "StopRequest":
        for s in SIGNALS:
            self._previous[s] = signal.signal(s, self._note)
        return self

    def __exit__(self, *exc) -> None:
        for s, handler in self._previous.items():
            signal.signal(s, handler)

    def _note(self, signum: int, frame) -> None:
        if self.signum is not None:
            if signum == signal.SIGINT:
                raise KeyboardInterrupt
            return
        self.signum = signum
        print(f"{self.who}: {signal.Signals(signum).name}: {self.then} (Ctrl-C again to stop at once)",
              file=sys.stderr, flush=True)

    @property
    def requested(self) -> bool:
        return self.signum is not None

    @property
    def exit_code(self) -> int:
        return 128 + (self.signum or 0)  # the shell's convention for "ended by signal N"



def child_environment(**extra: str) -> Dict[str, str]:
    """The environment of a runner's child process: die_with_parent() in the child then ties it to this process."""
    return {**os.environ, PARENT_ENV: str(os.getpid()), **extra}


def die_with_parent() -> None:
    """In a runner's child (PARENT_ENV set): asks the kernel for a SIGTERM when the runner ends, even by SIGKILL
    or with its whole process group, so that no trainer goes on writing a run nobody watches (Linux; a no-op
    elsewhere). SIGTERM lets a trainer checkpoint first. A runner already gone by now stops this process at once."""
    parent = os.environ.get(PARENT_ENV)
    if not parent or not parent.isdigit():
        return
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0) != 0:
            return
    except (OSError, AttributeError):
        return
    if os.getppid() != int(parent):
        os.kill(os.getpid(), signal.SIGTERM)


def stop_children(children: List[subprocess.Popen], grace_s: float = 180) -> None:
    """SIGTERM to each running child (a trainer then checkpoints after its running iteration, an evaluation
    point included; a `kage.bench run --task` process stops its trainer the same way), then SIGKILL to any
    still running after `grace_s`: a run resumes from its last checkpoint either way. Further SIGTERMs to
    this process are ignored meanwhile, so a repeated scancel cannot cut the wait short."""
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    for child in children:
        if child.poll() is None:
            child.terminate()
    for child in children:
        try:
            child.wait(timeout=grace_s)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()
