"""The baseline's evaluation protocol and episode metrics (kage-ppo-baseline.md §3, §4): every run of a
pack evaluated on its train config and each eval config at once, in fresh environments, and the
metrics read from the finished episodes' final info."""
import dataclasses
import itertools
import time
from typing import Dict, List, Optional

import torch

import kage
from kage.fields import ALL, BY_NAME, DIFF_METRICS, LISTED, RECORD, RECORD_COLUMNS
from kage.ppo import streams
from kage.ppo.counter_random import CounterRandom
from kage.ppo.policy import policy_step
from kage.ppo.wrappers import FrameStack

COLUMN = {name: i for i, name in enumerate(RECORD_COLUMNS)}  # a record's columns by name (kage.fields)
TRAIN_OFFSET, EVAL_OFFSET, EVAL_OFFSET_STEP = 20_000, 10_000, 1_000  # §3.2
# The original's eval offsets below the train config's: its 11th eval config would take the train config's.
EVAL_OFFSETS = (TRAIN_OFFSET - EVAL_OFFSET) // EVAL_OFFSET_STEP


@dataclasses.dataclass(frozen=True)
class EvalSettings:
    """How an evaluation is run (§3.2): finished episodes per config, whether the policy sees stacked frames,
    and how it acts."""

    episodes: int
    frame_stack: bool = False
    greedy: bool = False  # QUIRK off: sampled actions, as the original
    bf16: bool = False
    cuda_graph: bool = False  # each step (policy, environments, records) replayed as one CUDA graph


@dataclasses.dataclass
class EvalTargets:
    """What one run is evaluated on: its seed and, by label ("train" first, then the eval configs), a batch of
    fresh environments per config."""

    seed: int
    envs: Dict[str, "kage.VecEnv"]


def evaluation_seed(run_seed: int, config_index: int, iteration: int) -> int:
    """§3.2: the seed of a run's evaluation of its config_index-th config (0: the train config, offset 20,000;
    i > 0: the i-th eval config, offset 10,000 + 1,000 (i - 1)) at `iteration`. Past the original's 10 eval
    offsets (§3.5: its 11th would take the train config's) they start again: the 11th eval config takes the
    1st's, as a second run of the same training evaluating configs 11 and on would, which the training does
    not depend on."""
    if config_index == 0:
        return run_seed + TRAIN_OFFSET + iteration
    return run_seed + EVAL_OFFSET + EVAL_OFFSET_STEP * ((config_index - 1) % EVAL_OFFSETS) + iteration


class EpisodeMetrics:
    """Device views of the finished-episode fields of a list of batches, read each step without a copy
    (§4.1): the k-th row is the k-th batch."""

    def __init__(self, infos: List[dict], dists_to_success: List[float], device):
        self.masks = [torch.from_dlpack(info["_final"]) for info in infos]
        self.fields = {n: [torch.from_dlpack(info["final_info"][n]) for info in infos] for n in RECORD}
        self.dist_to_success = torch.tensor(dists_to_success, device=device)[:, None]

    def mask(self) -> torch.Tensor:
        return torch.stack(self.masks).float()

    def rows(self) -> torch.Tensor:
        """[K, len(RECORD_COLUMNS), N] float32: the finished mask and the recorded fields of §4.1 (kage.fields:
        the return, the length, then the metrics). QUIRK: success is recomputed with a strict > at the terminal
        state (the core uses >=)."""
        f = {n: torch.stack(v).float() for n, v in self.fields.items()}
        f["success"] = (f["passed_distance"] > self.dist_to_success).float()
        return torch.stack([self.mask()] + [f[n] for n in RECORD], dim=1)


