"""The trainer's arithmetic against values computed by hand (kage-ppo-baseline.md §1-§4)."""
import math

import numpy as np
import pytest
import torch

from kage.ppo.agent import Agent
from kage.ppo.args import Args
from kage.ppo.counter_random import CounterRandom
from kage.fields import RECORD_COLUMNS
from kage.ppo.evaluation import COLUMN, EpisodeMetrics, summarize_evaluation
from kage.ppo.losses import clip_grad_norm_per_run, compute_gae, entropy_of, ppo_loss
from kage.ppo.policy import sample_gumbel_max


def test_gae_on_a_three_step_batch():
    # gamma = lambda = 0.5; obs[2] starts an episode (dones[2] = 1), so step 1 is an episode's last.
    rewards = torch.tensor([[1.0], [2.0], [3.0]])
    values = torch.tensor([[0.5], [1.0], [1.5]])
    dones = torch.tensor([[0.0], [0.0], [1.0]])
    advantages, returns = compute_gae(rewards, values, dones, torch.tensor([2.0]), torch.tensor([0.0]), 0.5, 0.5)
    # t=2: 3 + 0.5*2.0 - 1.5 = 2.5 | t=1: 2 - 1.0 = 1.0 (no bootstrap) | t=0: (1 + 0.5*1.0 - 0.5) + 0.25*1.0 = 1.25
    assert advantages[:, 0].tolist() == [1.25, 1.0, 2.5]
    assert returns[:, 0].tolist() == [1.75, 2.0, 4.0]


def test_gae_does_not_bootstrap_after_a_final_step():
    advantages, _ = compute_gae(torch.tensor([[1.0]]), torch.tensor([[0.0]]), torch.tensor([[0.0]]),
                                torch.tensor([100.0]), torch.tensor([1.0]), 0.9, 0.9)
    assert advantages.item() == 1.0


def test_ppo_loss_on_two_samples():
    args = Args(train_config_path="x")
    new_logprob = torch.tensor([math.log(0.5), math.log(0.25)])
    old_logprob = torch.tensor([math.log(0.25), math.log(0.25)])  # ratios 2 and 1
    entropy = torch.tensor([2.0, 1.0])
    new_value, old_value = torch.tensor([1.0, 3.0]), torch.tensor([0.5, 3.5])
    advantages, returns = torch.tensor([1.0, -1.0]), torch.tensor([2.0, 3.0])
    loss, pg, v, ent, kl, clipfrac = ppo_loss(new_logprob, entropy, new_value, old_logprob, old_value, advantages,
                                              returns, args, 0.01)
    # normalised advantages (population std 1): +1, -1. pg: max(-2, -1.2) = -1.2 and max(1, 1) = 1 -> -0.1
    assert pg.item() == pytest.approx(-0.1, abs=1e-6)
    # value: clipped predictions 0.7 and 3.3; max((1-2)^2, (0.7-2)^2) = 1.69, max(0, 0.09) = 0.09 -> 0.5 * 0.89
    assert v.item() == pytest.approx(0.445, abs=1e-6)
    assert ent.item() == pytest.approx(1.5)
    assert loss.item() == pytest.approx(-0.1 - 0.01 * 1.5 + 0.5 * 0.445, abs=1e-6)
    assert kl.item() == pytest.approx((1 - math.log(2)) / 2, abs=1e-6)
    assert clipfrac.item() == 0.5


def test_unclipped_value_loss_and_raw_advantages():
    args = Args(train_config_path="x", clip_vloss=False, norm_adv=False)
    zero = torch.zeros(2)
    _, pg, v, *_ = ppo_loss(zero, zero, torch.tensor([1.0, 3.0]), zero, torch.tensor([0.5, 3.5]),
                            torch.tensor([3.0, 1.0]), torch.tensor([2.0, 3.0]), args, 0.0)
    assert v.item() == pytest.approx(0.5 * (1.0 + 0.0) / 2)
    assert pg.item() == pytest.approx(-(3.0 + 1.0) / 2)


