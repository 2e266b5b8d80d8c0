"""python3 -m kage.bench run SUITE --seeds 1-10 --out DIR [--pairs NAME ...] [--pack K] [--share-training]
[--task I[+J] | --gpus all|0,2 [--tasks 0,3+4]] [--dry-run] [trainer flags]

Trains every (pair, seed) of a suite manifest with `python3 -m kage.ppo.train`, each run in its own run
directory, one process after the other; --pack K trains K runs at once in one process (one GPU), which
the learner's batched forward and backward make several times faster in aggregate. The runs form a fixed
task table (kage.bench.tasks): --task I trains task I alone (a Slurm array task, kage.bench slurm), and
--gpus keeps one worker per GPU busy with the tasks (kage.bench.gpus); --task I+J (or --tasks I+J) trains
tasks I and J as one, in one process and one pack of their runs, for a GPU that one task's pack leaves
idle, each task still its own in the table. An --agent that cannot be packed trains its runs one at a time.
--share-training trains pairs that share a train config once per seed, in one run that evaluates all their
eval configs (the 34 pairs of KAGE-Bench have 7 train configs).
--dry-run prints the task table, and with --gpus each GPU's tasks, and trains and writes nothing.

    DIR/suite.json                  the suite's report (kagec suite): pairs, axes, paths, spec hashes, certificates
    DIR/bench.json                  the manifest, the seeds asked for so far, the trainer flags and the shared runs
    DIR/tasks.json                  the task table: the runs of each task
    DIR/runs/<pair>/seed_<s>/       a training run (kage.ppo.train's run directory), its train.log and
                                    bench_state.json (running, failed or stopped: kage.bench.run_state)
    DIR/packs/pack_<i>.json, .log   under --pack: the runs one process trained together, and its log
                                    (task_<I>_pack_<i> under --task I, task_<I>+<J>_pack_<i> under --task I+J)
    DIR/tasks/task_<I>.log          under --gpus: the log of task I's process (task_<I>+<J>.log: joined)
    DIR/bench.lock                  while a runner of all tasks (or --gpus) writes DIR; DIR/tasks/task_<I>.lock
                                    while `--task I` does, each of I and J's under `--task I+J` (kage.util.lock:
                                    host, process, start)

A plain pair trains on its train config and evaluates on its eval config (label "eval"). A sweep (one
train config, several evals) runs once per seed and evaluates every eval config of the sweep (labels:
the evals' names). Running again on the same DIR skips finished runs, resumes unfinished ones from their
checkpoints, and never overwrites a result; it refuses other trainer flags, and a config whose Spec
changed since DIR was started. One runner writes DIR (or, with --task, one task of it) at a time: a second
one refuses at once, naming the first. A runner's trainers stop when it ends, however it ends.
"""
import argparse
import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from typing import Dict, List, Optional, Union

import kage
from kage import front_end, resources
from kage.ppo import plugins
from kage.bench import dry_run, gpus, run_state, tasks
from kage.bench.records import bench_problem, parse_seeds, suite_problem, unit_name_problem
from kage.bench.units import Unit, select, train_stem, training_configs, units_of
from kage.errors import ConfigError
from kage.util.files import atomic_write, os_error_text, read_json_record, read_regular, remove_strays, write_json
from kage.util.lock import DirectoryLock, LockHeld
from kage.util.stop import child_environment, die_with_parent, stop_children
from kage.util.text import plural


# The trainer flags kage.bench sets for each run (the trainer's parser takes no abbreviations of them).
PER_RUN_FLAGS = ("--train-config-path", "--train-config-paths", "--train-weights", "--train-schedule",
                 "--eval-config-path", "--eval-config-paths", "--eval-config-labels",
                 "--seed", "--out", "--exp-name")


def units_to_train(report: dict, wanted: Optional[List[str]]) -> List[Unit]:
    """The suite's pairs and sweeps, in manifest order, or the `wanted` ones; refuses configs written inline."""
    for p in report["pairs"]:
        if "(inline)" in training_configs(p["train"]) or p["eval"]["name"] == "(inline)":
            raise SystemExit(f"kage.bench: pair {p['pair']} writes a config inline in the manifest; "
                             "kage.bench trains only configs in files: move it to a file")
    return select(units_of(report), wanted, "kage.bench")


