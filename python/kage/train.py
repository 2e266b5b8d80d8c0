"""PPO-CNN baseline of KAGE-Bench, in PyTorch, on kage.make_vec: train on one config, evaluate on it and
on one or more others, as the original's ppo_jax.py (and ppo_jax_multi_conf.py) do.

    python3 -m kage.train --train-config-path T --eval-config-path E --seed S [--device cuda|cpu] [--out DIR]

Read it top to bottom like CleanRL's ppo_atari_envpool.py: the flags (Args), the losses, then the
training loop; the network is kage.agent (§1), the evaluation and its metrics kage.evaluation (§3-4).
"§x.y" refers to the section of the baseline specification (kage-ppo-baseline.md) that a line implements.
Quirks of the original are kept by default and marked QUIRK; a flag offers the corrected behaviour where
one makes sense:
- truncation is treated as termination (no bootstrap across the 500-step limit): --bootstrap-truncation;
- evaluation samples its actions: --eval-greedy takes the most likely action instead;
- `success` is recomputed with a strict `>` at the terminal state, and the plots labelled "success rate"
  show `success_once`: both are logged.
Not offered: --target-kl (declared and never read by the original), Weights & Biases.

Your own agent: --agent module:factory builds the network, --augment module:fn transforms the update's
minibatches (kage.plugins); the rest of the protocol is the same for every agent. Videos: kage.video;
TensorBoard scalars under the original's tags, where tensorboard is importable: kage.tensorboard_log.

Packing: the loop trains K runs at once (K = 1 for a lone run; `kage.bench run --pack K`). Each run has its
own parameters, optimizer state, random streams, environments and run directory, and follows the same
algorithm as alone; tensors carry a leading run axis [K, ...], and one grouped forward and one backward
per rollout step and per minibatch serve all K runs, so the learner's kernel launches do not grow with K.

The environments and the learner share the device: observations, actions, rewards and episode metrics
never leave it during a rollout or an evaluation; the host reads a few scalars once per iteration for
the log. A run directory holds everything needed to resume a killed run exactly (kage.rundir).
"""
import argparse
import contextlib
import dataclasses
import importlib.util
import json
import math
import os
import sys
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

import torch

import kage
from kage import plugins, rundir, tensorboard_log, video
from kage.agent import Agent, RolloutPolicy, autocast, entropy_of
from kage.stop import StopRequest
from kage.counter_random import CounterRandom
from kage.evaluation import METRICS, EpisodeMetrics, evaluation_rows
from kage.wrappers import FrameStack, RewardNormalizer

ACTION_STREAM, SHUFFLE_STREAM = 1, 2  # the two random streams of a run (§2.4); evaluations use their own keys
AUGMENT_STREAM = 3  # --augment's draws (not in the original)


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
    # Your own agent (kage.plugins)
    agent: str = field(default=plugins.BASELINE_AGENT, metadata={
        "help": "module:factory building the policy network (default: the baseline's Nature CNN)"})
    augment: Optional[str] = field(default=None, metadata={
        "help": "module:fn augmenting the update's minibatches, never evaluations (e.g. kage.augment:random_shift)"})
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
    video_every: int = field(default=0, metadata={
        "help": "record an episode per config (videos/<label>_iter_<i>.gif) at the evaluation points whose "
                "iteration is a multiple of this (0: never)"})
    # Corrections of the original's quirks (off: as the original)
    bootstrap_truncation: bool = field(default=False, metadata={
        "help": "bootstrap from the final observation at truncation (QUIRK off: truncation is termination)"})
    eval_greedy: bool = field(default=False, metadata={"help": "greedy evaluation (QUIRK off: sampled actions)"})
    # Speed (off: plain eager float32; see kage.bench speed)
    bf16: bool = field(default=False, metadata={"help": "bfloat16 autocast for the network (GPU)"})
    channels_last: bool = field(default=False, metadata={"help": "channels-last convolutions"})
    cuda_graph: bool = field(default=False, metadata={"help": "replay the rollout's policy step as a CUDA graph"})
    fused_input: bool = field(default=False, metadata={
        "help": "one pass from uint8 frames to 4x4 blocks in the network's dtype; conv1 as the equal 2x2 conv"})
    triton_conv: bool = field(default=False, metadata={
        "help": "the convolutions as Triton implicit-GEMM kernels with the runs as a batch index, not cuDNN's "
                "channel groups (needs --fused-input, CUDA and triton)"})

    @property
    def batch_size(self) -> int:
        return self.num_envs * self.num_steps

    @property
    def minibatch_size(self) -> int:
        return self.batch_size // self.num_minibatches

    @property
    def num_iterations(self) -> int:
        return self.total_timesteps // self.batch_size


