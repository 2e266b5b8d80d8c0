"""The runs of a pack: what each owns besides its slice of the network (its arguments, Specs, stages, batches, the
CUDA stream of its batches and its directory), how its batches are made for a stage and replaced at a stage
boundary, and the device views of the training batches' outputs that the loop reads every step."""
import sys
import time
from dataclasses import dataclass, field
from typing import Dict, List, Optional

import torch

import kage
from kage import front_end
from kage.errors import ConfigError
from kage.ppo import rundir, schedule, streams
from kage.ppo.args import Args, configs_of, stages_of
from kage.ppo.evaluation import EpisodeMetrics


@dataclass
class Run:
    """What a run owns besides its slice of the network: its arguments, directory and environments."""
    args: Args
    specs: Dict[str, dict]  # each config's resolved Spec, by label
    stages: List[schedule.Stage]  # what it trains on (one stage of one config, unless a mixture or schedule)
    labels: Dict[str, str]  # each training config's label, by path
    env: Optional["kage.VecEnv"] = None  # the training batch of stage `stage`
    stream: Optional[torch.cuda.Stream] = None  # the CUDA stream of the run's batches (kage.ppo.streams)
    eval_envs: Dict[str, "kage.VecEnv"] = field(default_factory=dict)  # "train", then the eval configs by label
    stage: int = 0
    dir: Optional[rundir.RunDir] = None  # opened once everything that can be refused was checked
    history: List[dict] = field(default_factory=list)


def compile_kernels(pack: List[Args]) -> None:
    """The GPU kernels of every config of the pack's runs compiled side by side, before any batch opens (each batch
    would otherwise compile its config as it opens, one config after another, tens of seconds each); says what it
    did and how long it took."""
    configs = list(dict.fromkeys(path for args in pack for _, path in configs_of(args)))
    started = time.perf_counter()
    try:
        done = kage.compile_kernels(configs, asset_root=pack[0].asset_root)
    except ConfigError as e:
        raise SystemExit(f"{e}\nkage.ppo.train: a config has the errors above: fix the config first") from None
    except (ValueError, RuntimeError, OSError) as e:  # no GPU, not a config, NVRTC's log
        raise SystemExit(f"kage.ppo.train: compiling the kernels of {len(configs)} configs: {e}") from None
    print(f"kage.ppo.train: the kernels of {len(configs)} configs: {done['compiled']} compiled, {done['cached']} "
          f"from the cache, in {time.perf_counter() - started:.1f} s", file=sys.stderr)


def open_batches(args: Args, threads: int) -> Run:
    """The run's configs resolved (and certified as one mixture where it trains on several) and its batches made
    for its first stage, each checked to run the resolved Specs; nothing written."""
    stages = stages_of(args)
    configs = configs_of(args)
    specs = rundir.resolve_configs(configs, args.asset_root)[0]
    if schedule.is_mixture(stages):
        try:
            schedule.check_iterations(stages, args.num_iterations, args.train_schedule or "--train-config-paths")
            front_end.certify_mixture(schedule.distinct_configs(stages), args.asset_root)
        except schedule.ScheduleError as e:
            raise SystemExit(f"kage.ppo.train: {e}") from None
        except ConfigError as e:  # kagec's located line names the key, both files and the rule
            given = f"the stages of {args.train_schedule}" if args.train_schedule else "--train-config-paths"
            raise SystemExit(f"{e}\nkage.ppo.train: {given}: train on configs of one hidden game, which differ only "
                             "on visual axes (kagec diff --mixture FILE... shows every difference)") from None
    run = Run(args, specs, stages, {path: label for label, path in configs[:len(schedule.distinct_configs(stages))]},
              stream=streams.new_stream(args.device))
    run.env = stage_batch(run, 0, args.num_envs, "--num-envs", threads, seed=args.seed)
    if args.run_eval_every > 0:  # the arguments check that its counts are positive then
        run.eval_envs["train"] = stage_batch(run, 0, args.eval_num_envs, "--eval-num-envs", threads)
        for label, path in configs[len(run.labels):]:
            run.eval_envs[label] = make_batch(specs, label, path, args.eval_num_envs, "--eval-num-envs", args, threads,
                                              run.stream)
    return run