def check_unit_name(name: str) -> None:
    """Refuses a pair or sweep name that would not be a folder inside DIR/runs/ (records.unit_name_problem), since
    its runs are written under DIR/runs/<name>/."""
    if unit_name_problem(name):
        raise SystemExit(f"kage.bench: pair or sweep name {name!r}: its runs go to DIR/runs/<name>/, so the name must "
                         "be a relative path of plain parts (no leading '/', no '.' or '..' parts, no empty part, no "
                         "backslash or control character): rename it in the suite")


def share_training(units: List[Unit], report: dict) -> List[Unit]:
    """--share-training: plain pairs whose training is one (train configs of one Spec, or mixtures or schedules
    of the same Specs, weights and stages: suite.json's train "spec_sha256") train once per seed, in one run
    that evaluates all their eval configs, each under its pair's name as label. A run depends only on its
    training, seed and flags, so these pairs' separate runs would train the same agent; the suite's 34 pairs
    have 7 train configs. Past 10 eval configs a run's evaluation seeds start again (evaluation_seed), as a
    second run's would. Sweeps and pairs with a training of their own stay."""
    train_hash = {p["pair"]: p["train"]["spec_sha256"] for p in report["pairs"] if p["sweep"] is None}
    groups: Dict[str, List[Unit]] = {}
    for unit in units:
        if unit.name in train_hash:
            groups.setdefault(train_hash[unit.name], []).append(unit)
    shared: Dict[str, List[Unit]] = {}
    for spec_hash, members in groups.items():
        if len(members) < 2:
            continue
        stem = train_stem(members[0].training)
        shared[members[0].name] = [Unit(f"shared/{stem}-{spec_hash[:8]}", "(shared)", [u.pairs[0] for u in members],
                                        shared=True, labels={u.name: u.name.replace("/", "_") for u in members})]
        for u in members[1:]:
            shared[u.name] = []
    return [v for u in units for v in shared.get(u.name, [u])]


def read_record(path: str, problem_of) -> dict:
    """bench.json or suite.json of DIR, refused in one line where it is damaged."""
    value, problem = read_json_record(path, problem_of)
    if problem:
        raise SystemExit(f"kage.bench: {path} is damaged ({problem}): restore it, or delete it and run the same "
                         "command again to write it anew (or use another --out)")
    return value


def check_suite_unchanged(out: str, report: dict) -> None:
    """Refuses a DIR started on configs whose Specs have changed since."""
    path = os.path.join(out, "suite.json")
    if not os.path.exists(path):
        return
    before = {p["pair"]: p for p in read_record(path, suite_problem)["pairs"]}
    for p in report["pairs"]:
        old = before.get(p["pair"])
        if old is None:
            continue
        for side in ("train", "eval"):
            if old[side]["spec_sha256"] != p[side]["spec_sha256"]:
                raise SystemExit(
                    f"kage.bench: {'training' if 'stages' in p[side] else 'config'} '{p[side]['name']}' "
                    f"({p['pair']}, {side}) changed since {out} was "
                    f"started (spec {old[side]['spec_sha256'][:12]} then, {p[side]['spec_sha256'][:12]} now): "
                    "restore it, or run into another --out")


def record_bench(out: str, manifest: str, seeds: List[int], units: List[Unit], trainer_args: List[str],
                 share: bool) -> None:
    """bench.json: the manifest, the trainer flags of the first run (later runs must use the same), the
    seeds and units (pairs, sweeps, shared runs) asked for so far, which the report covers, and under
    --share-training where each pair's results are ({pair: [unit, label]})."""
    path = os.path.join(out, "bench.json")
    names = [u.name for u in units]
    shared = {p["pair"]: [u.name, u.label(p)] for u in units if u.shared for p in u.pairs}
    if os.path.exists(path):
        previous = read_record(path, bench_problem)
        if previous["trainer_args"] != trainer_args:
            raise SystemExit(f"kage.bench: {out} was started with trainer flags {previous['trainer_args']}, now "
                             f"{trainer_args}: use the same flags (results must share one protocol), or another --out")
        if previous.get("share_training", False) != share:
            raise SystemExit(f"kage.bench: {out} was started {'with' if not share else 'without'} "
                             "--share-training: use the same, or another --out")
        for pair, (unit, _) in shared.items():
            before = previous.get("shared", {}).get(pair)
            if before and before[0] != unit:
                raise SystemExit(f"kage.bench: {out} runs pair {pair} in {before[0]}, this version in {unit} (a run "
                                 "now evaluates all the eval configs of its training, where it took at most 10 and "
                                 "the rest went to a second run, -part2): report or compare it as it is, and train "
                                 "more seeds or pairs into another --out")
        seeds = sorted(set(previous["seeds"]) | set(seeds))
        names = previous["units"] + [u for u in names if u not in previous["units"]]
        shared = {**previous.get("shared", {}), **shared}
    write_json(path, {"kage_bench": 1, "suite": manifest, "seeds": seeds, "units": names, "trainer_args": trainer_args,
                      "share_training": share, "shared": shared})


