"""Each run's environments on a CUDA stream of their own, so that the batches of a pack step at once.

A run's batch is a few hundred environments (a mixture's parts fewer still): its step and render kernels are
too small to fill the GPU and last about as long as a full one. On one stream a pack's K batches run one after
another; on a stream per run they overlap (a mixture's parts still run one after another on their run's
stream). A batch orders itself after the learner
when it takes the actions (the DLPack protocol, kage.actions); the learner orders itself after the batches
with `wait_for` before it reads their outputs, and the rest of the loop is unchanged."""
from typing import Iterable, List, Optional

import torch


def new_stream(device: str) -> Optional[torch.cuda.Stream]:
    """A stream for one run's batches on the GPU; None on the CPU."""
    return torch.cuda.Stream() if device == "cuda" else None


def streams_of(envs: Iterable["kage.VecEnv"]) -> List[torch.cuda.Stream]:
    """The distinct streams, other than the legacy default stream, that `envs` queue their work on."""
    return [torch.cuda.ExternalStream(handle) for handle in sorted({env.stream for env in envs} - {0})]


def wait_for(streams: Iterable[Optional[torch.cuda.Stream]]) -> None:
    """Orders the current stream after the work queued so far on each of `streams` (None: nothing to wait for)."""
    current = None
    for stream in streams:
        if stream is not None:
            current = current or torch.cuda.current_stream()
            current.wait_stream(stream)
