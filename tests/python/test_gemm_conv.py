"""--gemm-conv computes the baseline's convolutions as im2col and one batched matrix product per layer over
the packed runs; the parameters stay the grouped convolutions', so the network must compute the same
function as with cuDNN's grouped convolutions, alone (K = 1) and packed (K = 3), with and without
--fused-input, and give the same gradients (CPU, float32).

Tolerance, from the arithmetic: both paths form the same products and add them in another order. float32
rounds each addition by at most 6e-8 relative; a reordered sum of n terms differs by about sqrt(n) such
roundings of the terms' magnitudes (n up to 9,216 in the fc layer: about 6e-6 in an unlucky
draw, 1e-6 typically), and the four layers' differences add. An output (or a gradient tensor, whose
elements are sums of the same kind over the batch and the positions) may therefore differ by 1e-5 of the
largest magnitude of its tensor, and no more: a wrong weight order, window or flatten would change it by
the order of the values themselves."""
import pytest
import torch

from kage.agent import Agent

HEIGHT, WIDTH = 74, 102  # not square, not a multiple of 4: rows and columns cannot be swapped or misread


def network(runs: int, fused: bool, gemm: bool) -> Agent:
    agent = Agent(list(range(11, 11 + runs)), height=HEIGHT, width=WIDTH)
    agent.space_to_depth, agent.gemm_conv = fused, gemm
    return agent


def outputs_and_gradients(agent: Agent, obs: torch.Tensor):
    logits, value = agent(obs)
    loss = logits.logsumexp(-1).sum() + value.pow(2).sum()
    agent.zero_grad()
    loss.backward()
    return {"logits": logits.detach(), "value": value.detach(),
            **{f"grad {name}": p.grad.clone() for name, p in agent.named_parameters()}}


def assert_close(got: torch.Tensor, expected: torch.Tensor, what: str) -> None:
    scale = expected.abs().max().item()
    assert scale > 0, f"{what}: all zero, nothing compared"
    difference = (got - expected).abs().max().item()
    assert difference <= 1e-5 * scale, f"{what}: differs by {difference:.3g} at scale {scale:.3g}"


@pytest.mark.parametrize("fused", [False, True], ids=["frames", "fused-input"])
@pytest.mark.parametrize("runs", [1, 3])
def test_gemm_conv_computes_the_grouped_convolutions(runs, fused):
    generator = torch.Generator().manual_seed(runs)
    obs = torch.randint(0, 256, (runs, 5, HEIGHT, WIDTH, 3), dtype=torch.uint8, generator=generator)
    expected = outputs_and_gradients(network(runs, fused, gemm=False), obs)
    got = outputs_and_gradients(network(runs, fused, gemm=True), obs)
    assert got.keys() == expected.keys()
    for what in expected:
        assert_close(got[what], expected[what], what)