def training_fields(unit: Unit) -> Dict[str, object]:
    """What a unit's runs train on, as kage.ppo.train's Args fields: train_config_path for one config;
    train_config_paths and train_weights for a mixture (its configs as the suite resolved them); train_schedule
    for a schedule file (whose paths kage.ppo.train resolves against the file, as kagec suite does)."""
    train = unit.training
    if "stages" not in train:
        return {"train_config_path": train["name"]}
    if train.get("schedule") is not None:
        return {"train_config_path": "", "train_schedule": train["schedule"]}
    configs = train["stages"][0]["configs"]
    return {"train_config_path": "", "train_config_paths": [c["name"] for c in configs],
            "train_weights": [float(c["weight"]) for c in configs]}


def training_flags(unit: Unit) -> List[str]:
    """training_fields as kage.ppo.train flags."""
    fields = training_fields(unit)
    if "train_schedule" in fields:
        return ["--train-schedule", fields["train_schedule"]]
    if "train_config_paths" in fields:
        return ["--train-config-paths", *fields["train_config_paths"],
                "--train-weights", *(repr(w) for w in fields["train_weights"])]
    return ["--train-config-path", fields["train_config_path"]]


def train_flags(unit: Unit, seed: int, run_dir: str, trainer_args: List[str]) -> List[str]:
    evals = ["--eval-config-path", unit.evals[0]] if len(unit.evals) == 1 else ["--eval-config-paths", *unit.evals]
    return [*training_flags(unit), *evals, "--eval-config-labels", *unit.eval_labels, "--seed", str(seed),
            "--out", run_dir, "--exp-name", unit.name.replace("/", "_"), *trainer_args]


def checkpoint_iteration(run_dir: str) -> int:
    """The iteration of a run's last checkpoint (0 for none)."""
    try:
        iteration = json.loads(read_regular(os.path.join(run_dir, "checkpoints", "latest.json")))["iteration"]
    except (OSError, ValueError, KeyError, TypeError, RecursionError):  # absent, a FIFO or device, damaged
        return 0
    return iteration if isinstance(iteration, int) and not isinstance(iteration, bool) else 0


def training_shape(unit: Unit) -> tuple:
    """What packed runs must share of their training besides the configs themselves: one config, or a mixture
    of as many configs, or a schedule (whose stages change the batch at their own iterations)."""
    train = unit.training
    if "stages" not in train:
        return ("config",)
    if train.get("schedule") is not None:
        return ("schedule", train["schedule"])
    return ("mixture", len(train["stages"][0]["configs"]))


def packs_of(jobs: List[tuple], size: int, mix_eval_counts: bool = False) -> List[List[tuple]]:
    """Jobs (unit, seed, run_dir) in packs of at most `size`: a pack's runs evaluate the same number of
    configs (unless `mix_eval_counts`), train on the same kind of thing (training_shape) and resume from the
    same iteration (they step in lockstep)."""
    groups: Dict[tuple, List[tuple]] = {}
    for job in jobs:
        count = None if mix_eval_counts else len(job[0].evals)
        groups.setdefault((count, training_shape(job[0]), checkpoint_iteration(job[2])), []).append(job)
    return [group[i:i + size] for group in groups.values() for i in range(0, len(group), size)]


def split_tasks(bench: "Bench", groups: Optional[List[gpus.Group]]) -> List[str]:
    """A line for each task, or group of joined tasks (--tasks 3+4), of `groups` (None: every task) whose unfinished
    runs cannot share one pack (packs_of), and so train as several packs one after the other."""
    table, lines = bench.table(), []
    for group in gpus.every_task(table) if groups is None else groups:
        pending = [job for job in gpus.group_jobs(table, group) if not tasks.is_finished(job)]
        count = len(packs_of(pending, bench.pack * len(group), bench.mix_eval_counts))
        if count > 1:
            named = f"task {group[0]} trains" if len(group) == 1 else f"tasks {gpus.group_name(group)} train"
            lines.append(f"kage.bench run: {named} as {count} packs, one after the other, not as one: a pack's runs "
                         "evaluate as many configs, train on the same kind of thing (one config, a mixture of as many "
                         "configs, or a schedule) and resume from the same checkpoint iteration"
                         f"{'; join tasks whose runs do' if len(group) > 1 else ''}")
    return lines