def test_entropy_of_uniform_and_of_a_certain_policy():
    assert entropy_of(torch.zeros(1, 8)).item() == pytest.approx(math.log(8), rel=1e-6)
    certain = torch.tensor([[0.0] + [-1e30] * 7])
    assert entropy_of(certain).item() == 0.0


def test_gumbel_max_sampling_reports_its_log_probability():
    logits = torch.log(torch.tensor([[0.7, 0.1, 0.1, 0.1, 0, 0, 0, 0]]) + 1e-12).repeat(4000, 1)
    uniform = CounterRandom([0], "cpu").uniform(1, torch.tensor(0), (4000, 8))[0]
    action, logprob = sample_gumbel_max(logits, uniform)
    freq = torch.bincount(action, minlength=8).float() / 4000
    assert freq[0].item() == pytest.approx(0.7, abs=0.03) and freq[4:].sum().item() == 0
    assert torch.allclose(logprob, torch.log_softmax(logits, 1).gather(1, action[:, None]).squeeze(1))


def test_network_matches_the_specification():
    agent = Agent([1])
    assert sum(p.numel() for p in agent.parameters()) == 4_799_657
    assert sum(p.numel() for p in Agent([1], channels=12).parameters()) == 4_818_089
    h = torch.zeros(2, 3, 128, 128)
    shapes = []
    for conv in (agent.conv1, agent.conv2, agent.conv3):
        h = conv(h)
        shapes.append(tuple(h.shape[1:]))
    assert shapes == [(32, 31, 31), (64, 14, 14), (64, 12, 12)] and agent.flat == 9216
    assert agent.fc_weight.shape == (1, 9216, 512)
    logits, value = agent(torch.zeros(1, 5, 128, 128, 3, dtype=torch.uint8))
    assert logits.shape == (1, 5, 8) and value.shape == (1, 5)
    # Orthogonal columns scaled by the gain: actor 0.01, critic 1; orthogonal conv filters (gain sqrt 2).
    actor = agent.actor_weight[0]
    assert torch.allclose(actor.T @ actor, 0.01 ** 2 * torch.eye(8), atol=1e-8)
    assert agent.critic_weight.norm().item() == pytest.approx(1.0, rel=1e-5)
    filters = agent.conv2.weight.reshape(64, -1)
    assert torch.allclose(filters @ filters.T, 2 * torch.eye(64), atol=1e-4)
    biases = [agent.conv1.bias, agent.conv2.bias, agent.conv3.bias, agent.fc_bias, agent.actor_bias, agent.critic_bias]
    assert all(float(b.abs().max()) == 0 for b in biases)


def test_a_packed_agent_holds_each_lone_agent():
    # 44 x 44 frames (a 2 x 2 x 64 torso output) keep the orthogonal initialisations fast.
    lone = [Agent([seed], height=44, width=44) for seed in (4, 9, 2)]
    packed = Agent([4, 9, 2], height=44, width=44)
    obs = torch.randint(0, 256, (3, 6, 44, 44, 3), dtype=torch.uint8)
    logits, value = packed(obs)
    for k, agent in enumerate(lone):
        packed_params = dict(packed.named_parameters())
        for name, p in agent.named_parameters():
            assert torch.equal(packed.run_view(packed_params[name])[k], agent.run_view(p)[0]), name
        l, v = agent(obs[k:k + 1])
        assert torch.allclose(logits[k], l[0], atol=1e-5) and torch.allclose(value[k], v[0], atol=1e-5)


