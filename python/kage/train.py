"""PPO-CNN baseline of KAGE-Bench, in PyTorch, on kage.make_vec: train on one config, evaluate on it and
on one or more others, as the original's ppo_jax.py (and ppo_jax_multi_conf.py) do.

    python3 -m kage.train --train-config-path T --eval-config-path E --seed S [--device cuda|cpu] [--out DIR]

Read it top to bottom like CleanRL's ppo_atari_envpool.py: the flags (Args), the network, the losses,
the evaluation, the run directory, then the training loop. "§x.y" refers to the section of the baseline
specification (kage-ppo-baseline.md) that a line implements. Quirks of the original are kept by default
and marked QUIRK; a flag offers the corrected behaviour where one makes sense:
- truncation is treated as termination (no bootstrap across the 500-step limit): --bootstrap-truncation;
- evaluation samples its actions: --eval-greedy takes the most likely action instead;
- `success` is recomputed with a strict `>` at the terminal state, and the plots labelled "success rate"
  show `success_once`: both are logged, the report says which it shows.
Not offered: --target-kl (declared and never read by the original), videos, Weights & Biases.

The environment and the learner share the device: observations, actions, rewards and episode metrics
never leave it during a rollout or an evaluation; the host reads a few scalars once per iteration for
the log. A run directory holds everything needed to resume a killed run exactly (see RunDir).
"""
import argparse
import dataclasses
import math
import os
import random
import sys
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional

import numpy as np
import torch
import torch.nn as nn

import kage
from kage import rundir
from kage.wrappers import FrameStack, RewardNormalizer

METRICS = ("x", "y", "vx_mean", "vy_mean", "passed_distance", "progress", "jump_count", "success", "success_once")
DIFF_METRICS = ("return", "success", "progress", "success_once", "passed_distance", "jump_count")  # §3.3
TRAIN_OFFSET, EVAL_OFFSET, EVAL_OFFSET_STEP = 20_000, 10_000, 1_000  # §3.2