def write_pack_file(path: str, pack: List[tuple], trainer_args: List[str]) -> str:
    """The pack's runs as kage.ppo.train arguments (python3 -m kage.ppo.train --pack): each run's Args, its
    training fields (training_fields) set over those of its flags with a single train config."""
    from kage.ppo import train
    runs = []
    for u, s, d in pack:
        flags = train_flags(u, s, d, trainer_args)
        cut = len(training_flags(u))
        args = dataclasses.asdict(train.parse_args(["--train-config-path", u.train_configs[0], *flags[cut:]]))
        runs.append({**args, **training_fields(u)})
    os.makedirs(os.path.dirname(path), exist_ok=True)
    atomic_write(path, json.dumps({"runs": runs}, indent=1).encode())  # infinities as Infinity: read by Python
    return path


class Display:
    """Runs done, the running run's steps/s and the ETA: one updating line on a terminal, one line per
    finished run otherwise."""

    def __init__(self, total: int, steps_per_run: int):
        self.total, self.steps_per_run = total, steps_per_run
        self.done = 0
        self.live = sys.stderr.isatty()
        self.rate: Optional[float] = None

    def running(self, label: str, metrics_path: str, runs: int) -> None:
        """`runs` runs in one process, `metrics_path` the log of one of them."""
        step, rate = tasks.last_progress(metrics_path)
        self.rate = rate * runs if rate else self.rate
        remaining = (self.total - self.done) * self.steps_per_run - step * runs
        eta = f"ETA {remaining / self.rate / 60:,.0f} min" if self.rate else "ETA -"
        speed = f"{self.rate:,.0f} steps/s" if self.rate else "- steps/s"
        if self.live:
            sys.stderr.write(f"\r\033[Kruns {self.done}/{self.total} · {label} step {step:,} · {speed} · {eta}")
            sys.stderr.flush()

    def finished(self, label: str, status: str) -> None:
        self.done += 1
        prefix = "\r\033[K" if self.live else ""
        print(f"{prefix}[{self.done}/{self.total}] {label}: {status}", file=sys.stderr, flush=True)


class Stop(Exception):
    """SIGTERM (Slurm's scancel, preemption, a requeue) or Ctrl-C: stop the runs, keep their checkpoints."""


def raise_stop(signum, frame):
    raise Stop()


@dataclasses.dataclass
class Bench:
    """A benchmark directory's runs, as `prepare` checked and recorded them."""

    suite: str
    out: str
    seeds_text: str
    pairs: Optional[List[str]]
    pack: int
    trainer_args: List[str]
    units: List[Unit]
    seeds: List[int]
    steps_per_run: int
    device: str
    share_training: bool
    mix_eval_counts: bool = False
    report: dict = dataclasses.field(default_factory=dict, repr=False)  # the suite's (kagec suite)

    def table(self) -> List[List[tasks.Job]]:
        return tasks.task_table(self.units, self.seeds, self.pack, self.out, self.mix_eval_counts)

    def run_command(self) -> List[str]:
        """`python3 -m kage.bench run` with this benchmark's arguments (append --task I)."""
        pairs = ["--pairs", *self.pairs] if self.pairs else []
        return [sys.executable, "-m", "kage.bench", "run", self.suite, "--seeds", self.seeds_text, "--out", self.out,
                "--pack", str(self.pack), *pairs, *(["--share-training"] if self.share_training else []),
                *(["--mix-eval-counts"] if self.mix_eval_counts else []), *self.trainer_args]


