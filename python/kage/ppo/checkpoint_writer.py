"""Checkpoints written on a thread of their own, so that training goes on while a pack's files are encoded, synced
and renamed into place: about 0.25 s a run of the baseline's network (58 MB) on a CPU machine, which a pack of 5
waited for every 50 iterations (the iteration after a checkpoint took 1.2 s more than the others, 5 % of a DrAC
task's training; lab/2026-11-29-h200x2-drac-overlay-loo-tasks).

The files hold what the runs held when the checkpoint was asked for: the caller hands over copies, never the
tensors that training goes on changing. One batch of files at a time: a new batch waits for the last to land, so a
run's files never land out of order, and what stopped the last (a full disk) is raised in the training thread at
the next checkpoint, at `wait`, or when the writer closes."""
import sys
import threading
from typing import Callable, List, Optional


class CheckpointWriter:
    def __init__(self):
        self._thread: Optional[threading.Thread] = None
        self._error: Optional[BaseException] = None

    def submit(self, writes: List[Callable[[], None]]) -> None:
        """Starts `writes` (each writes one run's files) once the last batch has landed."""
        self.wait()
        self._thread = threading.Thread(target=self._write, args=(writes,), name="kage-checkpoints")
        self._thread.start()

    def _write(self, writes: List[Callable[[], None]]) -> None:
        try:
            for write in writes:
                write()
        except BaseException as e:  # raised in the training thread by wait()
            self._error = e

    def wait(self) -> None:
        """Returns once the last batch has landed; raises what stopped it."""
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        if self._error is not None:
            error, self._error = self._error, None
            raise error

    def __enter__(self) -> "CheckpointWriter":
        return self

    def __exit__(self, kind, value, traceback) -> None:
        if kind is None:
            self.wait()
            return
        # Another error is on its way out: the files in flight still land before the run directories unlock, and
        # their own error is named beside it rather than in its place.
        try:
            self.wait()
        except BaseException as e:
            print(f"kage.ppo.train: also, a checkpoint could not be written: {e}", file=sys.stderr, flush=True)