@dataclass
class Args:
    train_config_path: str = field(default="", metadata={"help": "the config to train on (YAML or kagec compile dir)"})
    eval_config_path: Optional[str] = field(default=None, metadata={"help": "the config to evaluate on (ppo_jax.py)"})
    eval_config_paths: List[str] = field(default_factory=list, metadata={
        "help": "several configs to evaluate on (ppo_jax_multi_conf.py, spec 3.5)"})
    eval_config_labels: List[str] = field(default_factory=list, metadata={
        "help": "labels of the eval configs (default: their file names)"})
    seed: int = field(default=1, metadata={"help": "seed of the run (spec 2.4)"})
    device: str = field(default="cuda", metadata={"help": "cuda or cpu (environments and learner)"})
    out: Optional[str] = field(default=None, metadata={
        "help": "run directory (default runs/<exp-name>__<train config>__<seed>); an unfinished one resumes"})
    exp_name: str = field(default="ppo_kage", metadata={"help": "name of the experiment"})
    threads: Optional[int] = field(default=None, metadata={"help": "CPU threads (default: all cores)"})
    asset_root: Optional[str] = field(default=None, metadata={"help": "resolve the configs' asset paths here"})
    # PPO (§2.1: the defaults of ppo_jax.py; the benchmark overrides none)
    total_timesteps: int = field(default=25_000_000, metadata={"help": "environment steps of the run"})
    learning_rate: float = field(default=5e-4, metadata={"help": "Adam learning rate"})
    num_envs: int = field(default=128, metadata={"help": "parallel training environments"})
    num_steps: int = field(default=128, metadata={"help": "steps per environment per rollout"})
    anneal_lr: bool = field(default=False, metadata={"help": "anneal the learning rate linearly (§2.6)"})
    gamma: float = field(default=0.999, metadata={"help": "discount"})
    gae_lambda: float = field(default=0.95, metadata={"help": "GAE lambda"})
    num_minibatches: int = field(default=8, metadata={"help": "minibatches per epoch"})
    update_epochs: int = field(default=3, metadata={"help": "epochs per update"})
    norm_adv: bool = field(default=True, metadata={"help": "normalise advantages per minibatch"})
    clip_coef: float = field(default=0.2, metadata={"help": "policy and value clipping"})
    clip_vloss: bool = field(default=True, metadata={"help": "clipped value loss"})
    ent_coef: float = field(default=0.01, metadata={"help": "entropy coefficient"})
    ent_coef_anneal: bool = field(default=False, metadata={"help": "anneal the entropy coefficient (§2.6)"})
    vf_coef: float = field(default=0.5, metadata={"help": "value loss coefficient"})
    max_grad_norm: float = field(default=0.5, metadata={"help": "global gradient norm clip"})
    normalize_reward: bool = field(default=False, metadata={"help": "per-environment reward normalisation"})
    reward_clip_min: float = field(default=-math.inf, metadata={"help": "lower reward clip"})
    reward_clip_max: float = field(default=math.inf, metadata={"help": "upper reward clip"})
    use_frame_stack: bool = field(default=False, metadata={"help": "stack the last 4 frames (§1.1)"})
    # Evaluation and checkpoints (§3)
    run_eval_every: int = field(default=50, metadata={"help": "iterations between evaluations (0: none)"})
    eval_episodes: int = field(default=128, metadata={"help": "episodes per config per evaluation"})
    eval_num_envs: int = field(default=32, metadata={"help": "parallel environments of an evaluation"})
    save_checkpoint_every: int = field(default=50, metadata={"help": "iterations between checkpoints (0: end only)"})
    # Corrections of the original's quirks (off: as the original)
    bootstrap_truncation: bool = field(default=False, metadata={
        "help": "bootstrap from the final observation at truncation (QUIRK off: truncation is termination)"})
    eval_greedy: bool = field(default=False, metadata={"help": "greedy evaluation (QUIRK off: sampled actions)"})

    @property
    def batch_size(self) -> int:
        return self.num_envs * self.num_steps

    @property
    def minibatch_size(self) -> int:
        return self.batch_size // self.num_minibatches

    @property
    def num_iterations(self) -> int:
        return self.total_timesteps // self.batch_size


def parse_args(argv: Optional[List[str]] = None) -> Args:
    """The flags of Args: --snake-case names, booleans as --flag / --no-flag."""
    parser = argparse.ArgumentParser(prog="python3 -m kage.train", description=__doc__.split("\n\n")[0])
    for f in dataclasses.fields(Args):
        flag = "--" + f.name.replace("_", "-")
        default = f.default_factory() if f.default_factory is not dataclasses.MISSING else f.default
        if f.type is bool:
            parser.add_argument(flag, action=argparse.BooleanOptionalAction, default=default, help=f.metadata["help"])
        elif f.type == List[str]:
            parser.add_argument(flag, nargs="+", default=default, help=f.metadata["help"])
        else:
            kind = next(t for t in (int, float, str) if f.type in (t, Optional[t]))
            parser.add_argument(flag, type=kind, default=default, help=f.metadata["help"])
    args = Args(**vars(parser.parse_args(argv)))
    problems = validate(args)
    if problems:
        parser.error("; ".join(problems))
    return args


def validate(args: Args) -> List[str]:
    """What is wrong with a combination of flags, each with its fix."""
    problems = []
    if not args.train_config_path:
        problems.append("--train-config-path is required")
    if args.eval_config_path and args.eval_config_paths:
        problems.append("give --eval-config-path or --eval-config-paths, not both")
    if args.device not in ("cuda", "cpu"):
        problems.append(f"--device {args.device}: use cuda or cpu")
    if args.num_envs <= 0 or args.num_steps <= 0:
        problems.append("--num-envs and --num-steps must be positive")
    elif args.batch_size % args.num_minibatches:
        problems.append(f"--num-minibatches {args.num_minibatches} must divide the batch (num_envs * num_steps "
                        f"= {args.batch_size})")
    elif args.num_iterations < 1:
        problems.append(f"--total-timesteps {args.total_timesteps} is less than one batch ({args.batch_size})")
    if args.run_eval_every < 0 or args.eval_episodes < 0 or args.eval_num_envs < 0:
        problems.append("--run-eval-every, --eval-episodes and --eval-num-envs must not be negative")
    n_evals = len(eval_paths(args))
    if args.eval_config_labels and len(args.eval_config_labels) != n_evals:
        problems.append(f"--eval-config-labels gives {len(args.eval_config_labels)} labels for {n_evals} eval configs")
    if n_evals > 10:
        problems.append("at most 10 eval configs (the 11th would reuse the train config's evaluation seeds, §3.5)")
    return problems