def add_bench_arguments(parser: argparse.ArgumentParser) -> None:
    """The arguments that choose a benchmark's runs (kage.bench run and slurm)."""
    parser.add_argument("suite", help="a suite manifest: a path, or a shipped suite's name (kage_bench)")
    parser.add_argument("--seeds", default="1-10", help="seeds: 1-10 (default), 1,3,5 or 7")
    parser.add_argument("--out", required=True, help="the benchmark directory (created, or continued)")
    parser.add_argument("--pairs", nargs="+", help="only these pairs or sweeps (by name)")
    parser.add_argument("--pack", type=int, default=1, help="train K runs at once in one process (default 1)")
    parser.add_argument("--share-training", action="store_true",
                        help="train pairs that share a train config once per seed, evaluating all their eval configs")
    parser.add_argument("--mix-eval-counts", action="store_true",
                        help="pack runs that evaluate different numbers of configs together, in manifest order "
                             "(the evaluation pads each to the pack's most), so that tasks can end together")


def plan(args: argparse.Namespace, trainer_args: List[str]) -> Bench:
    """Checks the arguments, the trainer flags and the suite, writing nothing. The suite and DIR are named by
    absolute paths from here on, so that every process of the benchmark resolves the same configs wherever it
    starts."""
    if args.pack < 1:
        raise SystemExit(f"kage.bench: --pack {args.pack}: a positive number of runs per process")
    from kage.ppo import args as trainer, train
    for flag in PER_RUN_FLAGS:
        if trainer.times_given(trainer_args, flag):
            raise SystemExit(f"kage.bench: {flag} is set per run by kage.bench; remove it")
    try:
        probe = train.parse_args(["--train-config-path", args.suite, *trainer_args])  # trainer flags checked now
    except SystemExit as e:
        prog = f"{trainer.PROG}: "
        if isinstance(e.code, str) and e.code.startswith(prog):  # a flag the trainer does not have, named here
            raise SystemExit(f"kage.bench: {e.code[len(prog):]}") from None
        raise
    if args.pack > 1 and not plugins.is_packable(plugins.load(probe.agent, "--agent")):
        print(f"kage.bench run: --agent {probe.agent} cannot be packed (its factory does not set packable = True): "
              f"its runs train one at a time instead of {args.pack} at once", file=sys.stderr)
        args.pack = 1
    seeds = parse_seeds(args.seeds)
    suite, out = os.path.abspath(resources.suite_path(args.suite)), os.path.abspath(args.out)
    try:
        report = front_end.suite_report(suite)
    except ConfigError as e:
        raise SystemExit(f"{e}\nkage.bench: fix the suite first") from None
    units = units_to_train(report, args.pairs)
    if args.share_training:
        units = share_training(units, report)
    for unit in units:
        check_unit_name(unit.name)
    check_before_runs(probe, units)
    warn_unrun_configs(probe.num_envs, units)
    warn_config_warnings(units)
    for p in report["pairs"]:
        if not p["certified"] and any(p["pair"] == q["pair"] for u in units for q in u.pairs):
            print(f"kage.bench: warning: {p['pair']} is not certified: {'; '.join(p['problems'])}", file=sys.stderr)
    return Bench(suite, out, args.seeds, args.pairs, args.pack, trainer_args, units, seeds,
                 probe.num_iterations * probe.batch_size, probe.device, args.share_training, args.mix_eval_counts,
                 report)


def check_before_runs(probe, units) -> None:
    """What every run's trainer would refuse at its start, refused once here before any run starts (else each run
    fails alike, and DIR keeps the flags that failed): a schedule stage after the runs' last iteration, and the
    plug-ins: imported and named, and for CPU runs also called as the trainer calls them (--agent built,
    --augment on blank frames at the first config's shape). GPU runs' plug-ins are not called here: the runner
    would hold a CUDA context beside its runs for the whole benchmark, or lack the GPU (a cluster's login node)."""
    from kage.ppo import schedule
    for unit in units:
        stages = [schedule.Stage(s["start"], tuple(c["name"] for c in s["configs"]))
                  for s in unit.training.get("stages", [])]
        where = f"{unit.name} (trains on {unit.train})"
        if unit.training.get("schedule"):  # the file itself, for the stage's line
            try:
                stages, where = schedule.read_schedule(unit.training["schedule"]), f"{unit.name}: {unit.train}"
            except schedule.ScheduleError:  # changed since the suite was certified: each run's trainer says so
                pass
        try:
            schedule.check_iterations(stages, probe.num_iterations, where)
        except schedule.ScheduleError as e:
            raise SystemExit(f"kage.bench: {e}") from None
    if probe.agent == plugins.BASELINE_AGENT and not probe.augment:
        return
    try:
        augment = plugins.load_augment(probe.augment)
        plugins.load(probe.agent, "--agent")
        if probe.device == "cpu":
            import torch
            with kage.make_vec(units[0].train_configs[0], 1, threads=1) as env:
                height, width, channels = env.single_observation_space.shape
                num_actions = int(env.single_action_space.n)
            shape = (height, width, channels * (4 if probe.use_frame_stack else 1))
            cpu = torch.device("cpu")
            plugins.build_agent(probe.agent, shape, num_actions, [0], cpu, None)
            if augment:
                warning = plugins.check_augment(augment, probe.augment, (1, 2, *shape), cpu)
                if warning:
                    print(f"kage.bench: warning: {warning}", file=sys.stderr, flush=True)
    except SystemExit as e:
        trainer = "kage.ppo.train: "  # the plug-ins' refusals name the trainer
        text = e.code[len(trainer):] if isinstance(e.code, str) and e.code.startswith(trainer) else e.code
        raise SystemExit(f"kage.bench: {text}\nkage.bench: no run started; fix the flag and run again") from None


