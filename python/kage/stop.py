"""Stopping on request: SIGTERM (a scheduler's preemption, `timeout`, `kill`) or SIGINT (Ctrl-C) lets the
running iteration finish, then the trainer checkpoints and exits, so a rerun resumes with nothing lost.
A second Ctrl-C stops at once (the run then resumes from its previous checkpoint); a repeated SIGTERM
changes nothing, since schedulers and kage.bench may both send one."""
import signal
import sys
from typing import Optional

SIGNALS = (signal.SIGTERM, signal.SIGINT)


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

