"""What the training loop carries across iterations (LoopState) and each run's checkpoint of it: written after an
iteration (save_checkpoints), checked against what this run would write (checkpoint_problem) and loaded to resume
a pack exactly where it stopped (resume). The files themselves are kage.ppo.rundir's and kage.ppo.checkpoint's."""
import functools
import math
import os
import sys
from dataclasses import dataclass
from typing import Dict, List, Optional

import torch

from kage.ppo import checkpoint, rundir, schedule, streams
from kage.ppo.args import Args
from kage.ppo.checkpoint_writer import CheckpointWriter
from kage.ppo.runs import BatchViews, Run, enter_stage


@dataclass
class LoopState:
    """The loop's counters and each environment's episode bookkeeping (§4.2), [K, N] or [K]: what a checkpoint
    holds besides parameters, optimizer, environments, frame stack and reward normaliser."""
    next_done: torch.Tensor
    last_return: torch.Tensor  # §4.2: each environment's most recent episode
    last_length: torch.Tensor
    any_finished: torch.Tensor
    iteration: int = 0  # the last finished
    global_step: int = 0
    optimizer_steps: int = 0
    train_seconds: float = 0.0

    TENSORS = ("next_done", "last_return", "last_length", "any_finished")

    @classmethod
    def start(cls, K: int, N: int, device) -> "LoopState":
        zeros = lambda: torch.zeros((K, N), device=device)  # noqa: E731
        return cls(zeros(), zeros(), zeros(), torch.zeros(K, dtype=torch.bool, device=device))

    def tally(self, rows: torch.Tensor, finished: torch.Tensor) -> torch.Tensor:
        """§4.2: records each environment's latest return and length; returns the finished episodes' count and
        metric sums [K, 1 + 9] to add to the iteration's."""
        self.last_return = torch.where(finished > 0, rows[:, 1], self.last_return)
        self.last_length = torch.where(finished > 0, rows[:, 2], self.last_length)
        self.any_finished.logical_or_(finished.any(1))
        return torch.cat([finished.sum(1, keepdim=True), (rows[:, 3:] * finished[:, None]).sum(2)], 1)

    def stored_episodes(self) -> Dict[str, torch.Tensor]:
        """§4.3: the mean of the stored returns and lengths over the environments that have one, [K] each."""
        stored = self.last_return != 0
        count = stored.sum(1).clamp(min=1)
        return {"episodic_return": torch.where(stored, self.last_return, 0).sum(1) / count,
                "episodic_length": torch.where(stored, self.last_length, 0).sum(1) / count,
                "any_finished": self.any_finished.float()}


def save_checkpoints(runs: List[Run], agent, optimizer, state: LoopState, stack, normalizer, agent_spec: dict,
                     writer: CheckpointWriter) -> None:
    """Each run's checkpoint (kage.ppo.rundir): its parameters and optimizer state, its environments' state, and
    its part of the loop state, copied now and written by `writer` while training goes on."""
    snapshots = [run.dir.checkpoint_snapshot(run_checkpoint(
        k, run, agent, rundir.optimizer_run_state(optimizer, agent, k), state, stack, normalizer, agent_spec))
        for k, run in enumerate(runs)]
    writer.submit([functools.partial(run.dir.write_checkpoint, snapshot) for run, snapshot in zip(runs, snapshots)])


def run_checkpoint(k: int, run: Run, agent, optimizer_state: dict, state: LoopState, stack, normalizer,
                   agent_spec: dict) -> dict:
    """Run `k`'s checkpoint as a dict of data (kage.ppo.checkpoint)."""
    saved = {
        "iteration": state.iteration, "global_step": state.global_step, "optimizer_steps": state.optimizer_steps,
        "train_seconds": state.train_seconds,
        "agent": {n: agent.run_view(p)[k].detach().cpu().clone() for n, p in agent.named_parameters()},
        "optimizer": optimizer_state, "env_state": run.env.save_state(),
        "frame_stack": stack.stack[k].to("cpu", copy=True) if stack else None,
        "normalizer": ({n: v[k].to("cpu", copy=True) for n, v in normalizer.state_dict().items()}
                       if normalizer else None),
        "history": list(run.history), "agent_spec": dict(agent_spec, seed=run.args.seed)}
    # Copies even on a CPU device, where .cpu() is the live tensor: the checkpoint is written while training goes on.
    saved.update({key: getattr(state, key)[k].to("cpu", copy=True) for key in LoopState.TENSORS})
    return saved