def warn_config_warnings(units) -> None:
    """kagec's warnings of every config the units train or evaluate on, each config once, here rather than in the
    runs' logs, where each run's trainer also writes them (kage.ConfigWarning)."""
    configs: List[str] = []
    for unit in units:
        configs.extend(c for c in [*unit.train_configs, *unit.evals] if c not in configs)
    for config in configs:
        text = front_end.lint(config)
        if text:
            print(f"kage.bench: warning: {config} has kagec's warnings (silence a deliberate one with a "
                  f"'# kagec: disable=RULE' comment):\n{text.rstrip()}", file=sys.stderr)


def warn_unrun_configs(num_envs: int, units) -> None:
    """A warning, here rather than in each run's train.log, for each mixture stage whose split of --num-envs
    leaves a config of positive weight without environments (kage.mixture's rule): it would not train at all."""
    from fractions import Fraction
    from kage import mixture
    for unit in units:
        for i, stage in enumerate(unit.training.get("stages", [])):
            weights = [Fraction(c["weight"]) for c in stage["configs"]]
            counts = mixture.split(num_envs, weights)
            unrun = [stage["configs"][k]["name"] for k in mixture.unrun(counts, weights)]
            if unrun:
                print(f"kage.bench: warning: {unit.name}: --num-envs {num_envs} split over stages[{i}]'s "
                      f"{len(counts)} configs as {list(counts)} leaves {', '.join(unrun)} without environments: they "
                      "do not train; raise --num-envs", file=sys.stderr)


def record(bench: Bench) -> Bench:
    """Records the benchmark in its DIR (suite.json, bench.json, tasks.json), refusing a DIR started on other
    flags or on configs that changed since."""
    out = bench.out
    os.makedirs(out, exist_ok=True)
    for folder in ("", "packs", "slurm"):
        remove_strays(os.path.join(out, folder))  # dead writers' temporary files (run directories: the trainer's)
    check_suite_unchanged(out, bench.report)
    record_bench(out, bench.suite, bench.seeds, bench.units, bench.trainer_args, bench.share_training)
    write_json(os.path.join(out, "suite.json"), bench.report)
    tasks.write_task_table(out, bench.table(), bench.pack)
    return bench


BENCH_LOCK_ENV = "KAGE_BENCH_LOCK"  # a runner's bench.lock token, which lets its own --task children run


def lock_bench(out: str, group: Optional[gpus.Group]) -> List[DirectoryLock]:
    """The runner's locks on DIR: bench.lock for a runner of all tasks (refused while a --task process of DIR
    runs), tasks/task_<I>.lock for each task I of --task I (or I+J) (refused while another runner holds
    bench.lock)."""
    way_out = f"Wait for it to end or stop it (python3 -m kage.bench status {out}), or use another --out"
    os.makedirs(os.path.join(out, "tasks"), exist_ok=True)
    held: List[DirectoryLock] = []
    try:
        if group is not None:
            whole = DirectoryLock(out, "bench", "kage.bench run")
            holder = whole.read()
            if holder is not None and holder.get("token") != os.environ.get(BENCH_LOCK_ENV) and whole.alive(holder):
                raise LockHeld(whole.describe(holder, way_out))
            for task in group:
                one = DirectoryLock(os.path.join(out, "tasks"), f"task_{task}",
                                    f"kage.bench run --task {gpus.group_name(group)}")
                one.acquire(way_out)
                held.append(one)
            return held
        whole = DirectoryLock(out, "bench", "kage.bench run")
        whole.acquire(way_out)
        held.append(whole)
        for name in sorted(os.listdir(os.path.join(out, "tasks"))):
            if name.startswith("task_") and name.endswith(".lock"):
                one = DirectoryLock(os.path.join(out, "tasks"), name[:-len(".lock")], "")
                holder = one.read()
                if holder is not None and one.alive(holder):
                    raise LockHeld(one.describe(holder, way_out))
        os.environ[BENCH_LOCK_ENV] = whole.token
        return held
    except LockHeld as e:
        for lock in reversed(held):
            lock.release()
        raise SystemExit(f"kage.bench run: {e}") from None