@torch.no_grad()
def evaluate(agent, envs: List[List["kage.VecEnv"]], seeds: List[List[int]],
             settings: EvalSettings) -> List[List[Dict[str, Optional[float]]]]:
    """The evaluations of each run's configs (§3.2; envs[k][c]: run k's c-th config), each in fresh
    environments with its own seed and sampling stream, all stepped together: one forward pass per step.
    Sampled actions until `episodes` episodes have finished in each. Steps are queued without a host
    synchronisation: every KAGE episode ends by truncation at `episode_length` (§2.3), so
    ceil(episodes / envs) waves of episode_length steps finish them; the records stay on the device until the
    host reads them once, after the waves, and checks the counts there (it steps on, as many waves again, if one
    fell short). Runs may evaluate different numbers of configs: the policy sees every run's C slots (C the
    most), a run's slots past its own configs hold blank frames that no environment steps and no result reads."""
    device = next(agent.parameters()).device
    flat_envs = [e for run in envs for e in run]
    flat_seeds = [s for run in seeds for s in run]
    specs = [env.resolved_specs[0]["config"] for env in flat_envs]  # the hidden game's: a mixture's configs share it
    episode_length = max(c["episode_length"] for c in specs)
    configs, n, num_actions = max(map(len, envs)), flat_envs[0].num_envs, flat_envs[0].single_action_space.n
    # Slot k * C + c holds run k's c-th config; a run's slots past its own configs are padding: blank frames, no
    # environment, no result, and a sampling stream of seed 0, which changes no other's draws (a stream's values
    # depend on its own seed alone).
    slots = len(envs) * configs
    real = [k * configs + c for k, run in enumerate(envs) for c in range(len(run))]
    padded = len(real) < slots
    slot_seeds = [0] * slots
    for slot, seed in zip(real, flat_seeds):
        slot_seeds[slot] = seed
    random = CounterRandom(slot_seeds, device)
    counter = torch.zeros((), dtype=torch.int64, device=device)  # set by fill_: no host-to-device copy
    infos = []
    for env, seed in zip(flat_envs, flat_seeds):
        infos.append(env.reset(seed=seed)[1])
    env_streams = streams.streams_of(flat_envs)  # the trainer's: a stream per run (kage.ppo.streams)
    streams.wait_for(env_streams)
    frames = [torch.from_dlpack(env.outputs()[0]) for env in flat_envs]
    if padded:
        slot_frames = [torch.zeros_like(frames[0])] * slots
        for slot, frame in zip(real, frames):
            slot_frames[slot] = frame
        frames = slot_frames
        real_slots = torch.tensor(real, device=device)
        ended = torch.zeros((slots, n), device=device)  # the padding's rows stay 0: no episode ends there
    metrics = EpisodeMetrics(infos, [c["dist_to_success"] for c in specs], device)

    def slot_mask() -> torch.Tensor:
        """The episodes that just ended, [K * C, E]."""
        return ended.index_copy_(0, real_slots, metrics.mask()) if padded else metrics.mask()

    stack = FrameStack(torch.stack(frames)) if settings.frame_stack else None
    episodes = settings.episodes
    chunk = -(-episodes // n) * episode_length

    def step(uniform: torch.Tensor) -> torch.Tensor:
        """One step of every evaluation: the policy on the frames, the environments, the records' row."""
        obs = stack.stack if stack else torch.stack(frames)             # [K * C, E, H, W, ch]
        # QUIRK: sampled, not greedy (Gumbel-max: an exact categorical sampler with no host check).
        actions, _, _ = policy_step(agent, obs.view(len(envs), configs * n, *obs.shape[2:]),
                                    uniform.reshape(len(envs), configs * n, num_actions),
                                    bf16=settings.bf16, greedy=settings.greedy)
        actions = actions.view(slots, n)
        kage.step_batches(flat_envs, actions.index_select(0, real_slots) if padded else actions)
        streams.wait_for(env_streams)
        if stack:
            stack.push(torch.stack(frames), slot_mask())
        return metrics.rows()

    graph = StepGraph(step) if graphable(settings, flat_envs) else None
    waves = []  # each wave's records, on the host
    while True:
        noise = random.uniform(0, counter.fill_(len(waves)), (chunk, n, num_actions))  # each evaluation's draws
        wave = [graph(noise[:, t]) if graph else step(noise[:, t]) for t in range(chunk)]
        waves.append(torch.stack(wave).cpu())  # the one host read, unless the episodes fell short
        host = torch.cat(waves)
        if host[:, :, 0].sum((0, 2)).min().item() >= episodes:
            break
    results = [summarize_evaluation(host[:, i], episodes) for i in range(len(flat_envs))]
    ends = list(itertools.accumulate(map(len, envs)))
    return [results[end - len(run):end] for run, end in zip(envs, ends)]


def graphable(settings: EvalSettings, envs: List["kage.VecEnv"]) -> bool:
    """Whether the evaluation's step can be a CUDA graph: asked for, without a frame stack (whose buffer is
    rebuilt each step), and every batch on a stream of its own (a capture cannot use the legacy default one)."""
    return settings.cuda_graph and not settings.frame_stack and all(env.stream != 0 for env in envs)


class StepGraph:
    """An evaluation's step replayed as one CUDA graph: the policy's kernels, every config's step and render
    launches over the batches, and the records' row, with one launch from the host per step instead of hundreds.
    The first call steps eagerly (cuDNN and Triton choose their kernels outside the capture, and the batches'
    launch plan is made); the second captures the step, which steps nothing, then replays it, as every later call
    does. The configs' launches are captured on streams of their own, forked from and joined to the capture's, so
    they still run side by side; a batch numbers its step launches on the device, so an action's report names the
    replayed step."""

    def __init__(self, step):
        self.step, self.graph = step, None
        self.uniform = self.rows = None

    def __call__(self, uniform: torch.Tensor) -> torch.Tensor:
        if self.uniform is None:
            self.uniform = uniform.clone()
            return self.step(uniform)
        self.uniform.copy_(uniform)
        if self.graph is None:
            self.graph = torch.cuda.CUDAGraph()
            with torch.cuda.graph(self.graph):
                self.rows = self.step(self.uniform)
        self.graph.replay()
        return self.rows.clone()


def summarize_evaluation(records: torch.Tensor, episodes: int) -> Dict[str, Optional[float]]:
    """§3.2 steps 3-4 from [steps, len(RECORD_COLUMNS), N] records: the LISTED fields (return and length) are
    means over the first `episodes` finished episodes (in step, then environment order) whose return is not
    exactly 0 (QUIRK: zero returns dropped; all zero gives no value); each other metric is its sum over every
    episode that finished up to the step where the count reached `episodes`, over max(1, that number)."""
    finished = records[:, COLUMN["finished"]] > 0                          # [S, N]
    per_step = finished.sum(1).cumsum(0)
    last_step = int(torch.nonzero(per_step >= episodes)[0]) if bool((per_step >= episodes).any()) else len(per_step) - 1
    values = records[: last_step + 1].permute(0, 2, 1)[finished[: last_step + 1]]  # [finished, columns], step-major
    listed = values[:episodes]
    nonzero = listed[:, COLUMN["return"]] != 0
    count = max(1, values.shape[0])
    result: Dict[str, Optional[float]] = {"episodes": int(values.shape[0])}
    for name in RECORD:
        if BY_NAME[name].record == LISTED:
            result[name] = float(listed[nonzero, COLUMN[name]].mean()) if bool(nonzero.any()) else None
        else:
            assert BY_NAME[name].record == ALL
            result[name] = float(values[:, COLUMN[name]].sum() / count)
    return result


def absolute_difference(a: Optional[float], b: Optional[float]) -> Optional[float]:
    return None if a is None or b is None else abs(a - b)


def evaluation_rows(agent, targets: List[EvalTargets], settings: EvalSettings, iteration: int,
                    global_step: int) -> List[dict]:
    """Evaluates each run's current parameters on its train config and on each eval config (§3.2, seeds by
    evaluation_seed), and the absolute differences train - eval (§3.3): one log row per run."""
    start = time.perf_counter()
    was_training = agent.training
    agent.eval()
    seeds = [[evaluation_seed(t.seed, i, iteration) for i in range(len(t.envs))] for t in targets]
    results = evaluate(agent, [list(t.envs.values()) for t in targets], seeds, settings)
    agent.train(was_training)
    rows = []
    for target, result in zip(targets, results):
        train, *evals = result
        labels = list(target.envs)[1:]
        rows.append({"kind": "eval", "iteration": iteration, "global_step": global_step, "train": train,
                     "evals": dict(zip(labels, evals)),
                     "diffs": {label: {m: absolute_difference(train[m], ev[m]) for m in DIFF_METRICS}
                               for label, ev in zip(labels, evals)},
                     "seconds": time.perf_counter() - start})
    return rows