def test_gradient_clipping_is_per_run():
    agent = Agent([1, 2], height=44, width=44)
    for p in agent.parameters():
        p.grad = torch.zeros_like(p)
    agent.fc_bias.grad[0].fill_(1.0)    # run 0: norm sqrt(512) > 0.5 -> scaled to 0.5
    agent.actor_bias.grad[1].fill_(0.1)  # run 1: norm sqrt(8) * 0.1 < 0.5 -> unchanged
    norms = clip_grad_norm_per_run(agent, 0.5)
    assert norms.tolist() == pytest.approx([math.sqrt(512), math.sqrt(8) * 0.1])
    assert agent.fc_bias.grad[0].norm().item() == pytest.approx(0.5)
    assert torch.allclose(agent.actor_bias.grad[1], torch.full((1, 8), 0.1))


def test_evaluation_summary_follows_the_protocol():
    # [steps, columns, envs], the columns named by kage.fields.RECORD_COLUMNS. Two environments, three steps:
    # step 1: env 0 ends (return 10); step 2: env 0 ends with return 0 and env 1 with return 6.
    records = torch.zeros(3, len(RECORD_COLUMNS), 2)
    head = [COLUMN["finished"], COLUMN["return"], COLUMN["length"]]
    x = COLUMN["x"]
    records[1, head, 0] = torch.tensor([1.0, 10.0, 2.0])
    records[1, x, 0] = 1.0
    records[2, head, 0] = torch.tensor([1.0, 0.0, 2.0])
    records[2, x, 0] = 2.0
    records[2, head, 1] = torch.tensor([1.0, 6.0, 2.0])
    records[2, x, 1] = 3.0
    result = summarize_evaluation(records, episodes=2)
    # The list holds the first two episodes (10 and 0); the zero return is dropped: return 10, length 2.
    assert result["return"] == 10.0 and result["length"] == 2.0
    # The metric sums take every episode up to the step where the count reached 2: (1 + 2 + 3) / 3.
    assert result["x"] == 2.0 and result["episodes"] == 3
    only_zero = summarize_evaluation(records[:, :, :1].clone().index_fill_(1, torch.tensor([COLUMN["return"]]), 0.0),
                                     episodes=1)
    assert only_zero["return"] is None and only_zero["length"] is None


def test_success_is_strict_at_the_terminal_state():
    n = 3
    fields = {name: np.zeros(n, dtype=np.float32) for name in ("return", "x", "y", "vx_mean", "vy_mean", "progress")}
    fields.update({"length": np.full(n, 500, dtype=np.int32), "jump_count": np.zeros(n, dtype=np.int32),
                   "success": np.ones(n, dtype=np.uint8), "success_once": np.array([1, 1, 0], dtype=np.uint8),
                   "passed_distance": np.array([490.0, 491.0, 12.0], dtype=np.float32)})
    info = {"_final": np.array([1, 1, 1], dtype=np.uint8), "final_info": fields}
    rows = EpisodeMetrics([info], [490.0], "cpu").rows()[0]
    assert rows[COLUMN["success"]].tolist() == [0.0, 1.0, 0.0]  # 490 > 490 is false (QUIRK)
    assert rows[COLUMN["success_once"]].tolist() == [1.0, 1.0, 0.0]


def test_space_to_depth_conv1_equals_the_8x8_convolution():
    agent = Agent([5, 6], height=44, width=44)
    obs = torch.randint(0, 256, (2, 3, 44, 44, 3), dtype=torch.uint8)
    plain = agent(obs)
    blocked = Agent([5, 6], height=44, width=44, fused_input=True)(obs)  # the same parameters (the same seeds)
    for a, b in zip(plain, blocked):
        assert torch.allclose(a, b, rtol=1e-5, atol=1e-6)
    for k in range(2):  # and each run's output is its own 8x8 convolution of its frames
        x = obs[k].permute(0, 3, 1, 2).float() / 255.0
        w = agent.run_view(agent.conv1.weight)[k]
        reference = torch.nn.functional.conv2d(x, w, agent.run_view(agent.conv1.bias)[k], stride=4)
        got = agent._conv1_space_to_depth(obs)[:, k * 32:(k + 1) * 32]
        assert torch.allclose(got, reference, rtol=1e-5, atol=1e-5)