def train_jobs(bench: Bench, jobs: List[tasks.Job], pack_prefix: str, task: Union[int, str, None],
               size: int) -> int:
    """Trains `jobs` (unit, seed, run_dir) one pack of up to `size` after the other, skipping finished runs;
    `task` (the task's index, or the joined tasks' name, or None) is recorded in each run's state."""
    display = Display(len(jobs), bench.steps_per_run)
    pending = []
    for job in jobs:
        if tasks.is_finished(job):
            display.finished(f"{job[0].name} seed {job[1]}", "finished earlier, skipped")
        else:
            os.makedirs(job[2], exist_ok=True)
            pending.append(job)
    failures = []
    for index, pack in enumerate(packs_of(pending, size, bench.mix_eval_counts)):
        labels = [f"{u.name} seed {s}" for u, s, _ in pack]
        run_dirs = [d for _, _, d in pack]
        if len(pack) == 1:
            log_path = os.path.join(pack[0][2], "train.log")
            command = train_flags(*pack[0], bench.trainer_args)
        else:
            pack_path = os.path.join(bench.out, "packs", f"{pack_prefix}{index}.json")
            log_path = pack_path[:-len(".json")] + ".log"
            command = ["--pack", write_pack_file(pack_path, pack, bench.trainer_args)]
        label = labels[0] if len(pack) == 1 else f"pack of {len(pack)} ({labels[0]}, ...)"
        run_state.mark(run_dirs, "running", task=task, log=log_path)
        with open(log_path, "ab") as log:
            # Its own session: a terminal's Ctrl-C or a kill of our process group reaches it through stop_children.
            child = subprocess.Popen([sys.executable, "-m", "kage.ppo.train", *command], stdout=log, stderr=log,
                                     start_new_session=True, env=child_environment())
            try:
                beat = time.monotonic()
                while child.poll() is None:
                    display.running(label, os.path.join(pack[0][2], "metrics.jsonl"), len(pack))
                    if time.monotonic() - beat > run_state.HEARTBEAT_S:
                        run_state.mark(run_dirs, "running", task=task, log=log_path)
                        beat = time.monotonic()
                    time.sleep(1.0)
            except (Stop, KeyboardInterrupt) as stopped:
                stop_children([child])
                run_state.mark(run_dirs, "stopped", task=task, log=log_path)
                print(f"\nkage.bench run: stopped {', '.join(labels)}; run again (or requeue) to resume them from "
                      "their last checkpoints", file=sys.stderr, flush=True)
                # The shell's convention for "ended by signal N", as the trainer's: Ctrl-C 130, SIGTERM 143.
                return 128 + (signal.SIGINT if isinstance(stopped, KeyboardInterrupt) else signal.SIGTERM)
        error = None
        if child.returncode == 0:
            run_state.mark(run_dirs, "done", task=task, log=log_path)
        else:
            error = run_state.last_error(log_path)
            run_state.mark(run_dirs, "failed", task=task, log=log_path, exit_code=child.returncode, error=error)
        for one in labels:
            if child.returncode == 0:
                display.finished(one, "done")
            else:
                failures.append(one)
                display.finished(one, f"FAILED (exit {child.returncode}): {error}; see {log_path}")
    if failures:
        print(f"kage.bench run: {len(failures)} run(s) failed: {', '.join(failures)}; fix what each log's last line "
              "says (above; kage.bench status DIR keeps them) and rerun: they resume from their last checkpoints",
              file=sys.stderr)
        return 1
    return 0


