"""Each run's environments on a CUDA stream of their own, ordered against the learner.

A run's batch is a few hundred environments (a mixture's parts fewer still): its kernels alone would be too small
to fill the GPU. A pack's step goes through kage.step_batches, which launches each config once over every run's
batch (on the first run's stream; the other runs' streams are ordered before and after it), while a run's own
work (a reset, a stage's entry, a saved state) queues on its stream. A batch orders itself after the learner when
it takes the actions (the DLPack protocol, kage.actions); the learner orders itself after the batches with
`wait_for` before it reads their outputs, and the rest of the loop is unchanged. Under --cuda-graph the whole
step is one graph (GraphedStep)."""
from typing import Iterable, List, Optional

import torch

import kage


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


def release(streams: Iterable[Optional[torch.cuda.Stream]]) -> None:
    """Orders each of `streams` after the work queued so far on the current stream: after a GraphedStep's
    replays (which run on the current stream), before a batch's own work (a reset, a saved state) on its stream."""
    current = None
    for stream in streams:
        if stream is not None:
            current = current or torch.cuda.current_stream()
            stream.wait_stream(current)


class GraphedStep:
    """`kage.step_batches(envs, actions)` and the learner's `wait_for` as one CUDA graph: one launch a step
    instead of a launch pair per config. Captured at the first call (the capture steps nothing; the replay that
    follows does), and again when the batches or the actions' memory change (a schedule's stage opens new
    batches). The configs' launches are captured on streams of their own, forked from the capture's and joined
    back, so they still run side by side; a batch numbers its steps on the device, so an action's report names
    the replayed step. The replays run on the current stream: `release` the batches'
    streams before queueing work on them directly."""

    def __init__(self):
        self.graph, self.envs, self.actions = None, [], None

    def __call__(self, envs: List["kage.VecEnv"], actions: torch.Tensor) -> None:
        if (self.graph is None or len(envs) != len(self.envs) or any(a is not b for a, b in zip(envs, self.envs))
                or actions.data_ptr() != self.actions):
            self.graph = None  # the old graph's launches name batches that may be closed
            graph = torch.cuda.CUDAGraph()
            with torch.cuda.graph(graph):
                kage.step_batches(envs, actions)
                wait_for(streams_of(envs))
            self.graph, self.envs, self.actions = graph, list(envs), actions.data_ptr()
        self.graph.replay()