# The arguments that differ between the runs of a pack; the others are the pack's, shared.
PER_RUN = ("train_config_path", "eval_config_path", "eval_config_paths", "eval_config_labels", "seed", "out",
           "exp_name")


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
    parser.add_argument("--pack", help="train the runs listed in this JSON file together (written by kage.bench)")
    namespace = vars(parser.parse_args(argv))
    pack = namespace.pop("pack")
    if pack:
        with open(pack) as f:
            return [Args(**run) for run in json.load(f)["runs"]]
    args = Args(**namespace)
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
    if args.device == "cpu" and (args.bf16 or args.cuda_graph):
        problems.append("--bf16 and --cuda-graph are for --device cuda")
    if args.video_every < 0:
        problems.append("--video-every must not be negative")
    if args.agent != plugins.BASELINE_AGENT and (args.fused_input or args.channels_last or args.triton_conv):
        problems.append("--fused-input, --channels-last and --triton-conv rewrite the baseline's network: drop them "
                        "with --agent")
    if args.triton_conv and args.device == "cpu":
        problems.append("--triton-conv is for --device cuda")
    if args.triton_conv and not args.fused_input:
        problems.append("--triton-conv runs conv1 on --fused-input's 4x4 blocks: add --fused-input")
    if args.triton_conv and importlib.util.find_spec("triton") is None:
        problems.append("--triton-conv needs the triton package (it comes with PyTorch's CUDA builds): install it, "
                        "or drop --triton-conv")
    return problems


def eval_paths(args: Args) -> List[str]:
    return [args.eval_config_path] if args.eval_config_path else list(args.eval_config_paths)


def configs_of(args: Args) -> List[Tuple[str, str]]:
    """(label, path) of the configs a run evaluates on: "train" first, then the eval configs."""
    return [("train", args.train_config_path)] + list(zip(eval_labels(args), eval_paths(args)))


def eval_labels(args: Args) -> List[str]:
    """Labels of the eval configs: given, or the file base name with spaces as underscores (§3.5)."""
    labels = args.eval_config_labels or [os.path.basename(p.rstrip("/")).replace(" ", "_") for p in eval_paths(args)]
    if len(set(labels)) != len(labels):
        raise SystemExit(f"kage.train: eval configs share a label ({labels}); name them with --eval-config-labels")
    return labels


# ---- the algorithm's arithmetic (§2.5 step 3, §2.6), with any leading run axes ----

