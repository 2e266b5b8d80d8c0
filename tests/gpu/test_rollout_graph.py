"""The rollout's policy step replayed as a CUDA graph (--cuda-graph) gives what the eager network gives,
after the parameters have changed by optimizer steps, with and without --bf16."""
import pytest
import torch

from kage.ppo.agent import Agent
from kage.ppo.policy import RolloutPolicy, autocast


@pytest.mark.parametrize("bf16", [False, True])
def test_graph_replay_follows_the_updated_parameters(bf16):
    device = torch.device("cuda")
    agent = Agent([1, 2], 3, 128, 128, device, bf16=bf16)
    obs_shape = (2, 16, 128, 128, 3)
    graph = RolloutPolicy(agent, obs_shape, 8, device, bf16=bf16, cuda_graph=True)
    eager = RolloutPolicy(agent, obs_shape, 8, device, bf16=bf16, cuda_graph=False)
    optimizer = torch.optim.Adam(agent.parameters(), lr=1e-3)
    generator = torch.Generator(device).manual_seed(0)
    for _ in range(5):
        obs = torch.randint(0, 256, obs_shape, dtype=torch.uint8, device=device, generator=generator)
        uniform = torch.rand((2, 16, 8), device=device, generator=generator).clamp(1e-6, 1 - 1e-6)
        got = [t.clone() for t in graph(obs, uniform)]
        want = eager(obs, uniform)
        assert torch.equal(got[0], want[0])
        torch.testing.assert_close(got[1], want[1], rtol=1e-3, atol=1e-3)
        torch.testing.assert_close(got[2], want[2], rtol=1e-3, atol=1e-3)
        optimizer.zero_grad()
        with autocast(bf16):
            logits, value = agent(obs)
        (logits.float().square().mean() + value.float().square().mean()).backward()
        optimizer.step()
