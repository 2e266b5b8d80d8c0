"""Files that are replaced whole: a reader, or a process killed while writing, sees the old or the new
content, never a part."""
import json
import os
import socket


def atomic_write(path: str, data: bytes) -> None:
    """Writes `data` beside `path`, syncs it, then renames it over `path`. The temporary name is the
    writer's own (host and process), for processes of several hosts sharing a directory (a Slurm array)."""
    tmp = f"{path}.tmp.{socket.gethostname()}.{os.getpid()}"
    with open(tmp, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def write_json(path: str, value) -> None:
    """Pretty, key-sorted, strict JSON (no NaN or infinity), written atomically."""
    atomic_write(path, (json.dumps(value, indent=1, sort_keys=True, allow_nan=False) + "\n").encode())


def safe(name: str) -> str:
    """A pair or label name as one path component."""
    return name.replace("/", "_").replace(" ", "_")