def compute_gae(rewards, values, dones, next_value, next_done, gamma: float, gae_lambda: float):
    """Advantages and returns over a [T, ...] rollout (§2.5 step 3). dones[t] is true iff obs[t] starts an
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
    """The minibatch loss of §2.6 and its diagnostics, reduced over the last axis (a run's minibatch):
    (loss, pg_loss, v_loss, entropy, approx_kl, clipfrac), each [K] (or a scalar without a run axis)."""
    logratio = new_logprob - old_logprob
    ratio = logratio.exp()
    with torch.no_grad():
        approx_kl = ((ratio - 1) - logratio).mean(-1)
        clipfrac = ((ratio - 1.0).abs() > args.clip_coef).float().mean(-1)
    if args.norm_adv:
        # Population standard deviation (divide by n), as the original's jnp.std.
        mean = advantages.mean(-1, keepdim=True)
        advantages = (advantages - mean) / (advantages.std(-1, unbiased=False, keepdim=True) + 1e-8)
    pg_loss = torch.max(-advantages * ratio, -advantages * ratio.clamp(1 - args.clip_coef, 1 + args.clip_coef)).mean(-1)
    if args.clip_vloss:
        v_clipped = old_value + (new_value - old_value).clamp(-args.clip_coef, args.clip_coef)
        v_loss = 0.5 * torch.max((new_value - returns) ** 2, (v_clipped - returns) ** 2).mean(-1)
    else:
        v_loss = 0.5 * ((new_value - returns) ** 2).mean(-1)
    entropy_loss = entropy.mean(-1)
    loss = pg_loss - ent_coef * entropy_loss + v_loss * args.vf_coef
    return loss, pg_loss, v_loss, entropy_loss, approx_kl, clipfrac


def entropy_coefficient(args: Args, optimizer_steps: int) -> float:
    """§2.6: constant, or annealed from the optimiser steps taken so far."""
    if not args.ent_coef_anneal:
        return args.ent_coef
    total = args.num_iterations * args.update_epochs * args.num_minibatches
    return args.ent_coef * min(max(1.0 - optimizer_steps / total, 0.0), 1.0)


def clip_grad_norm_per_run(agent: Agent, max_norm: float) -> torch.Tensor:
    """Scales each run's gradients by max_norm / max(norm, max_norm), its norm taken over all its
    parameters (Optax's clip_by_global_norm, §2.1); returns the [K] norms."""
    grads = [agent.run_view(p.grad) for p in agent.parameters()]
    norm = torch.stack([g.pow(2).sum(tuple(range(1, g.dim()))) for g in grads]).sum(0).sqrt()
    scale = max_norm / torch.maximum(norm, torch.full_like(norm, max_norm))
    for g in grads:
        g.mul_(scale.view(-1, *[1] * (g.dim() - 1)))
    return norm


# ---- the runs of a pack ----

@dataclass
class Run:
    """What a run owns besides its slice of the network: its arguments, directory and environments."""
    args: Args
    dir: rundir.RunDir
    env: "kage.VecEnv"
    eval_envs: Dict[str, "kage.VecEnv"]  # "train", then the eval configs by label
    specs: Dict[str, dict]
    history: List[dict] = field(default_factory=list)


def open_run(args: Args, threads: int) -> Run:
    run_dir = rundir.RunDir.open(args, configs_of(args))
    env = kage.make_vec(args.train_config_path, args.num_envs, device=args.device, seed=args.seed,
                        asset_root=args.asset_root, threads=threads)
    eval_envs = {}
    if args.run_eval_every > 0 and args.eval_episodes > 0 and args.eval_num_envs > 0:
        for label, path in configs_of(args):
            eval_envs[label] = kage.make_vec(path, args.eval_num_envs, device=args.device, asset_root=args.asset_root,
                                             threads=threads)
    return Run(args, run_dir, env, eval_envs, run_dir.specs)


def check_pack(runs: List[Args]) -> Args:
    """The pack's shared arguments: every run must agree on all but PER_RUN and on the number of eval configs."""
    first = dataclasses.asdict(runs[0])
    for args in runs[1:]:
        other = dataclasses.asdict(args)
        differ = [k for k in first if k not in PER_RUN and first[k] != other[k]]
        if differ:
            raise SystemExit(f"kage.train: packed runs must share {', '.join(differ)}")
        if len(eval_paths(args)) != len(eval_paths(runs[0])):
            raise SystemExit("kage.train: packed runs must evaluate the same number of configs")
    return runs[0]


class NoTimer:
    """The phases of an iteration, timed only by kage.bench speed (kage.bench.speed.PhaseTimer)."""

    def __call__(self, phase: str):
        return contextlib.nullcontext()

    def end_iteration(self) -> None:
        pass


# ---- the training loop (§2.5) ----

def train(pack: List[Args], timer=None, stop_after: Optional[int] = None,
          stop: Optional[StopRequest] = None) -> List[Run]:
    """Trains the runs of `pack` together (one for a lone run) to the end, or `stop_after` iterations past
    where they start (kage.bench speed). Resumes each run from its checkpoint if it has one. Once `stop` is
    requested (a signal), checkpoints after the running iteration and exits."""
    args = check_pack(pack)
    stop = stop or StopRequest("kage.train", "")
    timer = timer or NoTimer()
    if args.device == "cuda" and not torch.cuda.is_available():
        raise SystemExit("kage.train: --device cuda, but torch sees no GPU: use --device cpu")
    device = torch.device(args.device)
    threads = args.threads or os.cpu_count() or 1
    torch.set_num_threads(threads)
    if device.type == "cuda":
        torch.backends.cudnn.benchmark = True
        torch.set_float32_matmul_precision("high")  # TF32, as JAX's default precision on this GPU

    runs = [open_run(a, threads) for a in pack]
    K, T, N = len(runs), args.num_steps, args.num_envs
    height, width, channels = runs[0].env.single_observation_space.shape
    channels *= 4 if args.use_frame_stack else 1
    num_actions = runs[0].env.single_action_space.n
    agent = plugins.build_agent(args.agent, (height, width, channels), num_actions, [a.seed for a in pack],
                                device)  # §2.4: the runs' seeds
    if isinstance(agent, Agent):  # the baseline's speed options
        if args.channels_last:
            agent = agent.to(memory_format=torch.channels_last)
        if args.bf16:
            agent.input_dtype = torch.bfloat16
        agent.space_to_depth = args.fused_input
        agent.triton_conv = args.triton_conv
    augment = plugins.load_augment(args.augment)
    agent_spec = {"agent": args.agent, "observation_shape": [height, width, channels], "num_actions": num_actions,
                  "use_frame_stack": args.use_frame_stack}  # what kage.evaluate needs to rebuild a run's policy
    optimizer = torch.optim.Adam(agent.parameters(), lr=args.learning_rate, eps=1e-5)
    random = CounterRandom([a.seed for a in pack], device)
    counter = torch.zeros((), dtype=torch.int64, device=device)  # set by fill_: no host-to-device copy

    # Rollout storage, [T, K, N, ...] on the device (§2.5 step 1d).
    obs = torch.zeros((T, K, N, height, width, channels), dtype=torch.uint8, device=device)
    actions = torch.zeros((T, K, N), dtype=torch.long, device=device)
    logprobs, rewards, dones, values = (torch.zeros((T, K, N), device=device) for _ in range(4))

    # Views of the runtime's buffers, which every step rewrites in place.
    infos = []
    for run in runs:
        infos.append(run.env.reset(seed=kage.env_seeds(run.args.seed, N))[1])
    outputs = [run.env.outputs() for run in runs]
    frames = [torch.from_dlpack(o[0]) for o in outputs]
    env_reward, env_terminated, env_truncated = ([torch.from_dlpack(o[i]) for o in outputs] for i in (1, 2, 3))
    final_frames = [torch.from_dlpack(info["final_obs"]) for info in infos]
    episode = EpisodeMetrics(infos, [r.specs["train"]["config"]["dist_to_success"] for r in runs], device)
    stack = FrameStack(torch.stack(frames)) if args.use_frame_stack else None
    normalizer = RewardNormalizer((K, N), args.gamma, device) if args.normalize_reward else None
    next_done = torch.zeros((K, N), device=device)
    last_return = torch.zeros((K, N), device=device)  # §4.2: each environment's most recent episode
    last_length = torch.zeros((K, N), device=device)
    any_finished = torch.zeros(K, dtype=torch.bool, device=device)
    start_iteration, global_step, optimizer_steps, train_seconds = 1, 0, 0, 0.0
    boards = [tensorboard_log.open_writer(run.dir.path, run.args) for run in runs]

    def observe() -> torch.Tensor:
        """The runs' current observations, [K, N, H, W, C]."""
        return stack.stack if stack else torch.stack(frames)

    checkpoints = [run.dir.load_checkpoint(device) for run in runs]
    if any(c is not None for c in checkpoints):  # resume: the loop state, then the environments' state
        if any(c is None or c["iteration"] != checkpoints[0]["iteration"] for c in checkpoints):
            raise SystemExit("kage.train: packed runs resume together from checkpoints of one iteration; "
                             "pack them by the iteration they reached")
        for k, (run, c) in enumerate(zip(runs, checkpoints)):
            with torch.no_grad():
                for name, p in agent.named_parameters():
                    agent.run_view(p)[k].copy_(c["agent"][name])
            run.env.load_state(c["env_state"])
            for tensor, key in ((next_done, "next_done"), (last_return, "last_return"), (last_length, "last_length"),
                                (any_finished, "any_finished")):
                tensor[k] = c[key].to(device)
            if stack:
                stack.stack[k] = c["frame_stack"].to(device)
            if normalizer:
                for name, value in c["normalizer"].items():
                    getattr(normalizer, name)[k] = value.to(device)
            run.history = c["history"]
            boards[k].purge(c["global_step"])
        rundir.load_optimizer(optimizer, agent, [c["optimizer"] for c in checkpoints])
        c = checkpoints[0]
        start_iteration, global_step = c["iteration"] + 1, c["global_step"]
        optimizer_steps, train_seconds = c["optimizer_steps"], c["train_seconds"]
        for run in runs:
            print(f"kage.train: resuming {run.dir.path} after iteration {c['iteration']}", file=sys.stderr)
    elif runs[0].eval_envs:
        with timer("eval"):  # §3.1: the untrained policy
            for run, board, row in zip(runs, boards, evaluation_rows(agent, runs, args, 0, 0)):
                run.history.append(run.dir.log(row))
                board.write(row)
            video.record_runs(agent, runs, args, 0)

    def save_checkpoints(iteration: int) -> None:
        for k, run in enumerate(runs):
            run.dir.save_checkpoint({
                "iteration": iteration, "global_step": global_step, "optimizer_steps": optimizer_steps,
                "train_seconds": train_seconds,
                "agent": {n: agent.run_view(p)[k].detach().cpu().clone() for n, p in agent.named_parameters()},
                "optimizer": rundir.optimizer_run_state(optimizer, agent, k), "env_state": run.env.save_state(),
                "next_done": next_done[k].cpu(), "last_return": last_return[k].cpu(),
                "last_length": last_length[k].cpu(), "any_finished": any_finished[k].cpu(),
                "frame_stack": stack.stack[k].cpu() if stack else None,
                "normalizer": {n: v[k].cpu() for n, v in normalizer.state_dict().items()} if normalizer else None,
                "history": run.history, "agent_spec": dict(agent_spec, seed=run.args.seed)})

    progress = rundir.Progress(args.num_iterations, args.batch_size * K)
    last_iteration = args.num_iterations if stop_after is None else min(args.num_iterations,
                                                                        start_iteration + stop_after - 1)
    rollout = RolloutPolicy(agent, args, observe().shape, num_actions, device)
    # Episodes end only by truncation at episode_length (§2.3): when no episode is shorter than a rollout, an
    # environment ends at most one per rollout, and its final info still holds it when the rollout is over,
    # so the episode metrics are read once per rollout instead of after every step.
    read_once = min(r.specs["train"]["config"]["episode_length"] for r in runs) >= T
    finished_at = torch.zeros((T, K, N), device=device)

    def tally(rows: torch.Tensor, finished: torch.Tensor) -> None:
        """§4.2: sums of the finished episodes' metrics; each environment's latest return and length."""
        nonlocal episode_sums, last_return, last_length
        episode_sums += torch.cat([finished.sum(1, keepdim=True), (rows[:, 3:] * finished[:, None]).sum(2)], 1)
        last_return = torch.where(finished > 0, rows[:, 1], last_return)
        last_length = torch.where(finished > 0, rows[:, 2], last_length)
        any_finished.logical_or_(finished.any(1))

    for iteration in range(start_iteration, last_iteration + 1):
        iteration_start = time.perf_counter()
        if args.anneal_lr:  # §2.6
            optimizer.param_groups[0]["lr"] = args.learning_rate * (1.0 - (iteration - 1.0) / args.num_iterations)
        episode_sums = torch.zeros((K, len(METRICS) + 1), device=device)  # count, then the nine metrics
        # The action stream's draws for the whole rollout; the counter names the iteration, so a run draws the
        # same numbers alone, packed or resumed.
        noise = random.uniform(ACTION_STREAM, counter.fill_(iteration - 1), (T, N, num_actions))

        for step in range(T):  # §2.5 step 1
            with timer("forward"):
                if stack:
                    obs[step] = stack.stack
                else:
                    torch.stack(frames, out=obs[step])  # the runtime's frames straight into the rollout buffer
                dones[step] = next_done
                action, logprob, value = rollout(obs[step], noise[:, step])
                values[step], actions[step], logprobs[step] = value, action, logprob
            with timer("env"):
                for run, a in zip(runs, action):
                    run.env.step(a)
                reward = torch.stack(env_reward)
                next_done = (torch.stack(env_terminated) | torch.stack(env_truncated)).float()  # QUIRK (§2.5 b)
                finished = finished_at[step] = episode.mask()
                if not read_once:
                    tally(episode.rows(), finished)
                if args.bootstrap_truncation:
                    with torch.no_grad(), autocast(args.bf16):  # the value of the observation the truncation discarded
                        truncated = torch.stack(env_truncated).float() * finished
                        final = torch.stack(final_frames)
                        if stack:  # the final frame on top of the episode's last stack
                            final = torch.cat([stack.stack[..., final.shape[-1]:], final], -1)
                        reward = reward + args.gamma * agent(final)[1].float() * truncated
                if normalizer:
                    reward = normalizer(reward, next_done)
                rewards[step] = reward.clamp(args.reward_clip_min, args.reward_clip_max)
                if stack:
                    stack.push(torch.stack(frames), next_done)
        if read_once:
            with timer("env"):
                tally(episode.rows(), finished_at.sum(0))
        global_step += args.batch_size  # §2.5 step 2

        with torch.no_grad(), timer("forward"):  # §2.5 step 3
            with autocast(args.bf16):
                next_value = agent(observe())[1].float()
            advantages, returns = compute_gae(rewards, values, dones, next_value, next_done, args.gamma,
                                              args.gae_lambda)

        # §2.5 step 4: E epochs of M minibatches over each run's flattened (time-major) batch.
        b_obs = obs.transpose(0, 1).reshape(K, T * N, height, width, channels)
        b_logprobs, b_actions, b_advantages, b_returns, b_values = (
            t.transpose(0, 1).reshape(K, T * N) for t in (logprobs, actions, advantages, returns, values))
        runs_axis = torch.arange(K, device=device)[:, None]
        for epoch in range(args.update_epochs):
            ent_coef = entropy_coefficient(args, optimizer_steps)
            counter.fill_((iteration - 1) * args.update_epochs + epoch)
            permutation = random.permutation(SHUFFLE_STREAM, counter, args.batch_size)  # [K, B]
            for start in range(0, args.batch_size, args.minibatch_size):
                mb = permutation[:, start:start + args.minibatch_size]
                with timer("update_forward"):
                    mb_obs = b_obs[runs_axis, mb]
                    if augment:  # the update's minibatch only: the rollout and evaluations see plain frames
                        draws = plugins.augment_draws(random, AUGMENT_STREAM, counter, optimizer_steps)
                        mb_obs = augment(mb_obs, draws)
                    with autocast(args.bf16):
                        logits, new_value = agent(mb_obs)
                    logits, new_value = logits.float(), new_value.float()
                    new_logprob = torch.log_softmax(logits, -1).gather(-1, b_actions[runs_axis, mb, None]).squeeze(-1)
                    loss, pg_loss, v_loss, entropy, approx_kl, clipfrac = ppo_loss(
                        new_logprob, entropy_of(logits), new_value, b_logprobs[runs_axis, mb], b_values[runs_axis, mb],
                        b_advantages[runs_axis, mb], b_returns[runs_axis, mb], args, ent_coef)
                with timer("backward"):
                    optimizer.zero_grad()
                    loss.sum().backward()  # the runs' losses are independent: each gradient is its run's own
                with timer("optimizer"):
                    clip_grad_norm_per_run(agent, args.max_grad_norm)
                    optimizer.step()
                optimizer_steps += 1

        # §2.5 step 5, §4.3: losses of the last minibatch; the host reads the scalars once.
        var_returns = b_returns.var(1, unbiased=False)
        explained_var = 1 - (b_returns - b_values).var(1, unbiased=False) / (var_returns + 1e-8)
        stored = last_return != 0
        count = stored.sum(1).clamp(min=1)
        scalars = torch.cat([torch.stack([v_loss, pg_loss, entropy, approx_kl, clipfrac, loss, explained_var, var_returns,
                                          torch.where(stored, last_return, 0).sum(1) / count,
                                          torch.where(stored, last_length, 0).sum(1) / count,
                                          any_finished.float()], 1), episode_sums], 1).tolist()
        timer.end_iteration()
        iteration_seconds = time.perf_counter() - iteration_start
        train_seconds += iteration_seconds
        evaluate_now = runs[0].eval_envs and (iteration % args.run_eval_every == 0 or iteration == last_iteration)
        eval_rows = []
        if evaluate_now:  # §2.5 step 6, and §3.1's final point
            with timer("eval"):
                eval_rows = evaluation_rows(agent, runs, args, iteration, global_step)
        for k, run in enumerate(runs):
            row = run.dir.log(train_row(scalars[k], iteration, global_step, train_seconds, iteration_seconds, args,
                                        optimizer.param_groups[0]["lr"], ent_coef))
            if eval_rows:
                run.history.append(run.dir.log(eval_rows[k]))
            boards[k].write(row, *eval_rows[k:k + 1])
        if eval_rows:
            video.record_runs(agent, runs, args, iteration)
        if (args.save_checkpoint_every > 0 and iteration % args.save_checkpoint_every == 0) or \
                iteration == args.num_iterations or stop.requested:  # §2.5 step 7, at the end, and when asked
            save_checkpoints(iteration)
        progress.update(iteration, global_step * K, {"charts/SPS": global_step * K / train_seconds},
                        eval_rows[0] if eval_rows else None)
        if stop.requested and iteration < last_iteration:
            print(f"kage.train: stopped after iteration {iteration} of {args.num_iterations}, checkpointed; "
                  "run the same command again to resume", file=sys.stderr, flush=True)
            raise SystemExit(stop.exit_code)

    if last_iteration == args.num_iterations:
        for run in runs:
            run.dir.finish(run.history)
            print(f"kage.train: done, {run.dir.path}/summary.json", file=sys.stderr)
    for run, board in zip(runs, boards):
        for env in [run.env, *run.eval_envs.values()]:
            env.close()
        board.close()
    return runs


def train_row(s: List[float], iteration: int, global_step: int, train_seconds: float, iteration_seconds: float,
              args: Args, learning_rate: float, ent_coef: float) -> dict:
    """A run's training log row (§4.3) from its scalars: losses, explained variance and its denominator,
    the stored return and length, whether any episode finished, then the episode count and metric sums."""
    row = {"kind": "train", "iteration": iteration, "global_step": global_step,
           "charts/learning_rate": learning_rate, "charts/entropy_coef": ent_coef,
           "charts/SPS": global_step / train_seconds, "charts/SPS_update": args.batch_size / iteration_seconds,
           "losses/value_loss": s[0], "losses/policy_loss": s[1], "losses/entropy": s[2],
           "losses/approx_kl": s[3], "losses/clipfrac": s[4], "losses/loss": s[5]}
    if s[7] > 0:
        row["train/explained_variance"] = s[6]
    if s[10]:
        row["train/avg_completed_episodic_return"], row["train/avg_completed_episodic_length"] = s[8], s[9]
    if s[11] > 0:
        row.update({f"train/avg_{m}": total / s[11] for m, total in zip(METRICS, s[12:])})
    return row


def main(argv: Optional[List[str]] = None) -> int:
    parsed = parse_args(argv)
    pack = parsed if isinstance(parsed, list) else [parsed]
    unfinished = []
    for args in pack:
        run_dir = rundir.RunDir.open(args, configs_of(args))
        if run_dir.finished:
            print(f"kage.train: {run_dir.path} is finished (summary.json); nothing to do", file=sys.stderr)
        else:
            unfinished.append(args)
    if unfinished:
        with StopRequest("kage.train", "finishing this iteration, then checkpointing and exiting") as stop:
            train(unfinished, stop=stop)
    return 0


if __name__ == "__main__":
    sys.exit(main())
