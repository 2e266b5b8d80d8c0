"""One writer per directory: a lock file that names its holder, works on shared file systems, and is taken
over from a holder that died instead of being waited on.

    DIR/<name>.lock   {"host", "pid", "proc_start", "started", "program", "token"} of the holder

Taking it: the holder's description is written to a temporary file, then hard-linked to the lock's name, which
fails if the name exists (atomic on local and network file systems alike, NFS included, where O_EXCL was not
always). The holder refreshes the file's modification time every HEARTBEAT_S seconds from a thread.

A holder is dead when it runs on this host and its process is gone (or its process id now names another
process: the start time differs), or when it runs on another host and its heartbeat is older than STALE_S
by the file system's clock. A dead holder's lock is taken over under a second lock (DIR/<name>.lock.break),
so that of two processes finding it dead only one takes it, and only if it is still the lock they found.
"""
import json
import os
import socket
import sys
import threading
import time
from typing import Optional

from kage.util.files import create_temporary, named_errors, process_alive, read_regular

HEARTBEAT_S = 30.0
STALE_S = 4 * HEARTBEAT_S
BREAK_STALE_S = 60.0  # a takeover takes milliseconds: a break lock this old is a dead breaker's


class LockHeld(Exception):
    """The directory has a live writer: the message names it and the ways out."""


def process_start(pid: int) -> Optional[str]:
    """The start time of process `pid` in clock ticks since boot (/proc/PID/stat, field 22), None where unknown."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[19]
    except (OSError, IndexError):
        return None


def boot_id() -> Optional[str]:
    try:
        with open("/proc/sys/kernel/random/boot_id") as f:
            return f.read().strip()
    except OSError:
        return None


class DirectoryLock:
    """DIR/NAME.lock, held from acquire() until release() (or this process's end)."""

    def __init__(self, directory: str, name: str, program: str):
        self.path = os.path.join(directory, f"{name}.lock")
        self.directory, self.program = directory, program
        self.token: Optional[str] = None
        self.lost = False  # set by the heartbeat when another process took the lock (this one was thought dead)
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None

    def acquire(self, way_out: str) -> None:
        """Takes the lock, or raises LockHeld naming the holder and `way_out` (what the user can do instead)."""
        for _ in range(3):
            if self._create():
                return self._start_heartbeat()
            holder = self.read()
            if holder is not None and self.alive(holder):
                raise LockHeld(self.describe(holder, way_out))
            if self._take_over(holder):
                return self._start_heartbeat()
        raise LockHeld(f"{self.path}: other processes are taking this lock at the same time; try again")

    def release(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        holder = self.read()
        if holder is not None and holder.get("token") == self.token:
            try:
                os.unlink(self.path)
            except FileNotFoundError:
                pass
        self.token = None

    def __enter__(self) -> "DirectoryLock":
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    def read(self) -> Optional[dict]:
        """The holder's description; {} for a lock whose content cannot be read; None when there is no lock."""
        try:
            text = read_regular(self.path, 1 << 20)  # a FIFO or a device reads as no holder, never waited on
        except FileNotFoundError:
            return None
        except OSError:
            return {}
        try:
            holder = json.loads(text)
        except (ValueError, RecursionError):
            return {}
        return holder if isinstance(holder, dict) else {}

    def alive(self, holder: dict) -> bool:
        if holder.get("host") == socket.gethostname() and holder.get("boot_id") == boot_id():
            pid = holder.get("pid")
            if not isinstance(pid, int) or not process_alive(pid):
                return False
            start = process_start(pid)
            return start is None or holder.get("proc_start") in (None, start)
        return self._heartbeat_age() <= STALE_S

    def describe(self, holder: dict, way_out: str) -> str:
        age = self._heartbeat_age()
        if not isinstance(holder.get("pid"), int) or not isinstance(holder.get("host"), str):
            # Not a lock this program wrote (damaged, or made by hand): nobody can be named as its holder.
            return (f"{self.directory} has a lock that names no writer ({self.path}, changed {age:,.0f} s ago): "
                    f"delete it if no process uses {self.directory}, or wait {STALE_S:.0f} s from its last change, "
                    f"after which it is taken over; or use another directory.")
        return (f"{self.directory} is in use by another writer: process {holder.get('pid', '?')} on host "
                f"{holder.get('host', '?')}, since {holder.get('started', '?')} ({holder.get('program', '?')}; lock "
                f"{self.path}, heartbeat {age:,.0f} s ago). {way_out}. A holder on another host that stopped without "
                f"a word is taken over {STALE_S:.0f} s after its last heartbeat.")

    # ---- internals ----

    def _description(self) -> bytes:
        self.token = os.urandom(8).hex()
        return json.dumps({"host": socket.gethostname(), "pid": os.getpid(), "proc_start": process_start(os.getpid()),
                           "boot_id": boot_id(), "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                           "program": self.program, "token": self.token}, sort_keys=True).encode()

    def _written_temporary(self, data: bytes) -> str:
        name, fd = create_temporary(self.path)
        try:
            with named_errors(self.path), os.fdopen(fd, "wb") as f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())
        except BaseException:
            os.unlink(name)
            raise
        return name

    def _create(self, path: Optional[str] = None) -> bool:
        """Links a new description to `path` (the lock); False if the name exists."""
        name = self._written_temporary(self._description())
        try:
            os.link(name, path or self.path)
            return True
        except FileExistsError:
            return False
        finally:
            os.unlink(name)

    def _take_over(self, found: Optional[dict]) -> bool:
        """Replaces a dead holder's lock with ours, if it is still the lock `found` describes."""
        breaker = DirectoryLock(self.directory, os.path.basename(self.path)[:-len(".lock")] + ".lock.break",
                                self.program)
        if not breaker._create():
            try:
                if self._mtime_age(breaker.path) <= BREAK_STALE_S:
                    return False
                os.unlink(breaker.path)
            except FileNotFoundError:
                pass
            return False
        try:
            if self.read() != found:
                return False
            if found is None:
                return self._create()
            name = self._written_temporary(self._description())
            os.replace(name, self.path)
            print(f"{self.program}: took over {self.path} from a holder that is gone (process {found.get('pid')} on "
                  f"{found.get('host')})", file=sys.stderr, flush=True)
            return True
        finally:
            os.unlink(breaker.path)

    def _heartbeat_age(self) -> float:
        try:
            return self._mtime_age(self.path)
        except FileNotFoundError:
            return 0.0

    def _mtime_age(self, path: str) -> float:
        """How long ago `path` was modified, by the clock of the file system that holds it (hosts' clocks
        may differ): the modification time of a file created there now, less that of `path`."""
        name, fd = create_temporary(self.path)
        try:
            now = os.fstat(fd).st_mtime
        finally:
            os.close(fd)
            os.unlink(name)
        return now - os.stat(path).st_mtime

    def _start_heartbeat(self) -> None:
        self._stop.clear()
        self._thread = threading.Thread(target=self._beat, name=f"heartbeat {self.path}", daemon=True)
        self._thread.start()

    def _beat(self) -> None:
        while not self._stop.wait(HEARTBEAT_S):
            holder = self.read()
            if holder is None or holder.get("token") != self.token:
                self.lost = True
                print(f"{self.program}: lost {self.path} to another process (this one was taken for dead)",
                      file=sys.stderr, flush=True)
                return
            try:
                os.utime(self.path)
            except OSError:
                pass