def main(argv: List[str]) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m kage.bench run", description=__doc__.split("\n\n")[0],
                                     epilog="Any other flag is a trainer flag (python3 -m kage.ppo.train --help).",
                                     allow_abbrev=False)  # --seed is a trainer flag, not --seeds
    add_bench_arguments(parser)
    parser.add_argument("--task", help="train only task I of DIR/tasks.json (a Slurm array task); I+J trains tasks "
                                       "I and J as one pack of their runs")
    parser.add_argument("--gpus", help="'all' or a list like 0,2: one worker process per GPU, each training "
                                       "tasks until none is left")
    parser.add_argument("--tasks", help="with --gpus: only these tasks of DIR/tasks.json, a list like 0,3,4 (what "
                                        "fits a lease); 3+4 trains tasks 3 and 4 as one, in one process and pack")
    parser.add_argument("--dry-run", action="store_true",
                        help="print the task table (and, with --gpus, each GPU's tasks) without training or writing")
    args, trainer_args = parser.parse_known_args(argv)
    die_with_parent()  # a --task worker of --gpus stops with its runner
    try:
        return run_command(args, trainer_args)
    except OSError as e:  # a DIR the file system refuses: a file, read-only, full, no permission
        raise SystemExit(os_error_text("kage.bench run", e, "--out")) from None


def run_command(args: argparse.Namespace, trainer_args: List[str]) -> int:
    """main() without its handling of file-system errors."""
    if args.task is not None and args.gpus:
        raise SystemExit("kage.bench run: --task and --gpus exclude each other: --gpus runs the tasks itself")
    if args.tasks is not None and not args.gpus:
        raise SystemExit("kage.bench run: --tasks picks the tasks that --gpus trains: add --gpus all (or use --task I "
                         "for one task in this process)")
    bench = plan(args, trainer_args)
    if args.dry_run:
        if args.task is not None:
            raise SystemExit("kage.bench run: --dry-run shows every task: drop --task")
        only = dry_run.tasks_of(args.tasks, bench.table())
        print(dry_run.describe(bench, dry_run.devices_of(args.gpus) if args.gpus else None, only))
        for line in split_tasks(bench, only):
            print(line)
        return 0
    if bench.device == "cuda":
        import torch  # here: kage.bench slurm plans on machines without torch's GPU build
        if not torch.cuda.is_available():  # every run would fail alone, each in its own train.log
            raise SystemExit("kage.bench run: --device cuda (the trainer's default), but torch sees no GPU here: "
                             "add --device cpu, or run on a GPU machine (kage.bench slurm writes a cluster job)")
    devices = gpus.parse_gpus(args.gpus, bench.device) if args.gpus else None
    count = len(bench.table())
    group = None if args.task is None else task_group(args.task, count, bench.out)
    only = gpus.parse_tasks(args.tasks, count, bench.out) if devices else None
    if group or devices:  # without either, packs_of packs the whole table's runs, not task by task
        for line in split_tasks(bench, [group] if group else only):
            print(line, file=sys.stderr, flush=True)
    held = lock_bench(bench.out, group)
    try:
        return run_locked(record(bench), devices, group, only)
    finally:
        for lock in reversed(held):
            lock.release()


def task_group(text: str, count: int, out: str) -> gpus.Group:
    """--task 'I' or 'I+J' -> [I] or [I, J], indices of the task table of `count` tasks."""
    groups = gpus.parse_tasks(text, count, out, "--task")
    if len(groups) != 1:
        raise SystemExit(f"kage.bench run: --task {text}: one task (or tasks joined by '+', like 3+4); several "
                         "tasks one after the other: --gpus all --tasks 3,4")
    return groups[0]


def run_locked(bench: Bench, devices: Optional[List[str]], group: Optional[gpus.Group],
               only: Optional[List[gpus.Group]]) -> int:
    """main() under the runner's lock; `group`, --task's tasks; `only`, --tasks'."""
    table = bench.table()
    signal.signal(signal.SIGTERM, raise_stop)
    if devices:
        return gpus.run_on_gpus(bench, table, devices, only)
    if group is None:
        status = train_jobs(bench, [job for task in table for job in task], "pack_", None, bench.pack)
    else:
        name = gpus.group_name(group)
        status = train_jobs(bench, gpus.group_jobs(table, group), f"task_{name}_pack_",
                            group[0] if len(group) == 1 else name, bench.pack * len(group))
    if status == 0 and group is None:
        print(f"kage.bench run: {plural(sum(map(len, table)), 'run')} in {bench.out}; tables and plots: "
              f"python3 -m kage.bench report {bench.out}", file=sys.stderr)
    return status
