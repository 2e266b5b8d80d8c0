"""When an evaluation replays its step as a CUDA graph (kage.ppo.evaluation.graphable): only under --cuda-graph,
never with a frame stack (its buffer is rebuilt each step, so a graph would replay a stale one), and only when every
batch queues on a stream of its own (a capture cannot use the legacy default stream, 0). The graph itself runs on
the GPU: tests/gpu/test_step_graph_gpu.py."""
import dataclasses

import pytest

from kage.ppo.evaluation import EvalSettings, graphable


@dataclasses.dataclass
class Batch:
    stream: int


@pytest.mark.parametrize("cuda_graph, frame_stack, streams, expected", [
    (True, False, [11, 12, 12], True),
    (False, False, [11, 12, 12], False),
    (True, True, [11, 12, 12], False),
    (True, False, [11, 0, 12], False),
])
def test_graphable(cuda_graph, frame_stack, streams, expected):
    settings = EvalSettings(episodes=4, frame_stack=frame_stack, cuda_graph=cuda_graph)
    assert graphable(settings, [Batch(s) for s in streams]) is expected
