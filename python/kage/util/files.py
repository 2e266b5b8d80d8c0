"""Files that are replaced whole: a reader, or a process killed while writing, sees the old or the new
content, never a part.

The content goes to a temporary file beside the target, NAME.tmp.<host>.<pid>.<random>: created exclusively
(an existing file or a planted symlink at that name makes the create fail instead of being followed),
unpredictable, removed when the write fails (a full disk keeps no stray), and named by its writer, so that
remove_strays can tell a dead writer's leftovers from a live one's (processes of several hosts may share a
directory: a Slurm array).

Files that are read back (a run's records, logs and checkpoints) are opened with open_regular: only a regular
file (or a symlink to one) is read, and only up to a size cap, so that a log that is a symlink to /dev/zero
or a FIFO is refused at once instead of filling the memory or waiting forever."""
import contextlib
import errno
import json
import os
import re
import secrets
import socket
import stat
import time
from typing import Any, BinaryIO, Callable, Iterator, Optional, Tuple

STRAY_AGE_S = 3600  # another host's temporary file this old is a dead writer's: a write takes seconds
_TEMPORARY = re.compile(r"^.+\.tmp\.(?P<host>[^/]+?)\.(?P<pid>\d+)(?:\.[0-9a-f]+)?$")


def atomic_write(path: str, data: bytes) -> None:
    """Writes `data` to a new temporary file beside `path`, syncs it, then renames it over `path`."""
    with named_errors(path):
        name, fd = create_temporary(path)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())
            os.replace(name, path)
        except BaseException:
            _unlink(name)
            raise


@contextlib.contextmanager
def named_errors(path: str):
    """OSErrors of the block that name no file (a write's or fsync's ENOSPC) name `path`."""
    try:
        yield
    except OSError as e:
        if e.filename is None:
            raise OSError(e.errno, e.strerror, path) from e
        raise


def os_error_text(program: str, e: OSError, flag: str) -> str:
    """One line for a file system's refusal: the file, the reason, and what to do (`flag`: the option that
    chose where to write). An error raised with a message alone (a name that is neither a path nor a shipped
    file, kage.resources) is that message: it names the file and the choices."""
    if e.errno is None:
        return f"{program}: {e}"
    where = e.filename if e.filename is not None else "?"
    if e.errno in (errno.ENOSPC, errno.EDQUOT):
        fix = "free space on that file system (or raise the quota), then run the same command again: it resumes"
    elif e.errno in (errno.EROFS, errno.EACCES, errno.EPERM):
        fix = f"choose a writable {flag}"
    else:
        fix = f"check that path (or choose another {flag}), then run the same command again"
    return f"{program}: {where}: {e.strerror or e}: {fix}"


def create_temporary(path: str):
    """(name, file descriptor) of a new file beside `path` that nobody else could have created or planted."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    for _ in range(100):
        name = f"{path}.tmp.{socket.gethostname()}.{os.getpid()}.{secrets.token_hex(6)}"
        try:
            return name, os.open(name, flags, 0o666)
        except FileExistsError:
            continue
    raise FileExistsError(errno.EEXIST, "no unused temporary name after 100 tries", path)


def output_folder(path: str, *subfolders: str) -> None:
    """Creates `path` and its `subfolders` for files replaced whole (a report's, a scoring's), removing the
    temporary files that killed writers left there."""
    for folder in (path, *(os.path.join(path, sub) for sub in subfolders)):
        os.makedirs(folder, exist_ok=True)
        remove_strays(folder)


def remove_strays(directory: str) -> None:
    """Removes the temporary files of atomic_write in `directory` whose writer is gone: this host's whose
    process no longer runs, and any older than STRAY_AGE_S. Live writers' files are left alone."""
    try:
        names = os.listdir(directory)
    except FileNotFoundError:
        return
    host, now = socket.gethostname(), time.time()
    for name in names:
        m = _TEMPORARY.match(name)
        if not m:
            continue
        path = os.path.join(directory, name)
        try:
            age = now - os.lstat(path).st_mtime
        except FileNotFoundError:
            continue
        if (m["host"] == host and not process_alive(int(m["pid"]))) or age > STRAY_AGE_S:
            _unlink(path)


def _unlink(path: str) -> None:
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


def process_alive(pid: int) -> bool:
    """Whether a process with this id runs on this host."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


RECORD_LIMIT = 64 << 20  # a JSON record (bench.json, suite.json, run.json, summary.json, a state): ~1000x a real one
LOG_LIMIT = 4 << 30  # a metrics.jsonl (a long run's is tens of MB)


class NotRegularFile(OSError):
    """A file that a reader refuses before reading it: not a regular file (a FIFO, a device, a directory, a
    socket; through a symlink too), or larger than the reader's cap. Its strerror says which."""

    def __str__(self) -> str:
        return f"{self.filename}: {self.strerror}"


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISDIR, "a directory"), (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


@contextlib.contextmanager
def open_regular(path: str, limit: int) -> Iterator[BinaryIO]:
    """`path` opened for reading in binary, where it is a regular file (a symlink to one is fine) of at most
    `limit` bytes; NotRegularFile (an OSError naming `path`) otherwise, before anything is read. Opened without
    blocking, so that a FIFO is refused at once instead of waiting for a writer."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            target = f" (a symlink to {os.path.realpath(path)})" if os.path.islink(path) else ""
            raise NotRegularFile(errno.EINVAL, f"{_kind(info.st_mode)}{target}, not a regular file", path)
        if info.st_size > limit:
            raise NotRegularFile(errno.EFBIG, f"{info.st_size:,} bytes, more than such a file can be ({limit:,})",
                                 path)
        os.set_blocking(fd, True)
        f = os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise
    with f:
        yield f


def read_regular(path: str, limit: int = RECORD_LIMIT) -> bytes:
    """The content of the regular file `path`, at most `limit` bytes (open_regular's refusals)."""
    with open_regular(path, limit) as f:
        data = f.read(limit + 1)
    if len(data) > limit:  # it grew while being read
        raise NotRegularFile(errno.EFBIG, f"more than such a file can be ({limit:,} bytes)", path)
    return data


def read_json_record(path: str, problem_of: Callable[[Any], Optional[str]]) -> Tuple[Any, Optional[str]]:
    """A JSON record's value and what is wrong with it (not JSON, or `problem_of`'s answer; None when nothing is),
    for the caller to refuse in its own words. OSError passes through (NotRegularFile for a FIFO, a device or a
    file larger than RECORD_LIMIT)."""
    data = read_regular(path)
    try:
        value = json.loads(data)
    except (ValueError, RecursionError) as e:  # UnicodeDecodeError too; RecursionError: nesting too deep
        return None, f"not JSON ({e})"
    return value, problem_of(value)


def write_json(path: str, value) -> None:
    """Pretty, key-sorted, strict JSON (no NaN or infinity), written atomically."""
    atomic_write(path, (json.dumps(value, indent=1, sort_keys=True, allow_nan=False) + "\n").encode())


def safe(name: str) -> str:
    """A pair or label name as one path component."""
    return name.replace("/", "_").replace(" ", "_")
