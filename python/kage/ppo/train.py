"""PPO-CNN baseline of KAGE-Bench, in PyTorch, on kage.make_vec: train on one config, evaluate on it and
on one or more others, as the original's ppo_jax.py (and ppo_jax_multi_conf.py) do.

    python3 -m kage.ppo.train --train-config-path T --eval-config-path E --seed S [--device cuda|cpu] [--out DIR]

Not in the original: train on a mixture of configs (--train-config-paths A B C [--train-weights ...]: one batch
split across them) or on a schedule of mixtures (--train-schedule FILE), kage.ppo.schedule; the evaluation's
"train" target is then the current stage's mixture.

Read it top to bottom like CleanRL's ppo_atari_envpool.py: train() is the loop (rollout, GAE, update, log),
and each other concern is a function of its own below it (the pack's runs, resume and checkpoints, the
evaluation points, the log rows). The flags are kage.ppo.args, the losses kage.ppo.losses, the network
kage.ppo.agent (§1), the policy step kage.ppo.policy, the evaluation and its metrics kage.ppo.evaluation (§3-4).
"§x.y" refers to the section of the baseline specification (kage-ppo-baseline.md) that a line implements.
Quirks of the original are kept by default and marked QUIRK; a flag offers the corrected behaviour where
one makes sense:
- truncation is treated as termination (no bootstrap across the 500-step limit): --bootstrap-truncation;
- evaluation samples its actions: --eval-greedy takes the most likely action instead;
- `success` is recomputed with a strict `>` at the terminal state, and the plots labelled "success rate"
  show `success_once`: both are logged.
Not offered: --target-kl (declared and never read by the original), Weights & Biases.

Your own agent: --agent module:factory builds the network, --augment module:fn transforms training frames
(kage.ppo.plugins; the standard set in kage.ppo.augment) as --augment-mode says: drac (the default) keeps PPO's
losses on the plain frames and adds DrAC's regularisers (Raileanu et al. 2021) on the augmented minibatch;
rollout lets the policy act on augmented frames and trains on those same frames; update augments the update's
minibatches only, so that PPO's ratio compares the policy on augmented frames with the rollout's on plain ones
(unsound for strong augmentations: kept for comparison). Evaluations always see plain frames. The rest of the
protocol is the same for every agent. Videos: kage.ppo.video;
TensorBoard scalars under the original's tags, where tensorboard is importable: kage.ppo.tensorboard_log.

Packing: the loop trains K runs at once (K = 1 for a lone run; `kage.bench run --pack K`). Each run has its
own parameters, optimizer state, random streams, environments and run directory, and follows the same
algorithm as alone; tensors carry a leading run axis [K, ...], and one grouped forward and one backward
per rollout step and per minibatch serve all K runs, so the learner's kernel launches do not grow with K.
On the GPU each run's environments queue their work on a stream of their own (kage.ppo.streams), so the
pack's K batches, too small each to fill the device, step at once.

The environments and the learner share the device: observations, actions, rewards and episode metrics
never leave it during a rollout or an evaluation; the host reads a few scalars once per iteration for
the log. A run directory holds everything needed to resume a killed run exactly (kage.ppo.rundir).
"""
import contextlib
import dataclasses
import math
import os
import sys
import time
from typing import Dict, List, Optional

import torch

import kage
from kage.fields import EPISODE_METRICS as METRICS
from kage.ppo import plugins, rundir, schedule, streams, tensorboard_log, video
from kage.ppo.agent import frames_at
from kage.ppo.args import PER_RUN, Args, configs_of, parse_args
from kage.ppo.checkpoint_writer import CheckpointWriter
from kage.ppo.counter_random import CounterRandom
from kage.ppo.evaluation import EvalSettings, EvalTargets, evaluation_rows
from kage.ppo.loop_state import LoopState, resume, save_checkpoints
from kage.ppo.losses import (clip_grad_norm_per_run, compute_gae, drac_regularisers, entropy_coefficient, entropy_of,
                             ppo_loss)
