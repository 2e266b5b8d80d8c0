"""Under bfloat16 autocast (--bf16) the network's heads stay in float32. An untrained run's values are near
-3,900, where bfloat16's spacing is 16, more than a step's reward: rounded values would bury the advantages
in noise (a run under --bf16 stopped learning that way). CPU autocast stands in for the GPU's here."""
import torch

from kage.ppo.agent import Agent


def test_heads_stay_float32_under_bf16_autocast():
    torch.manual_seed(0)
    agent = Agent([1, 2], 3, 128, 128)
    with torch.no_grad():
        agent.critic_bias.fill_(-3000.0)  # values of the size an untrained run sees
    obs = torch.randint(0, 256, (2, 32, 128, 128, 3), dtype=torch.uint8)
    with torch.no_grad():
        logits32, value32 = agent(obs)
        with torch.autocast("cpu", dtype=torch.bfloat16):
            logits16, value16 = agent(obs)
    assert value16.dtype == torch.float32 and logits16.dtype == torch.float32
    # Only the torso's bfloat16 rounding remains: far below the +-8 of a bfloat16 value near 3,000.
    assert (value16 - value32).abs().max() < 0.5
    assert (logits16 - logits32).abs().max() < 0.01