def checkpoint_problem(c: dict, k: int, run: Run, agent, state: LoopState, stack, normalizer, agent_spec: dict,
                       args: Args) -> Optional[str]:
    """What keeps run `k` from resuming from checkpoint `c` (already proven intact and this run's): its parts must
    be shaped as this run writes them, and its counters those of a whole number of iterations."""
    adam = {n: {"exp_avg": t, "exp_avg_sq": t, "step": torch.zeros(())} for n, t in
            ((n, agent.run_view(p)[k].detach().cpu()) for n, p in agent.named_parameters())}
    expected = run_checkpoint(k, run, agent, adam, state, stack, normalizer, agent_spec)
    expected.update(history=c.get("history"), identity=c.get("identity"), log=c.get("log"))  # rundir checks these
    found = dict(c, optimizer={n: s if s or n not in adam else adam[n] for n, s in c["optimizer"].items()}) \
        if isinstance(c.get("optimizer"), dict) else c  # a parameter Adam never stepped has no state
    problem = checkpoint.structure_problem(expected, found)
    if problem:
        return problem
    if not isinstance(c["history"], list) or not all(
            isinstance(row, dict) and all(isinstance(row.get(key), dict) for key in ("train", "evals", "diffs")) and
            isinstance(row.get("iteration"), int) and isinstance(row.get("global_step"), int) for row in c["history"]):
        return "/history: not a list of evaluation rows"
    i = c["iteration"]
    if not (1 <= i <= args.num_iterations and c["global_step"] == i * args.batch_size and
            c["optimizer_steps"] == i * args.update_epochs * args.num_minibatches and
            math.isfinite(c["train_seconds"]) and c["train_seconds"] >= 0):
        return (f"its counters (iteration {i}, global_step {c['global_step']}, optimizer_steps {c['optimizer_steps']}, "
                f"train_seconds {c['train_seconds']}) are not those of a run of {args.num_iterations} iterations")
    return None


def resume(runs: List[Run], agent, optimizer, state: LoopState, stack, normalizer, boards, device,
           agent_spec: dict, views: BatchViews, threads: int) -> bool:
    """Loads the runs' checkpoints, if they have any, into the network, optimizer, environments and loop state;
    whether they had."""
    checkpoints = [run.dir.load_checkpoint() for run in runs]
    if all(c is None for c in checkpoints):
        return False
    if any(c is None or c["iteration"] != checkpoints[0]["iteration"] for c in checkpoints):
        raise SystemExit("kage.ppo.train: packed runs resume together from checkpoints of one iteration; "
                         "pack them by the iteration they reached")
    for k, (run, c) in enumerate(zip(runs, checkpoints)):
        problem = checkpoint_problem(c, k, run, agent, state, stack, normalizer, agent_spec, run.args)
        if problem:
            raise SystemExit(f"kage.ppo.train: {os.path.join(run.dir.path, 'checkpoints', 'latest.pt')}: not a "
                             f"checkpoint this run can resume from ({problem}): restore this run's checkpoint, or "
                             "train anew with another --out")
    for k, (run, c) in enumerate(zip(runs, checkpoints)):
        with torch.no_grad():
            for name, p in agent.named_parameters():
                agent.run_view(p)[k].copy_(c["agent"][name])
        stage = schedule.stage_at(run.stages, c["iteration"])
        if stage != run.stage:  # the checkpoint's environments are those of the stage it was written in
            enter_stage(run, stage, threads, reset=False)
            views.bind(k, run.env)
        run.env.load_state(c["env_state"])
        for key in LoopState.TENSORS:
            getattr(state, key)[k] = c[key].to(device)
        if stack:
            stack.stack[k] = c["frame_stack"].to(device)
        if normalizer:
            for name, value in c["normalizer"].items():
                getattr(normalizer, name)[k] = value.to(device)
        run.history = c["history"]
        boards[k].purge(c["global_step"])
    rundir.load_optimizer(optimizer, agent, [c["optimizer"] for c in checkpoints])
    c = checkpoints[0]
    state.iteration, state.global_step = c["iteration"], c["global_step"]
    state.optimizer_steps, state.train_seconds = c["optimizer_steps"], c["train_seconds"]
    streams.wait_for(run.stream for run in runs)
    for run in runs:
        mode = f"; --augment-mode {run.args.augment_mode}, as it started" if run.args.augment else ""
        print(f"kage.ppo.train: resuming {run.dir.path} after iteration {c['iteration']} (its checkpoint, log and "
              f"arguments agree{mode})", file=sys.stderr)
    return True