from kage.ppo.policy import RolloutPolicy, autocast
from kage.ppo.runs import BatchViews, Run, compile_kernels, enter_stage, open_batches, open_run_dir
from kage.ppo.wrappers import FrameStack, RewardNormalizer
from kage.util.files import os_error_text, safe
from kage.util.stop import StopRequest, die_with_parent
from kage.util.text import plural

ACTION_STREAM, SHUFFLE_STREAM = 1, 2  # the two random streams of a run (§2.4); evaluations use their own keys
AUGMENT_STREAM = 3  # --augment's draws on update minibatches (update and drac modes; not in the original)
ROLLOUT_AUGMENT_STREAM = 4  # its draws on the rollout's frames (rollout mode)


# ---- the training loop (§2.5) ----

def train(pack: List[Args], timer=None, stop_after: Optional[int] = None,
          stop: Optional[StopRequest] = None) -> List[Run]:
    """Trains the runs of `pack` together (one for a lone run) to the end, or `stop_after` iterations past
    where they start (kage.bench speed). Resumes each run from its checkpoint if it has one. Once `stop` is
    requested (a signal), checkpoints after the running iteration and exits. Each run directory is locked from
    its opening to the end (kage.util.lock)."""
    pack = [rundir.with_augment_mode(a) for a in pack]
    with rundir.held_open(), CheckpointWriter() as writer:  # the files in flight land before the directories unlock
        return train_locked(pack, timer, stop_after, stop, writer)


