"""Checkpoint files that hold data only: reading one never runs code from it.

A checkpoint is the nested dict kage.ppo.train keeps (tensors, numbers, strings, lists, the environments'
saved state as bytes). On disk it is a torch.save file of three entries that torch.load(weights_only=True)
reads on every torch this package supports (1.13 reads neither Python floats nor bytes that way):

    "format"   FORMAT
    "json"     the dict as JSON text (a uint8 tensor), each tensor replaced by {"__tensor__": i} and each bytes
               value by {"__bytes__": i}
    "tensors"  the list of those tensors (bytes values as uint8 tensors)
    "sha256"   of the JSON text and every tensor's dtype, shape and bytes: a bit flipped on disk or an edit
               is refused, since torch does not check the zip's CRCs

Checkpoints written before this format (a pickled dict) are read with weights_only=True too, where the torch
in use can (2.x); nothing is ever unpickled beyond what that loader allows.
"""
import hashlib
import io
import json
from typing import Any, List, Optional

import numpy as np
import torch

from kage.util.files import NotRegularFile, open_regular

FORMAT = "kage.ppo.checkpoint/2"
LIMIT = 1 << 40  # bytes: a cap only against a file that never ends; a checkpoint is what its run holds


class CheckpointError(Exception):
    """A file that is not a checkpoint this package can read as data: the message names the file and why."""


def encode(state: dict) -> bytes:
    """The file's bytes for `state`."""
    tensors: List[torch.Tensor] = []

    def pack(value: Any) -> Any:
        if isinstance(value, torch.Tensor):
            tensors.append(value.detach().cpu())
            return {"__tensor__": len(tensors) - 1}
        if isinstance(value, (bytes, bytearray)):
            tensors.append(torch.frombuffer(bytearray(value), dtype=torch.uint8) if value else
                           torch.zeros(0, dtype=torch.uint8))
            return {"__bytes__": len(tensors) - 1}
        if isinstance(value, dict):
            if not all(isinstance(k, str) for k in value):
                raise TypeError(f"checkpoint keys must be strings, got {sorted(map(repr, value))[:3]}")
            return {k: pack(v) for k, v in value.items()}
        if isinstance(value, (list, tuple)):
            return [pack(v) for v in value]
        if value is None or isinstance(value, (bool, int, float, str)):
            return value
        if isinstance(value, np.generic) and value.dtype.kind in "biuf":  # a numpy number: its Python value
            return value.item()
        raise TypeError(f"a checkpoint holds data only, not {type(value).__name__}")

    text = json.dumps(pack(state), sort_keys=True).encode()  # Infinity and NaN as Python's json writes them
    buffer = io.BytesIO()
    torch.save({"format": FORMAT, "json": torch.frombuffer(bytearray(text), dtype=torch.uint8), "tensors": tensors,
                "sha256": digest(text, tensors)}, buffer)
    return buffer.getvalue()


def digest(text: bytes, tensors: List[torch.Tensor]) -> str:
    """SHA-256 of a checkpoint's JSON text and tensors (dtype, shape and bytes of each, in order)."""
    h = hashlib.sha256(text)
    for t in tensors:
        h.update(f"|{t.dtype}{tuple(t.shape)}|".encode())
        h.update(t.contiguous().reshape(-1).view(torch.uint8).numpy().tobytes())
    return h.hexdigest()


def load(path: str) -> dict:
    """The state saved at `path`, read as data only; CheckpointError names the file and what is wrong."""
    try:
        with open_regular(path, LIMIT) as f:  # a FIFO or a device is refused, not waited on or read forever
            raw = torch.load(f, map_location="cpu", weights_only=True)
    except FileNotFoundError:
        raise CheckpointError(f"{path}: no such file") from None
    except NotRegularFile as e:
        raise CheckpointError(f"{path}: {e.strerror}: give the checkpoints/latest.pt that kage.ppo.train wrote") \
            from None
    except Exception as e:  # torch raises many kinds on a damaged, foreign or code-carrying file
        older = ("; a checkpoint of an older kage.ppo.train (a pickled dict) reads as data only with torch 2.x"
                 if int(torch.__version__.split(".")[0]) < 2 else "")
        raise CheckpointError(
            f"{path}: cannot be read as data only ({reason(e)}): it is damaged, "
            "is not a kage.ppo.train checkpoint, or holds Python objects that only unpickling would rebuild, which "
            f"can run code{older}") from None
    if isinstance(raw, dict) and raw.get("format") == FORMAT:
        return _decode(path, raw)
    if isinstance(raw, dict) and "agent" in raw and "iteration" in raw:
        return raw  # the pickled dict of earlier versions, which the data-only loader could read
    found = f"format {raw.get('format')!r}" if isinstance(raw, dict) and "format" in raw else type(raw).__name__
    raise CheckpointError(f"{path}: not a kage.ppo.train checkpoint ({found}, expected {FORMAT})")


