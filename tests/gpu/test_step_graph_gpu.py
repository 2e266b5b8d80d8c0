"""Steps captured in a CUDA graph: kage.step_batches captured once (batches on streams of their own, a mixture
among them, whose parts fork onto their own streams) and replayed equals the same batches stepped eagerly,
byte for byte, across autoresets; an out-of-range action in a replay is named by that replay's step number
(batches count their step launches on the device); an evaluation with --cuda-graph (kage.ppo.evaluation's
StepGraph) gives the eager evaluation's numbers, in float32 and under the table's speed flags."""
import pytest
import torch

import kage
from kage.ppo.agent import Agent
from kage.ppo.evaluation import EvalSettings, evaluate
from support import ROOT
from test_step_batches_gpu import assert_same_outputs

BENCH = ROOT / "configs/kage_bench"
SKELETON, FILTERS_4, FILTERS_5 = (str(BENCH / p) for p in ("bases/image_skeleton.yaml", "filters/4-eval.yaml",
                                                            "filters/5-eval.yaml"))
N = 48


def batches(streams, seed=10):
    configs = [SKELETON, [SKELETON, FILTERS_4, FILTERS_5], FILTERS_5]
    return [kage.make_vec(c, N, device="cuda", seed=seed + i, stream=s)
            for i, (c, s) in enumerate(zip(configs, streams))]


def captured_step(envs, actions: torch.Tensor) -> torch.cuda.CUDAGraph:
    """A graph of kage.step_batches(envs, actions) on the capture's stream, joined back as a learner joins."""
    streams = [torch.cuda.ExternalStream(env.stream) for env in envs]
    graph = torch.cuda.CUDAGraph()
    with torch.cuda.graph(graph):
        kage.step_batches(envs, actions)
        for stream in streams:
            torch.cuda.current_stream().wait_stream(stream)
    return graph


def test_replayed_steps_equal_eager_steps():
    graphed = batches([torch.cuda.Stream().cuda_stream for _ in range(3)])
    eager = batches([torch.cuda.Stream().cuda_stream for _ in range(3)])
    for env in graphed + eager:
        env.reset()
    generator = torch.Generator(device="cuda").manual_seed(3)
    actions = torch.zeros((3, N), dtype=torch.int64, device="cuda")
    graph = captured_step(graphed, actions)
    torch.cuda.synchronize()
    assert_same_outputs(graphed, eager, "after the capture, which must step nothing")
    finished = 0
    for step in range(560):  # past the 500-step truncation of every episode
        actions.copy_(torch.randint(0, 8, (3, N), device="cuda", generator=generator))
        graph.replay()
        kage.step_batches(eager, actions)
        torch.cuda.synchronize()
        if step % 50 == 0 or step >= 495:
            assert_same_outputs(graphed, eager, step)
        finished += sum(int(torch.from_dlpack(env.outputs()[4]["_final"]).sum()) for env in graphed)
    assert finished >= 3 * N


def test_a_bad_action_in_a_replay_is_named_by_its_step():
    envs = batches([torch.cuda.Stream().cuda_stream for _ in range(3)])
    for env in envs:
        env.reset()
    actions = torch.zeros((3, N), dtype=torch.int64, device="cuda")
    kage.step_batches(envs, actions)  # step 1
    graph = captured_step(envs, actions)  # steps nothing
    graph.replay()  # step 2
    graph.replay()  # step 3
    actions[1, N // 3 + 5] = -1  # the mixture's second part (16 environments a part), its environment 5
    graph.replay()  # step 4
    actions[1, N // 3 + 5] = 0
    torch.cuda.synchronize()
    with pytest.raises(ValueError, match=rf"step 4 held -1 for environment {N // 3 + 5}"):
        envs[1].step(torch.zeros(N, dtype=torch.int64, device="cuda"))


def eval_envs():
    streams = [torch.cuda.Stream().cuda_stream for _ in range(2)]  # a stream per run, as the trainer's
    return [[kage.make_vec(c, 8, device="cuda", seed=0, stream=s) for c in (SKELETON, FILTERS_5, FILTERS_4)]
            for s in streams]


@pytest.mark.parametrize("table_flags", [False, True])
def test_an_evaluation_as_a_graph_gives_the_eager_numbers(table_flags):
    """Plain float32, and the table's speed flags (bf16, fused input, Triton convolutions)."""
    speed = dict(bf16=True, fused_input=True, triton_conv=True) if table_flags else {}
    agent = Agent([1, 2], 3, 128, 128, torch.device("cuda"), **speed)
    seeds = [[101, 102, 103], [201, 202, 203]]
    results = {}
    for cuda_graph in (False, True):
        # two waves of 500 steps: 16 episodes each
        settings = EvalSettings(episodes=12, bf16=table_flags, cuda_graph=cuda_graph)
        results[cuda_graph] = evaluate(agent, eval_envs(), seeds, settings)
    assert results[True] == results[False]
    assert all(r["episodes"] >= 12 for run in results[True] for r in run)