def train_locked(pack: List[Args], timer, stop_after: Optional[int], stop: Optional[StopRequest],
                 writer: CheckpointWriter) -> List[Run]:
    """train(), with its run directories closed and its checkpoints' writer waited for by the caller."""
    args = check_pack(pack)
    stop = stop or StopRequest("kage.ppo.train", "")
    timer = timer or NoTimer()
    device, threads = choose_device(args)
    # Everything that can be refused is checked before a run directory is written: the configs, the batches
    # (their size against the memory), the agent and the augmentation (each called once on blank frames), and
    # the rollout's storage against the device's free memory.
    opening = time.perf_counter()
    if device.type == "cuda":
        compile_kernels(pack)
    runs = [open_batches(a, threads) for a in pack]
    K, T, N = len(runs), args.num_steps, args.num_envs
    # A pack's start takes a while (its configs' kernels, then a batch per run and config): the log says how long.
    print(f"kage.ppo.train: {plural(sum(1 + len(run.eval_envs) for run in runs), 'batch', 'batches')} of "
          f"{plural(K, 'run')} opened in "
          f"{time.perf_counter() - opening:.1f} s", file=sys.stderr)
    height, width, channels = runs[0].env.single_observation_space.shape
    channels *= 4 if args.use_frame_stack else 1
    num_actions = runs[0].env.single_action_space.n
    agent = plugins.build_agent(args.agent, (height, width, channels), num_actions, [a.seed for a in pack], device,
                                speed_modes(args))  # §2.4: the runs' seeds
    augment = plugins.load_augment(args.augment)
    if augment:
        warning = plugins.check_augment(augment, args.augment, (K, 2, height, width, channels), device)
        if warning:
            print(f"kage.ppo.train: warning: {warning}", file=sys.stderr, flush=True)
    check_memory(args, K, (height, width, channels), device)
    # A network that reads a minibatch where the rollout stored it (kage.ppo.agent.Agent) gets the buffer and
    # the frames' indices; any other gets the gathered frames.
    frames_in_place = getattr(agent, "takes_frame_indices", False)
    for run in runs:
        open_run_dir(run)
    agent_spec = {"agent": args.agent, "observation_shape": [height, width, channels], "num_actions": num_actions,
                  "use_frame_stack": args.use_frame_stack}  # what kage.ppo.evaluate needs to rebuild a run's policy
    # On CUDA, Adam's one fused kernel: the same update as the multi-tensor one, one pass over the parameters,
    # gradients and moments instead of several (the optimizer took 8 % of a packed iteration before).
    optimizer = torch.optim.Adam(agent.parameters(), lr=args.learning_rate, eps=1e-5, fused=device.type == "cuda")
    random = CounterRandom([a.seed for a in pack], device)
    counter = torch.zeros((), dtype=torch.int64, device=device)  # set by fill_: no host-to-device copy
    settings = EvalSettings(args.eval_episodes, args.use_frame_stack, args.eval_greedy, args.bf16, args.cuda_graph)

    # Rollout storage, [T, K, N, ...] on the device (§2.5 step 1d).
    obs = torch.zeros((T, K, N, height, width, channels), dtype=torch.uint8, device=device)
    actions = torch.zeros((T, K, N), dtype=torch.long, device=device)
    logprobs, rewards, dones, values = (torch.zeros((T, K, N), device=device) for _ in range(4))

    for run in runs:
        run.env.reset(seed=kage.env_seeds(run.args.seed, N))
    streams.wait_for(run.stream for run in runs)
    specs = [run.env.resolved_specs[0]["config"] for run in runs]  # the hidden game's: a mixture's configs share it
    # Views of the runtime's buffers, which every step rewrites in place.
    views = BatchViews(runs, [spec["dist_to_success"] for spec in specs], device)
    frames, env_reward, env_terminated, env_truncated = views.frames, views.reward, views.terminated, views.truncated
    stack = FrameStack(torch.stack(frames)) if args.use_frame_stack else None
    normalizer = RewardNormalizer((K, N), args.gamma, device) if args.normalize_reward else None
    state = LoopState.start(K, N, device)
    boards = [tensorboard_log.open_writer(run.dir.path, run.args) for run in runs]

    def observe() -> torch.Tensor:
        """The runs' current observations, [K, N, H, W, C]."""
        return stack.stack if stack else torch.stack(frames)

    resumed = resume(runs, agent, optimizer, state, stack, normalizer, boards, device, agent_spec, views, threads)
    progress = rundir.Progress(args.num_iterations, args.batch_size * K,
                               args.run_eval_every if runs[0].eval_envs else 0)
    if not resumed and runs[0].eval_envs:
        progress.evaluating(0, max(len(run.eval_envs) for run in runs), args.eval_episodes)
        with timer("eval"):  # §3.1: the untrained policy
            evaluation_point(agent, runs, boards, settings, args, 0, 0)
        progress.evaluated()
    start_iteration = state.iteration + 1
    last_iteration = args.num_iterations if stop_after is None else min(args.num_iterations,
                                                                        start_iteration + stop_after - 1)
    rollout = RolloutPolicy(agent, observe().shape, num_actions, device, bf16=args.bf16, cuda_graph=args.cuda_graph)
    # Episodes end only by truncation at episode_length (§2.3): when no episode is shorter than a rollout, an
    # environment ends at most one per rollout, and its final info still holds it when the rollout is over,
    # so the episode metrics are read once per rollout instead of after every step.
    read_once = min(spec["episode_length"] for spec in specs) >= T
    finished_at = torch.zeros((T, K, N), device=device)
    augment_minibatch = augment if args.augment_mode in ("update", "drac") else None
    augment_rollout = RolloutAugment(augment, args.augment, random, T, observe().shape, device,
                                     args.cuda_graph) if args.augment_mode == "rollout" else None
    env_step = streams.GraphedStep() if args.cuda_graph else None  # the rollout policy's actions keep their memory

    clock = TrainClock()
    for iteration in range(start_iteration, last_iteration + 1):
        for k, run in enumerate(runs):  # a schedule's stage boundary: the run's batches for the new mixture
            stage = schedule.stage_at(run.stages, iteration)
            if stage != run.stage:
                names = ", ".join(run.labels.get(c, c) for c in run.stages[stage].configs)
                print(f"kage.ppo.train: {run.args.out}: iteration {iteration}: stage {stage + 1} of "
                      f"{len(run.stages)} starts ({names})", file=sys.stderr, flush=True)
                enter_stage(run, stage, threads, reset=True)
                views.bind(k, run.env)
                state.next_done[k] = 1.0  # the episodes under way end here
                if stack:
                    stack.restart(k, frames[k])
                if normalizer:
                    normalizer.ret[k] = 0.0
        streams.wait_for(run.stream for run in runs)
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
            if augment_rollout:  # the policy acts on, and the update trains on, the same augmented frames
                with timer("augment"):
                    obs[step] = augment_rollout(obs[step], iteration, step)
            with timer("forward"):
                dones[step] = state.next_done
                action, logprob, value = rollout(obs[step], noise[:, step])
                values[step], actions[step], logprobs[step] = value, action, logprob
            with timer("env"):
                if env_step:
                    env_step([run.env for run in runs], action)
                else:
                    kage.step_batches([run.env for run in runs], action)
                    streams.wait_for(run.stream for run in runs)
                reward = torch.stack(env_reward)
                state.next_done = (torch.stack(env_terminated) | torch.stack(env_truncated)).float()  # QUIRK (§2.5 b)
                finished = finished_at[step] = views.episode.mask()
                if not read_once:
                    episode_sums += state.tally(views.episode.rows(), finished)
                if args.bootstrap_truncation:
                    with torch.no_grad(), autocast(args.bf16):  # the value of the observation the truncation discarded
                        truncated = torch.stack(env_truncated).float() * finished
                        final = torch.stack(views.final_frames)
                        if stack:  # the final frame on top of the episode's last stack
                            final = torch.cat([stack.stack[..., final.shape[-1]:], final], -1)
                        if augment_rollout:
                            final = augment_rollout(final, iteration, step, final=True)
                        reward = reward + args.gamma * agent(final)[1].float() * truncated
                if normalizer:
                    reward = normalizer(reward, state.next_done)
                rewards[step] = reward.clamp(args.reward_clip_min, args.reward_clip_max)
                if stack:
                    stack.push(torch.stack(frames), state.next_done)
        if read_once:
            with timer("env"):
                episode_sums += state.tally(views.episode.rows(), finished_at.sum(0))
        if env_step:  # the batches' own work (a stage's reset, a saved state) after the graph's steps
            streams.release(run.stream for run in runs)
        state.global_step += args.batch_size  # §2.5 step 2

        with torch.no_grad(), timer("forward"):  # §2.5 step 3
            last = augment_rollout(observe(), iteration, T) if augment_rollout else observe()
            with autocast(args.bf16):
                next_value = agent(last)[1].float()
            advantages, returns = compute_gae(rewards, values, dones, next_value, state.next_done, args.gamma,
                                              args.gae_lambda)

        # §2.5 step 4: E epochs of M minibatches over each run's flattened (time-major) batch. Element t * N + n
        # of run k is frame (t * K + k) * N + n of the rollout buffer: the minibatch's frames are read there.
        b_logprobs, b_actions, b_advantages, b_returns, b_values = (
            t.transpose(0, 1).reshape(K, T * N) for t in (logprobs, actions, advantages, returns, values))
        runs_axis = torch.arange(K, device=device)[:, None]
        var_returns = b_returns.var(1, unbiased=False)  # [K]: DrAC's value term is in units of its root
        for epoch in range(args.update_epochs):
            ent_coef = entropy_coefficient(args, state.optimizer_steps)
            counter.fill_((iteration - 1) * args.update_epochs + epoch)
            permutation = random.permutation(SHUFFLE_STREAM, counter, args.batch_size)  # [K, B]
            for start in range(0, args.batch_size, args.minibatch_size):
                mb = permutation[:, start:start + args.minibatch_size]
                images = (mb // N * K + runs_axis) * N + mb % N
                augmented = None
                if augment_minibatch:
                    with timer("augment"):
                        draws = plugins.augment_draws(random, AUGMENT_STREAM, counter, state.optimizer_steps)
                        augmented = plugins.augment_frames(augment, args.augment, obs, draws, images)
                with timer("update_forward"):
                    # Under update the loss reads the augmented frames alone: no plain minibatch is gathered.
                    plain = None if args.augment_mode == "update" and augmented is not None else \
                        (obs, images) if frames_in_place else (frames_at(obs, images),)
                    loss, terms = minibatch_loss(agent, plain, augmented, b_actions[runs_axis, mb],
                                                 b_logprobs[runs_axis, mb], b_values[runs_axis, mb],
                                                 b_advantages[runs_axis, mb], b_returns[runs_axis, mb], var_returns,
                                                 args, ent_coef)
                with timer("backward"):
                    optimizer.zero_grad()
                    loss.sum().backward()  # the runs' losses are independent: each gradient is its run's own
                with timer("optimizer"):
                    clip_grad_norm_per_run(agent, args.max_grad_norm)
                    optimizer.step()
                state.optimizer_steps += 1

        # §2.5 step 5, §4.3: losses of the last minibatch, named; the host reads them once.
        explained_var = 1 - (b_returns - b_values).var(1, unbiased=False) / (var_returns + 1e-8)
        measured = {**terms, "loss": loss, "explained_variance": explained_var, "var_returns": var_returns,
                    **state.stored_episodes(), "episode_sums": episode_sums}
        timer.end_iteration()
        host_values = to_host(measured)  # waits for the iteration's work on the device, which the clock then counts
        iteration_seconds = clock.lap()
        state.train_seconds += iteration_seconds
        state.iteration = iteration
        rows = train_rows(host_values, iteration, state.global_step, state.train_seconds, iteration_seconds, args,
                          optimizer.param_groups[0]["lr"], ent_coef)
        eval_rows = []
        if runs[0].eval_envs and (iteration % args.run_eval_every == 0 or iteration == last_iteration):
            progress.evaluating(iteration, max(len(run.eval_envs) for run in runs), args.eval_episodes)
            with timer("eval"), clock.paused():  # §2.5 step 6, and §3.1's final point
                eval_rows = evaluation_point(agent, runs, boards, settings, args, iteration, state.global_step,
                                             train_rows=rows)
            progress.evaluated()
        else:
            for run, board, row in zip(runs, boards, rows):
                board.write(run.dir.log(row))
        if (args.save_checkpoint_every > 0 and iteration % args.save_checkpoint_every == 0) or \
                iteration == args.num_iterations or stop.requested:  # §2.5 step 7, at the end, and when asked
            save_checkpoints(runs, agent, optimizer, state, stack, normalizer, agent_spec, writer)
            if iteration == last_iteration or stop.requested:
                writer.wait()  # landed before summary.json, or before the exit that says the runs are checkpointed
        progress.update(iteration, state.global_step * K, {"charts/SPS": state.global_step * K / state.train_seconds},
                        eval_rows[0] if eval_rows else None)
        if stop.requested and iteration < last_iteration:
            print(f"kage.ppo.train: stopped after iteration {iteration} of {args.num_iterations}, checkpointed; "
                  "run the same command again to resume", file=sys.stderr, flush=True)
            raise SystemExit(stop.exit_code)

    if last_iteration == args.num_iterations:
        for run in runs:
            run.dir.finish(run.history)
            print(f"kage.ppo.train: done, {run.dir.path}/summary.json", file=sys.stderr)
    for run, board in zip(runs, boards):
        for env in [run.env, *run.eval_envs.values()]:
            env.close()
        board.close()
    return runs


def minibatch_loss(agent, plain: Optional[tuple], augmented: Optional[torch.Tensor], actions, old_logprob, old_value,
                   advantages, returns, var_returns, args: Args, ent_coef: float):
    """One minibatch's loss [K] (§2.6) as --augment-mode says, and its named terms: PPO's losses on the network's
    outputs for the plain frames (`plain`: its arguments; None under update), or under update on the augmented
    ones; under drac,
    + drac_coef (G_pi + G_V) between the plain and the augmented frames' outputs (kage.ppo.losses), G_V in units
    of var_returns [K], the variance of each run's returns over its batch."""
    inputs = (augmented,) if args.augment_mode == "update" and augmented is not None else plain
    with autocast(args.bf16):
        logits, value = agent(*inputs)
    logits, value = logits.float(), value.float()
    logprob = torch.log_softmax(logits, -1).gather(-1, actions[..., None]).squeeze(-1)
    loss, pg_loss, v_loss, entropy, approx_kl, clipfrac = ppo_loss(logprob, entropy_of(logits), value, old_logprob,
                                                                   old_value, advantages, returns, args, ent_coef)
    terms = {"value_loss": v_loss, "policy_loss": pg_loss, "entropy": entropy, "approx_kl": approx_kl,
             "clipfrac": clipfrac}
    if args.augment_mode == "drac" and augmented is not None:
        with autocast(args.bf16):
            augmented_logits, augmented_value = agent(augmented)
        terms["drac_policy"], terms["drac_value"] = drac_regularisers(logits, value, augmented_logits.float(),
                                                                      augmented_value.float(), var_returns)
        loss = loss + args.drac_coef * (terms["drac_policy"] + terms["drac_value"])
    return loss, terms


def check_pack(runs: List[Args]) -> Args:
    """The pack's shared arguments: every run must agree on all but PER_RUN (its configs among them: runs may
    evaluate different numbers of configs, kage.ppo.evaluation)."""
    first = dataclasses.asdict(runs[0])
    for args in runs[1:]:
        other = dataclasses.asdict(args)
        differ = [k for k in first if k not in PER_RUN and first[k] != other[k]]
        if differ:
            raise SystemExit(f"kage.ppo.train: packed runs must share {', '.join(differ)}")
    return runs[0]


def choose_device(args: Args):
    """The learner's device and CPU thread count, with the GPU's math settings."""
    if args.device == "cuda" and not torch.cuda.is_available():
        raise SystemExit("kage.ppo.train: --device cuda, but torch sees no GPU: use --device cpu")
    threads = args.threads or os.cpu_count() or 1
    torch.set_num_threads(threads)
    if args.device == "cuda":
        torch.backends.cudnn.benchmark = True
        torch.set_float32_matmul_precision("high")  # TF32, as JAX's default precision on this GPU
    return torch.device(args.device), threads


def speed_modes(args: Args) -> Optional[dict]:
    """The baseline network's speed modes from the flags (none for another --agent, which validate() ensures)."""
    if args.agent != plugins.BASELINE_AGENT:
        return None
    return {"bf16": args.bf16, "channels_last": args.channels_last, "fused_input": args.fused_input,
            "triton_conv": args.triton_conv}


class RolloutAugment:
    """--augment-mode rollout: the augmentation of the frames the policy acts on, each draw named by the iteration,
    the step and whether it is a truncation's final frame, so a run draws the same numbers alone, packed or
    resumed. The position is a device tensor, so that under --cuda-graph the augmentation of a step's frames is
    captured once and replayed (a step's few dozen small launches cost more than its frames' pass); one that
    cannot be captured runs eagerly, and the trainer says so."""

    def __init__(self, augment, reference: str, random: CounterRandom, num_steps: int, shape, device,
                 cuda_graph: bool):
        self.augment, self.reference, self.random, self.num_steps = augment, reference, random, num_steps
        self.position = torch.zeros((), dtype=torch.int64, device=device)
        self.graph = None
        if cuda_graph:
            self.frames = torch.zeros(shape, dtype=torch.uint8, device=device)
            side = torch.cuda.Stream()
            side.wait_stream(torch.cuda.current_stream())
            with torch.cuda.stream(side):
                for _ in range(2):  # warm-up: kernels compiled, constants and images loaded outside the capture
                    self._augment(self.frames)
            torch.cuda.current_stream().wait_stream(side)
            graph = torch.cuda.CUDAGraph()
            try:
                with torch.cuda.graph(graph):
                    self.augmented = self._augment(self.frames)
                self.graph = graph
            except Exception as e:  # a function that reads values on the host, or allocates outside torch
                print(f"kage.ppo.train: --augment {reference} cannot be replayed as a CUDA graph ({type(e).__name__}: "
                      f"{str(e).splitlines()[0] if str(e) else ''}); it runs eagerly", file=sys.stderr, flush=True)

    def _augment(self, frames: torch.Tensor) -> torch.Tensor:
        base = self.position * 64
        draws = 0

        def uniform(shape):
            nonlocal draws
            draws += 1
            return self.random.uniform(ROLLOUT_AUGMENT_STREAM, base + draws, shape)
        return plugins.augment_frames(self.augment, self.reference, frames, uniform)

    def __call__(self, frames: torch.Tensor, iteration: int, step: int, final: bool = False) -> torch.Tensor:
        self.position.fill_(((iteration - 1) * (self.num_steps + 1) + step) * 2 + final)
        if self.graph is None:
            return self._augment(frames)
        self.frames.copy_(frames)
        self.graph.replay()
        return self.augmented


def check_memory(args: Args, runs: int, frame_shape, device) -> None:
    """Refuses a rollout whose storage (frames, actions, log-probabilities, rewards, dones, values, finished
    marks, and the frames of an update minibatch) does not fit the device's free memory."""
    T, N = args.num_steps, args.num_envs
    frame = math.prod(frame_shape)
    needed = T * runs * N * (frame + 8 + 6 * 4) + runs * args.minibatch_size * frame * (2 if args.augment else 1)
    if device.type == "cuda":
        free = torch.cuda.mem_get_info(device)[0]
        where = f"the GPU has {free / 2**30:.1f} GiB free"
    else:
        free = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        where = f"the machine has {free / 2**30:.1f} GiB available"
    if needed > 0.9 * free:
        raise SystemExit(f"kage.ppo.train: the rollout's storage needs {needed / 2**30:.1f} GiB ({T} steps x {runs} "
                         f"run{'s' if runs > 1 else ''} x {N} environments of {'x'.join(map(str, frame_shape))} "
                         f"frames), and {where}: lower --num-envs or --num-steps, or pack fewer runs")


class TrainClock:
    """charts/SPS's clock (§4.3): the wall time of the training loop less its evaluation points (their videos
    included). An iteration's lap runs from the last one's end to the host's read of this iteration's losses,
    which waits for the device to finish its work; the logging and checkpoint after that read count in the next
    lap, as in the original's running clock. Counting up to the read, not up to the last launch, keeps the
    device's unfinished work in the figure: a CUDA host runs ahead of its device."""

    def __init__(self):
        self._mark = time.perf_counter()

    def lap(self) -> float:
        now = time.perf_counter()
        seconds, self._mark = now - self._mark, now
        return seconds

    @contextlib.contextmanager
    def paused(self):
        start = time.perf_counter()
        try:
            yield
        finally:
            self._mark += time.perf_counter() - start


class NoTimer:
    """The phases of an iteration, timed only by kage.bench speed (kage.bench.speed.PhaseTimer)."""

    def __call__(self, phase: str):
        return contextlib.nullcontext()

    def end_iteration(self) -> None:
        pass


# ---- evaluation points and the log ----

def evaluation_point(agent, runs: List[Run], boards, settings: EvalSettings, args: Args, iteration: int,
                     global_step: int, train_rows: Optional[List[dict]] = None) -> List[dict]:
    """§2.5 step 6: evaluates every run (kage.ppo.evaluation), logs each run's training row (if any) and
    evaluation row to metrics.jsonl and TensorBoard, and records the videos that --video-every asks for."""
    eval_rows = evaluation_rows(agent, [EvalTargets(run.args.seed, run.eval_envs) for run in runs], settings,
                                iteration, global_step)
    for k, (run, board, row) in enumerate(zip(runs, boards, eval_rows)):
        logged = [run.dir.log(train_rows[k])] if train_rows else []
        run.history.append(run.dir.log(row))
        board.write(*logged, row)
    record_videos(agent, runs, args, iteration)
    return eval_rows


def record_videos(agent, runs: List[Run], args: Args, iteration: int) -> None:
    """--video-every: at an evaluation point whose iteration is a multiple of it, an episode of each run on
    each of its configs, <run dir>/videos/<label>_iter_<iteration>.gif (kage.ppo.video)."""
    if not args.video_every or iteration % args.video_every:
        return
    was_training = agent.training
    agent.eval()
    for k, run in enumerate(runs):
        os.makedirs(os.path.join(run.dir.path, "videos"), exist_ok=True)
        for label, config in configs_of(run.args):
            video.record(agent, k, config, run.args.seed + iteration,
                         os.path.join(run.dir.path, "videos", f"{safe(label)}_iter_{iteration}.gif"),
                         f"{label} · iteration {iteration}", device=args.device, asset_root=args.asset_root,
                         use_frame_stack=args.use_frame_stack, bf16=args.bf16, greedy=args.eval_greedy)
    agent.train(was_training)


def to_host(measured: Dict[str, torch.Tensor]) -> List[Dict[str, object]]:
    """Named device values ([K] each, or [K, n]) as one host read: a dict of Python numbers (or lists) per run."""
    names = list(measured)
    columns = [measured[n].float().reshape(measured[n].shape[0], -1) for n in names]
    widths = [c.shape[1] for c in columns]
    host = torch.cat(columns, 1).tolist()
    rows = []
    for values in host:
        row, at = {}, 0
        for name, width, column in zip(names, widths, columns):
            row[name] = values[at] if measured[name].dim() == 1 else values[at:at + width]
            at += width
        rows.append(row)
    return rows


def train_rows(measured: List[Dict[str, object]], iteration: int, global_step: int, train_seconds: float,
               iteration_seconds: float, args: Args, learning_rate: float, ent_coef: float) -> List[dict]:
    """Each run's training log row (§4.3) from its measured values: losses, explained variance (where the
    returns vary), the stored episodes' return and length (once one finished), and the mean of each metric
    over the episodes that finished in the iteration."""
    rows = []
    for m in measured:
        row = {"kind": "train", "iteration": iteration, "global_step": global_step,
               "charts/learning_rate": learning_rate, "charts/entropy_coef": ent_coef,
               "charts/SPS": global_step / train_seconds, "charts/SPS_update": args.batch_size / iteration_seconds}
        row.update({f"losses/{name}": m[name] for name in
                    ("value_loss", "policy_loss", "entropy", "approx_kl", "clipfrac", "loss", "drac_policy",
                     "drac_value") if name in m})
        if m["var_returns"] > 0:
            row["train/explained_variance"] = m["explained_variance"]
        if m["any_finished"]:
            row["train/avg_completed_episodic_return"] = m["episodic_return"]
            row["train/avg_completed_episodic_length"] = m["episodic_length"]
        count, *sums = m["episode_sums"]
        if count > 0:
            row.update({f"train/avg_{metric}": total / count for metric, total in zip(METRICS, sums)})
        rows.append(row)
    return rows


def main(argv: Optional[List[str]] = None) -> int:
    die_with_parent()  # under kage.bench run: its death (even SIGKILL) stops this trainer too
    try:
        return train_command(argv)
    except OSError as e:  # a file system that refuses writes: read-only, full, no permission
        raise SystemExit(os_error_text("kage.ppo.train", e, "--out")) from None


def train_command(argv: Optional[List[str]]) -> int:
    """main() without its handling of file-system errors."""
    parsed = parse_args(argv)
    pack = [rundir.with_augment_mode(a) for a in (parsed if isinstance(parsed, list) else [parsed])]
    unfinished = []
    for args in pack:
        path = args.out or rundir.default_dir(args)
        if rundir.is_finished(path):
            rundir.check_finished(path, args, configs_of(args))
            print(f"kage.ppo.train: {path} is finished (summary.json); nothing to do", file=sys.stderr)
        else:
            unfinished.append(args)
    if unfinished:
        with StopRequest("kage.ppo.train", "finishing this iteration, then checkpointing and exiting") as stop:
            train(unfinished, stop=stop)
    return 0


if __name__ == "__main__":
    sys.exit(main())