def reason(e: Exception) -> str:
    """The gist of torch.load's error: the data-only loader's own words where it gave them, else its first line."""
    text = str(e)
    gist = text.split("WeightsUnpickler error:", 1)[1] if "WeightsUnpickler error:" in text else text
    lines = [line.strip() for line in gist.splitlines() if line.strip()]
    return f"{type(e).__name__}: {lines[0][:120] if lines else 'no detail'}"


def _decode(path: str, raw: dict) -> dict:
    tensors = raw.get("tensors")
    try:
        text = bytes(raw["json"].numpy())
        intact = raw.get("sha256") == digest(text, tensors)
    except (KeyError, TypeError, AttributeError, RuntimeError) as e:
        raise CheckpointError(f"{path}: damaged: its parts are missing or of the wrong kind ({e})") from None
    if not intact:
        raise CheckpointError(f"{path}: damaged: its content does not match the SHA-256 it was written with (a bit "
                              "flipped on disk, or an edit)")
    try:
        tree = json.loads(text.decode())
    except (ValueError, UnicodeDecodeError) as e:
        raise CheckpointError(f"{path}: its JSON part is damaged ({e})") from None

    def unpack(value: Any) -> Any:
        if isinstance(value, dict):
            if value.keys() == {"__tensor__"} or value.keys() == {"__bytes__"}:
                (kind, index), = value.items()
                if not isinstance(tensors, list) or not isinstance(index, int) or not 0 <= index < len(tensors):
                    raise CheckpointError(f"{path}: its JSON names tensor {index!r}, which the file lacks")
                return bytes(tensors[index].numpy()) if kind == "__bytes__" else tensors[index]
            return {k: unpack(v) for k, v in value.items()}
        if isinstance(value, list):
            return [unpack(v) for v in value]
        return value

    state = unpack(tree)
    if not (isinstance(state, dict) and "agent" in state and "iteration" in state):
        raise CheckpointError(f"{path}: not a kage.ppo.train checkpoint (no parameters and iteration)")
    return state


def structure_problem(expected: Any, found: Any, where: str = "") -> Optional[str]:
    """Where a decoded checkpoint `found` is not shaped like `expected` (the one this code would write now), or
    None: dicts with the same keys, tensors of the same dtype and shape, bytes of the same length, lists, and
    numbers, strings, booleans and None of the same kind (a float may be an int). A digest proves a file intact,
    not that its writer wrote what a run needs: this turns a crafted or foreign file into a message."""
    at = where or "the top level"
    if isinstance(expected, np.generic):  # written as its Python value (encode)
        expected = expected.item()
    if isinstance(expected, dict):
        if not isinstance(found, dict):
            return f"{at}: {_kind(found)}, expected a dict"
        if found.keys() != expected.keys():
            missing, extra = sorted(expected.keys() - found.keys()), sorted(found.keys() - expected.keys())
            return f"{at}: " + "; ".join(filter(None, [missing and f"lacks {', '.join(missing[:4])}",
                                                      extra and f"has unknown {', '.join(map(str, extra[:4]))}"]))
        for key, value in expected.items():
            problem = structure_problem(value, found[key], f"{where}/{key}")
            if problem:
                return problem
        return None
    if isinstance(expected, torch.Tensor):
        if not isinstance(found, torch.Tensor) or found.dtype != expected.dtype or found.shape != expected.shape:
            shown = f"{found.dtype} {list(found.shape)}" if isinstance(found, torch.Tensor) else _kind(found)
            return f"{at}: {shown}, expected {expected.dtype} {list(expected.shape)}"
        return None
    if isinstance(expected, bytes):
        if not isinstance(found, bytes) or len(found) != len(expected):
            shown = f"{len(found)} bytes" if isinstance(found, bytes) else _kind(found)
            return f"{at}: {shown}, expected {len(expected)} bytes"
        return None
    kinds = {bool: (bool,), int: (int,), float: (int, float), str: (str,), list: (list,), type(None): (type(None),)}
    allowed = kinds.get(type(expected), (type(expected),))
    if not isinstance(found, allowed) or (isinstance(found, bool) and not isinstance(expected, bool)):
        return f"{at}: {_kind(found)}, expected {_kind(expected)}"
    return None


def _kind(value: Any) -> str:
    name = type(value).__name__
    return f"{'an' if name[0] in 'aeiou' else 'a'} {name}" if value is not None else "null"