def eval_paths(args: Args) -> List[str]:
    return [args.eval_config_path] if args.eval_config_path else list(args.eval_config_paths)


def eval_labels(args: Args) -> List[str]:
    """Labels of the eval configs: given, or the file base name with spaces as underscores (§3.5)."""
    labels = args.eval_config_labels or [os.path.basename(p.rstrip("/")).replace(" ", "_") for p in eval_paths(args)]
    if len(set(labels)) != len(labels):
        raise SystemExit(f"kage.train: eval configs share a label ({labels}); name them with --eval-config-labels")
    return labels


# ---- the agent (§1) ----

def layer_init(layer: nn.Module, std: float = math.sqrt(2), bias_const: float = 0.0) -> nn.Module:
    """Orthogonal weights with gain `std`, constant biases (§1.3)."""
    nn.init.orthogonal_(layer.weight, std)
    nn.init.constant_(layer.bias, bias_const)
    return layer


class Agent(nn.Module):
    """NatureCNN torso (no padding), a 512-unit layer and two linear heads (§1.2)."""

    def __init__(self, channels: int = 3, height: int = 128, width: int = 128):
        super().__init__()
        conv_h, conv_w = ((height - 8) // 4 + 1 - 4) // 2 + 1 - 2, ((width - 8) // 4 + 1 - 4) // 2 + 1 - 2
        self.network = nn.Sequential(
            layer_init(nn.Conv2d(channels, 32, 8, stride=4)), nn.ReLU(),
            layer_init(nn.Conv2d(32, 64, 4, stride=2)), nn.ReLU(),
            layer_init(nn.Conv2d(64, 64, 3, stride=1)), nn.ReLU(),
            nn.Flatten(),
            layer_init(nn.Linear(64 * conv_h * conv_w, 512)), nn.ReLU(),
        )
        self.actor = layer_init(nn.Linear(512, 8), std=0.01)
        self.critic = layer_init(nn.Linear(512, 1), std=1.0)

    def features(self, obs: torch.Tensor) -> torch.Tensor:
        """uint8 [B, H, W, C] frames -> [B, 512]; the first operation is /255 in float32 (§1.1)."""
        return self.network(obs.permute(0, 3, 1, 2).float() / 255.0)

    def get_value(self, obs: torch.Tensor) -> torch.Tensor:
        return self.critic(self.features(obs)).squeeze(-1)

    def get_logits_and_value(self, obs: torch.Tensor):
        hidden = self.features(obs)
        return self.actor(hidden), self.critic(hidden).squeeze(-1)


def sample_gumbel_max(logits: torch.Tensor, generator: torch.Generator):
    """Categorical sampling by the Gumbel-max trick, as the rollout does (§1.4): the action and its
    log-probability."""
    u = torch.rand(logits.shape, generator=generator, device=logits.device)
    action = torch.argmax(logits - torch.log(-torch.log(u)), dim=1)
    logprob = torch.log_softmax(logits, dim=1).gather(1, action[:, None]).squeeze(1)
    return action, logprob


def entropy_of(logits: torch.Tensor) -> torch.Tensor:
    """Entropy from log-softmax logits clipped at the smallest float32, so p log p is never 0 * -inf."""
    log_p = torch.log_softmax(logits, dim=1).clamp(min=torch.finfo(logits.dtype).min)
    return -(log_p.exp() * log_p).sum(1)


# ---- the algorithm's arithmetic (§2.5 step 3, §2.6) ----

def compute_gae(rewards, values, dones, next_value, next_done, gamma: float, gae_lambda: float):
    """Advantages and returns over a [T, N] rollout (§2.5 step 3). dones[t] is true iff obs[t] starts an
    episode; next_done / next_value belong to the observation after the last step."""
    num_steps = rewards.shape[0]
    advantages = torch.zeros_like(rewards)
    last_gae = torch.zeros_like(next_value)
    for t in reversed(range(num_steps)):
        if t == num_steps - 1:
            nonterminal, next_values = 1.0 - next_done, next_value
        else:
            nonterminal, next_values = 1.0 - dones[t + 1], values[t + 1]
        delta = rewards[t] + gamma * next_values * nonterminal - values[t]
        last_gae = delta + gamma * gae_lambda * nonterminal * last_gae
        advantages[t] = last_gae
    return advantages, advantages + values


def ppo_loss(new_logprob, entropy, new_value, old_logprob, old_value, advantages, returns, args: Args, ent_coef: float):
    """The minibatch loss of §2.6 and its diagnostics: (loss, pg_loss, v_loss, entropy, approx_kl, clipfrac)."""
    logratio = new_logprob - old_logprob
    ratio = logratio.exp()
    with torch.no_grad():
        approx_kl = ((ratio - 1) - logratio).mean()
        clipfrac = ((ratio - 1.0).abs() > args.clip_coef).float().mean()
    if args.norm_adv:
        # Population standard deviation (divide by n), as the original's jnp.std.
        advantages = (advantages - advantages.mean()) / (advantages.std(unbiased=False) + 1e-8)
    pg_loss = torch.max(-advantages * ratio, -advantages * ratio.clamp(1 - args.clip_coef, 1 + args.clip_coef)).mean()
    if args.clip_vloss:
        v_clipped = old_value + (new_value - old_value).clamp(-args.clip_coef, args.clip_coef)
        v_loss = 0.5 * torch.max((new_value - returns) ** 2, (v_clipped - returns) ** 2).mean()
    else:
        v_loss = 0.5 * ((new_value - returns) ** 2).mean()
    entropy_loss = entropy.mean()
    loss = pg_loss - ent_coef * entropy_loss + v_loss * args.vf_coef
    return loss, pg_loss, v_loss, entropy_loss, approx_kl, clipfrac


def entropy_coefficient(args: Args, optimizer_steps: int) -> float:
    """§2.6: constant, or annealed from the optimiser steps taken so far."""
    if not args.ent_coef_anneal:
        return args.ent_coef
    total = args.num_iterations * args.update_epochs * args.num_minibatches
    return args.ent_coef * min(max(1.0 - optimizer_steps / total, 0.0), 1.0)


# ---- episode metrics (§4) ----

class EpisodeMetrics:
    """Device views of a batch's finished-episode fields, read each step without a copy (§4.1)."""

    def __init__(self, env: "kage.VecEnv", info: dict, dist_to_success: float):
        final = info["final_info"]
        self.mask = torch.from_dlpack(info["_final"])
        self.fields = {name: torch.from_dlpack(final[name]) for name in ("return", "length") + METRICS}
        self.dist_to_success = dist_to_success

    def rows(self) -> torch.Tensor:
        """[12, N] float32: finished mask, return, length and the nine metrics of §4.1. QUIRK: success is
        recomputed with a strict > at the terminal state (the core uses >=)."""
        f = self.fields
        success = (f["passed_distance"] > self.dist_to_success).float()
        values = [self.mask.float(), f["return"], f["length"].float()]
        values += [success if m == "success" else f[m].float() for m in METRICS]
        return torch.stack(values)


@torch.no_grad()
def evaluate(agent: Agent, envs: List["kage.VecEnv"], seeds: List[int], dists_to_success: List[float], episodes: int,
             episode_length: int, greedy: bool, frame_stack: bool) -> List[Dict[str, Optional[float]]]:
    """The evaluations of several configs (§3.2), each in fresh environments with its own seed and
    sampling stream, stepped together: one forward pass per step for all their environments. Sampled
    actions until `episodes` episodes have finished in each. Steps are queued without a host
    synchronisation: every KAGE episode ends by truncation at `episode_length` (§2.3), so
    ceil(episodes / envs) waves of episode_length steps finish them; the host checks the counts once,
    after the waves (and steps on, a wave at a time, if one fell short)."""
    device = next(agent.parameters()).device
    generators = [torch.Generator(device=device).manual_seed(seed) for seed in seeds]
    frames, stacks, metrics = [], [], []
    for env, seed, dist in zip(envs, seeds, dists_to_success):
        obs, info = env.reset(seed=seed)
        frames.append(torch.from_dlpack(obs))
        stacks.append(FrameStack(frames[-1]) if frame_stack else None)
        metrics.append(EpisodeMetrics(env, info, dist))
    chunk = -(-episodes // min(env.num_envs for env in envs)) * episode_length
    records: List[List[torch.Tensor]] = [[] for _ in envs]
    while True:
        for _ in range(chunk):
            x = torch.cat([s.stack if s else f for f, s in zip(frames, stacks)])
            logits = agent.actor(agent.features(x)).split([env.num_envs for env in envs])
            for env, logit, generator, frame, stack, metric, record in zip(envs, logits, generators, frames, stacks,
                                                                           metrics, records):
                # QUIRK: sampled, not greedy. Gumbel-max is an exact categorical sampler with no host check.
                env.step(logit.argmax(1) if greedy else sample_gumbel_max(logit, generator)[0])
                if stack:
                    stack.push(frame, metric.mask)
                record.append(metric.rows())
        counts = torch.stack([torch.stack(r)[:, 0].sum() for r in records]).tolist()
        if min(counts) >= episodes:
            break
    return [summarize_evaluation(torch.stack(r).cpu(), episodes) for r in records]


def summarize_evaluation(records: torch.Tensor, episodes: int) -> Dict[str, Optional[float]]:
    """§3.2 steps 3-4 from [steps, 12, N] records: return and length are means over the first `episodes`
    finished episodes (in step, then environment order) whose return is not exactly 0 (QUIRK: zero
    returns dropped; all zero gives no value); each metric is its sum over every episode that finished
    up to the step where the count reached `episodes`, over max(1, that number)."""
    finished = records[:, 0] > 0                                           # [S, N]
    per_step = finished.sum(1).cumsum(0)
    last_step = int(torch.nonzero(per_step >= episodes)[0]) if bool((per_step >= episodes).any()) else len(per_step) - 1
    upto = records[: last_step + 1]
    mask = finished[: last_step + 1]
    values = upto.permute(0, 2, 1)[mask]                                   # [episodes finished, 12], step-major
    listed = values[:episodes]
    nonzero = listed[:, 1] != 0
    result: Dict[str, Optional[float]] = {
        "episodes": int(values.shape[0]),
        "return": float(listed[nonzero, 1].mean()) if bool(nonzero.any()) else None,
        "length": float(listed[nonzero, 2].mean()) if bool(nonzero.any()) else None,
    }
    count = max(1, values.shape[0])
    for i, m in enumerate(METRICS):
        result[m] = float(values[:, 3 + i].sum() / count)
    return result


def evaluation_point(agent, eval_envs, args: Args, iteration: int, global_step: int, specs) -> dict:
    """Evaluates the current parameters on the train config and on each eval config (§3.2; seed offsets
    20,000 for the train config, 10,000 + 1,000 i for the i-th eval config), and the absolute
    differences train - eval (§3.3)."""
    start = time.perf_counter()
    was_training = agent.training
    agent.eval()
    labels = list(eval_envs)
    seeds = [args.seed + (TRAIN_OFFSET if i == 0 else EVAL_OFFSET + EVAL_OFFSET_STEP * (i - 1)) + iteration
             for i in range(len(labels))]
    configs = [specs[label]["config"] for label in labels]
    results = dict(zip(labels, evaluate(agent, list(eval_envs.values()), seeds,
                                        [c["dist_to_success"] for c in configs], args.eval_episodes,
                                        max(c["episode_length"] for c in configs), args.eval_greedy,
                                        args.use_frame_stack)))
    agent.train(was_training)
    train_label, *labels = list(eval_envs)
    diffs = {label: {m: absolute_difference(results[train_label][m], results[label][m]) for m in DIFF_METRICS}
             for label in labels}
    return {"kind": "eval", "iteration": iteration, "global_step": global_step, "train": results[train_label],
            "evals": {label: results[label] for label in labels}, "diffs": diffs,
            "seconds": time.perf_counter() - start}


def absolute_difference(a: Optional[float], b: Optional[float]) -> Optional[float]:
    return None if a is None or b is None else abs(a - b)


# ---- the training loop (§2.5) ----

def main(argv: Optional[List[str]] = None) -> int:
    args = parse_args(argv)
    run = rundir.RunDir.open(args, labels=eval_labels(args))
    if run.finished:
        print(f"kage.train: {run.path} is finished (summary.json); nothing to do", file=sys.stderr)
        return 0
    if args.device == "cuda" and not torch.cuda.is_available():
        raise SystemExit("kage.train: --device cuda, but torch sees no GPU: use --device cpu")
    device = torch.device(args.device)
    threads = args.threads or os.cpu_count() or 1
    torch.set_num_threads(threads)
    if device.type == "cuda":
        torch.backends.cudnn.benchmark = True
        torch.set_float32_matmul_precision("high")  # TF32, as JAX's default precision on this GPU

    # §2.4: one seed for Python, numpy and torch (the network's initialisation); the rollout's own stream.
    random.seed(args.seed)
    np.random.seed(args.seed)
    torch.manual_seed(args.seed)
    rng = torch.Generator(device=device).manual_seed(args.seed)

    specs = run.specs
    train_spec = specs["train"]["config"]
    env = kage.make_vec(args.train_config_path, args.num_envs, device=args.device, seed=args.seed,
                        asset_root=args.asset_root, threads=threads)
    eval_envs = {}
    if args.run_eval_every > 0 and args.eval_episodes > 0 and args.eval_num_envs > 0:
        for label, path in [("train", args.train_config_path)] + list(zip(eval_labels(args), eval_paths(args))):
            eval_envs[label] = kage.make_vec(path, args.eval_num_envs, device=args.device, asset_root=args.asset_root,
                                             threads=threads)
    height, width, channels = env.single_observation_space.shape
    channels *= 4 if args.use_frame_stack else 1
    agent = Agent(channels, height, width).to(device)
    optimizer = torch.optim.Adam(agent.parameters(), lr=args.learning_rate, eps=1e-5)

    # Rollout storage, [T, N, ...] on the device (§2.5 step 1d).
    T, N = args.num_steps, args.num_envs
    obs = torch.zeros((T, N, height, width, channels), dtype=torch.uint8, device=device)
    actions = torch.zeros((T, N), dtype=torch.long, device=device)
    logprobs = torch.zeros((T, N), device=device)
    rewards = torch.zeros((T, N), device=device)
    dones = torch.zeros((T, N), device=device)
    values = torch.zeros((T, N), device=device)

    env.reset(seed=kage.env_seeds(args.seed, N))
    # Views of the runtime's buffers, which every step rewrites in place.
    env_obs, env_reward, env_terminated, env_truncated, env_info = env.outputs()
    frame = torch.from_dlpack(env_obs)
    env_reward, env_terminated, env_truncated = (torch.from_dlpack(a) for a in (env_reward, env_terminated, env_truncated))
    episode = EpisodeMetrics(env, env_info, train_spec["dist_to_success"])
    final_obs = torch.from_dlpack(env_info["final_obs"])
    stack = FrameStack(frame) if args.use_frame_stack else None
    normalizer = RewardNormalizer(N, args.gamma, device) if args.normalize_reward else None
    next_obs = stack.stack if stack else frame
    next_done = torch.zeros(N, device=device)
    last_return = torch.zeros(N, device=device)  # §4.2: each environment's most recent episode
    last_length = torch.zeros(N, device=device)
    any_finished = torch.zeros((), dtype=torch.bool, device=device)
    history: List[dict] = []
    start_iteration, global_step, optimizer_steps, train_seconds = 1, 0, 0, 0.0

    checkpoint = run.load_checkpoint(device)
    if checkpoint is not None:  # resume: everything the loop carries, then the environments' state
        agent.load_state_dict(checkpoint["agent"])
        optimizer.load_state_dict(checkpoint["optimizer"])
        rng.set_state(checkpoint["rng"])
        torch.set_rng_state(checkpoint["torch_rng"])
        env.load_state(checkpoint["env_state"])
        next_done, last_return, last_length = (checkpoint[k].to(device) for k in ("next_done", "last_return", "last_length"))
        any_finished = checkpoint["any_finished"].to(device)
        if stack:
            stack.stack = checkpoint["frame_stack"].to(device)
        if normalizer:
            normalizer.load_state_dict({k: v.to(device) for k, v in checkpoint["normalizer"].items()})
        next_obs = stack.stack if stack else frame
        history = checkpoint["history"]
        start_iteration, global_step = checkpoint["iteration"] + 1, checkpoint["global_step"]
        optimizer_steps, train_seconds = checkpoint["optimizer_steps"], checkpoint["train_seconds"]
        print(f"kage.train: resuming {run.path} after iteration {checkpoint['iteration']}", file=sys.stderr)
    elif eval_envs:
        history.append(run.log(evaluation_point(agent, eval_envs, args, 0, 0, specs)))  # §3.1: the untrained policy

    def save_checkpoint(iteration: int) -> None:
        run.save_checkpoint({
            "iteration": iteration, "global_step": global_step, "optimizer_steps": optimizer_steps,
            "train_seconds": train_seconds, "agent": agent.state_dict(), "optimizer": optimizer.state_dict(),
            "rng": rng.get_state(), "torch_rng": torch.get_rng_state(), "env_state": env.save_state(),
            "next_done": next_done, "last_return": last_return, "last_length": last_length,
            "any_finished": any_finished, "frame_stack": stack.stack if stack else None,
            "normalizer": normalizer.state_dict() if normalizer else None, "history": history,
        })

    progress = rundir.Progress(args.num_iterations, args.batch_size)
    for iteration in range(start_iteration, args.num_iterations + 1):
        iteration_start = time.perf_counter()
        if args.anneal_lr:  # §2.6
            optimizer.param_groups[0]["lr"] = args.learning_rate * (1.0 - (iteration - 1.0) / args.num_iterations)
        episode_sums = torch.zeros(len(METRICS) + 1, device=device)  # count, then the nine metrics

        for step in range(T):  # §2.5 step 1
            obs[step] = next_obs
            dones[step] = next_done
            with torch.no_grad():
                logits, value = agent.get_logits_and_value(next_obs)
                action, logprob = sample_gumbel_max(logits, rng)
            values[step], actions[step], logprobs[step] = value, action, logprob
            env.step(action)
            reward = env_reward.clone()
            next_done = (env_terminated | env_truncated).float()  # QUIRK: truncation is termination (§2.5 b)
            rows = episode.rows()
            finished = rows[0]
            if args.bootstrap_truncation:
                with torch.no_grad():  # the value of the observation the truncation discarded
                    reward += args.gamma * agent.get_value(final_obs) * env_truncated.float() * finished
            if normalizer:
                reward = normalizer(reward, next_done)
            rewards[step] = reward.clamp(args.reward_clip_min, args.reward_clip_max)
            # §4.2: sums of the finished episodes' metrics; each environment's latest return and length.
            episode_sums += torch.cat([finished.sum()[None], (rows[3:] * finished).sum(1)])
            last_return = torch.where(finished > 0, rows[1], last_return)
            last_length = torch.where(finished > 0, rows[2], last_length)
            any_finished |= finished.any()
            next_obs = stack.push(frame, next_done) if stack else frame
        global_step += args.batch_size  # §2.5 step 2

        with torch.no_grad():  # §2.5 step 3
            next_value = agent.get_value(next_obs)
            advantages, returns = compute_gae(rewards, values, dones, next_value, next_done, args.gamma,
                                              args.gae_lambda)

        # §2.5 step 4: E epochs of M minibatches over the flattened (time-major) batch.
        b_obs = obs.reshape((-1, height, width, channels))
        b_logprobs, b_actions = logprobs.reshape(-1), actions.reshape(-1)
        b_advantages, b_returns, b_values = advantages.reshape(-1), returns.reshape(-1), values.reshape(-1)
        for epoch in range(args.update_epochs):
            ent_coef = entropy_coefficient(args, optimizer_steps)
            permutation = torch.randperm(args.batch_size, generator=rng, device=device)
            for start in range(0, args.batch_size, args.minibatch_size):
                mb = permutation[start:start + args.minibatch_size]
                logits, new_value = agent.get_logits_and_value(b_obs[mb])
                new_logprob = torch.log_softmax(logits, 1).gather(1, b_actions[mb, None]).squeeze(1)
                loss, pg_loss, v_loss, entropy, approx_kl, clipfrac = ppo_loss(
                    new_logprob, entropy_of(logits), new_value, b_logprobs[mb], b_values[mb], b_advantages[mb],
                    b_returns[mb], args, ent_coef)
                optimizer.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(agent.parameters(), args.max_grad_norm)
                optimizer.step()
                optimizer_steps += 1

        # §2.5 step 5, §4.3: losses of the last minibatch; the host reads the scalars once.
        var_returns = b_returns.var(unbiased=False)
        explained_var = 1 - (b_returns - b_values).var(unbiased=False) / (var_returns + 1e-8)
        stored = last_return != 0
        scalars = torch.cat([torch.stack([v_loss, pg_loss, entropy, approx_kl, clipfrac, loss, explained_var,
                                          var_returns, torch.where(stored, last_return, 0).sum() / stored.sum().clamp(min=1),
                                          torch.where(stored, last_length, 0).sum() / stored.sum().clamp(min=1),
                                          any_finished.float()]), episode_sums]).tolist()
        sums = scalars[11:]
        iteration_seconds = time.perf_counter() - iteration_start
        train_seconds += iteration_seconds
        row = {"kind": "train", "iteration": iteration, "global_step": global_step,
               "charts/learning_rate": optimizer.param_groups[0]["lr"], "charts/entropy_coef": ent_coef,
               "charts/SPS": global_step / train_seconds, "charts/SPS_update": args.batch_size / iteration_seconds,
               "losses/value_loss": scalars[0], "losses/policy_loss": scalars[1], "losses/entropy": scalars[2],
               "losses/approx_kl": scalars[3], "losses/clipfrac": scalars[4], "losses/loss": scalars[5]}
        if scalars[7] > 0:
            row["train/explained_variance"] = scalars[6]
        if scalars[10]:
            row["train/avg_completed_episodic_return"] = scalars[8]
            row["train/avg_completed_episodic_length"] = scalars[9]
        if sums[0] > 0:
            row.update({f"train/avg_{m}": s / sums[0] for m, s in zip(METRICS, sums[1:])})
        run.log(row)

        evaluated = False
        if eval_envs and iteration % args.run_eval_every == 0:  # §2.5 step 6
            history.append(run.log(evaluation_point(agent, eval_envs, args, iteration, global_step, specs)))
            evaluated = True
        if iteration == args.num_iterations and eval_envs and not evaluated:  # §3.1: the final point
            history.append(run.log(evaluation_point(agent, eval_envs, args, iteration, global_step, specs)))
        if (args.save_checkpoint_every > 0 and iteration % args.save_checkpoint_every == 0) or \
                iteration == args.num_iterations:  # §2.5 step 7, and at the end
            save_checkpoint(iteration)
        progress.update(iteration, global_step, row, history[-1] if evaluated else None)

    run.finish(history)
    for e in [env, *eval_envs.values()]:
        e.close()
    print(f"kage.train: done, {run.path}/summary.json", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