def stage_batch(run: Run, stage: int, num_envs: int, flag: str, threads: int, **seed) -> "kage.VecEnv":
    """A batch of `num_envs` environments of the run's stage `stage`: its one config, or the mixture of its configs
    by its weights (a mixture whenever the run trains on more than one config)."""
    configs, weights = run.stages[stage].configs, run.stages[stage].weights
    if not schedule.is_mixture(run.stages):
        return make_batch(run.specs, "train", configs[0], num_envs, flag, run.args, threads, run.stream, **seed)
    label = "stage " + str(stage + 1) if run.args.train_schedule else "train"
    try:
        env = kage.make_vec(list(configs), num_envs, device=run.args.device, asset_root=run.args.asset_root,
                            threads=threads, weights=weights, stream=run.stream, **seed)
    except (ValueError, RuntimeError, OSError) as e:
        raise SystemExit(f"kage.ppo.train: the mixture of {', '.join(configs)} ({label}, {flag} {num_envs}): {e}") \
            from None
    rundir.check_env(run.specs, [run.labels[c] for c in configs], env)
    return env


def enter_stage(run: Run, stage: int, threads: int, reset: bool) -> None:
    """Replaces the run's training batch (and its evaluation's "train" batch) with stage `stage`'s; `reset`: starts
    their episodes with the stage's seeds (a resume loads the checkpoint's state instead)."""
    args = run.args
    run.env.close()
    run.env = stage_batch(run, stage, args.num_envs, "--num-envs", threads)
    if reset:
        run.env.reset(seed=kage.env_seeds(schedule.stage_seed(args.seed, stage), args.num_envs))
    if "train" in run.eval_envs:
        run.eval_envs["train"].close()
        run.eval_envs["train"] = stage_batch(run, stage, args.eval_num_envs, "--eval-num-envs", threads)
    run.stage = stage


class BatchViews:
    """Device views of the outputs of each run's training batch, which every step rewrites in place: the frames,
    rewards and flags as lists over the runs, the final frames, and the finished episodes' metrics."""

    def __init__(self, runs: List[Run], dists_to_success: List[float], device):
        self.device = device
        self.dists_to_success = dists_to_success
        self.frames, self.reward, self.terminated, self.truncated, self.final_frames, self.infos = \
            ([None] * len(runs) for _ in range(6))
        for k, run in enumerate(runs):
            self.bind(k, run.env)

    def bind(self, k: int, env: "kage.VecEnv") -> None:
        """Views of run k's batch `env` (a new one at a stage boundary), in place of its earlier ones."""
        obs, reward, terminated, truncated, info = env.outputs()
        self.frames[k], self.reward[k] = torch.from_dlpack(obs), torch.from_dlpack(reward)
        self.terminated[k], self.truncated[k] = torch.from_dlpack(terminated), torch.from_dlpack(truncated)
        self.final_frames[k], self.infos[k] = torch.from_dlpack(info["final_obs"]), info
        if all(i is not None for i in self.infos):
            self.episode = EpisodeMetrics(self.infos, self.dists_to_success, self.device)


def make_batch(specs: Dict[str, dict], label: str, path: str, num_envs: int, flag: str, args: Args, threads: int,
               stream: Optional[torch.cuda.Stream], **seed) -> "kage.VecEnv":
    """A batch of config `label` (`num_envs` environments, set by `flag`) on `stream`, checked to run the Spec
    resolved for it; what make_vec refuses (too large for the memory, no GPU) ends the trainer with its message."""
    try:
        env = kage.make_vec(path, num_envs, device=args.device, asset_root=args.asset_root, threads=threads,
                            stream=stream, **seed)
    except (ValueError, RuntimeError, OSError) as e:
        raise SystemExit(f"kage.ppo.train: config '{path}' ({label}, {flag} {num_envs}): {e}") from None
    rundir.check_env(specs, [label], env)
    return env


def open_run_dir(run: Run) -> None:
    """The run's directory, locked, then created or checked against the Specs its batches run."""
    run.dir = rundir.RunDir.open(run.args, configs_of(run.args), run.specs)
