"""The one policy step of the baseline: the network's forward pass, then an action per environment, sampled by
the Gumbel-max trick (§1.4) from given uniforms or taken greedily, its log-probability and the value. The
rollout (through RolloutPolicy, which can replay it as a CUDA graph), the evaluation protocol and the videos
all act through policy_step."""
import contextlib

import torch


def autocast(bf16: bool):
    """bfloat16 autocast for the network under --bf16, else nothing."""
    return torch.autocast("cuda", dtype=torch.bfloat16) if bf16 else contextlib.nullcontext()


def sample_gumbel_max(logits: torch.Tensor, uniform: torch.Tensor):
    """Categorical sampling by the Gumbel-max trick (§1.4): the action and its log-probability."""
    action = torch.argmax(logits - torch.log(-torch.log(uniform)), dim=-1)
    logprob = torch.log_softmax(logits.float(), dim=-1).gather(-1, action[..., None]).squeeze(-1)
    return action, logprob


def policy_step(agent, obs: torch.Tensor, uniform: torch.Tensor, *, bf16: bool = False, greedy: bool = False):
    """obs uint8 [K, B, H, W, C] and uniform [K, B, A] in (0, 1) -> action (int64), log-probability and value
    (float32), each [K, B]. Greedy takes the most likely action (the uniforms are then unused)."""
    with autocast(bf16):
        logits, value = agent(obs)
    logits = logits.float()
    if greedy:
        action = logits.argmax(-1)
        logprob = torch.log_softmax(logits, dim=-1).gather(-1, action[..., None]).squeeze(-1)
    else:
        action, logprob = sample_gumbel_max(logits, uniform)
    return action, logprob, value.float()


class RolloutPolicy:
    """The rollout's policy step: forward, Gumbel-max sampling (§1.4) with the given uniforms, the
    log-probability and the value. Under --cuda-graph it is captured once and replayed each step from
    static input buffers."""

    def __init__(self, policy, obs_shape, num_actions: int, device, *, bf16: bool = False, cuda_graph: bool = False):
        self.policy, self.bf16 = policy, bf16
        self.graph = None
        if cuda_graph:
            self.obs = torch.zeros(obs_shape, dtype=torch.uint8, device=device)
            self.uniform = torch.full((*obs_shape[:2], num_actions), 0.5, device=device)
            side = torch.cuda.Stream()
            side.wait_stream(torch.cuda.current_stream())
            with torch.cuda.stream(side), torch.no_grad():
                for _ in range(3):  # warm-up: cuDNN picks its algorithms outside the capture
                    self._step()
            torch.cuda.current_stream().wait_stream(side)
            self.graph = torch.cuda.CUDAGraph()
            with torch.cuda.graph(self.graph), torch.no_grad():
                self.outputs = self._step()

    def _step(self):
        return policy_step(self.policy, self.obs, self.uniform, bf16=self.bf16)

    @torch.no_grad()
    def __call__(self, obs: torch.Tensor, uniform: torch.Tensor):
        """obs [K, N, H, W, C] uint8, uniform [K, N, A] in (0, 1) -> action, log-probability, value [K, N]."""
        if self.graph is None:
            self.obs, self.uniform = obs, uniform
            return self._step()
        self.obs.copy_(obs)
        self.uniform.copy_(uniform)
        self.graph.replay()
        return self.outputs

