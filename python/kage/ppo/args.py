"""The baseline trainer's flags (kage-ppo-baseline.md §2.1: the defaults of the original's ppo_jax.py) as one
dataclass whose fields are the command line, with the checks of their combinations and the configs a run
trains and evaluates on."""
import argparse
import dataclasses
import difflib
import importlib.util
import json
import math
import os
import sys
from dataclasses import dataclass, field
from typing import List, Optional, Tuple

from kage import resources
from kage.ppo import plugins, schedule

DRAC_COEF = 0.1  # DrAC's weight of its regularisers, its paper's default
AUGMENT_MODES = ("drac", "rollout", "update")
DEFAULT_AUGMENT_MODE = "drac"  # --augment-mode where --augment is given alone (a run started in another resumes in it)

# Flags whose repetition reads as "both" but would keep the last: refused, with what to do instead.
ONE_EACH = {"--augment": "a run takes one augmentation; to combine several, write one function that calls each "
                         "(fn(obs, uniform), README: --augment)",
            "--agent": "a run trains one network; give one --agent"}

DESCRIPTION = ("PPO-CNN baseline of KAGE-Bench: train on one config, evaluate on it and on one or more others "
               "(kage-ppo-baseline.md)")


@dataclass
class Args:
    train_config_path: str = field(default="", metadata={"help": "the config to train on (YAML or kagec compile dir)"})
    train_config_paths: List[str] = field(default_factory=list, metadata={
        "help": "several YAML configs to train on at once, instead of --train-config-path: one batch split across "
                "them by --train-weights (a mixture; they must differ only on visual axes)"})
    train_weights: List[float] = field(default_factory=list, metadata={
        "help": "one non-negative weight per --train-config-paths config (default: equal)"})
    train_schedule: Optional[str] = field(default=None, metadata={
        "help": "a YAML list of stages (start iteration, configs, weights) whose mixture changes at each stage's "
                "start, instead of --train-config-path (a curriculum; kage.ppo.schedule)"})
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
    # Your own agent (kage.ppo.plugins)
    agent: str = field(default=plugins.BASELINE_AGENT, metadata={
        "help": "module:factory building the policy network (default: the baseline's Nature CNN)"})
    augment: Optional[str] = field(default=None, metadata={
        "help": "module:fn augmenting training frames, never evaluations (e.g. kage.ppo.augment:color_jitter; "
                "--augment-mode says which frames)"})
    augment_mode: Optional[str] = field(default=None, metadata={
        "help": "how --augment trains: drac (the default: PPO on plain frames plus DrAC's policy and value "
                "regularisers), rollout (the policy acts on augmented frames, and the update reuses them) or update "
                "(the update's minibatches only: unsound for strong augmentations, kept for comparison)",
        "choices": AUGMENT_MODES})
    drac_coef: float = field(default=DRAC_COEF, metadata={
        "help": "weight of DrAC's regularisers under --augment-mode drac (alpha_r; 0.1 in Raileanu et al. 2021)"})
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
    cuda_graph: bool = field(default=False, metadata={
        "help": "replay the rollout's policy step, the environments' step and each evaluation step as CUDA graphs"})
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


PROG = "python3 -m kage.ppo.train"  # the trainer's command, which its refusals start with


def times_given(argv: List[str], flag: str) -> int:
    """How many times `flag` is in `argv`, as `--flag VALUE` or `--flag=VALUE`."""
    return sum(a == flag or a.startswith(flag + "=") for a in argv)


def unknown_argument(parser: argparse.ArgumentParser, word: str) -> str:
    """What is wrong with `word`, the first argument `parser` did not take, and the fix."""
    if not word.startswith("-"):
        return f"unexpected argument {word!r}: every argument is a --flag or a flag's value"
    flag = word.split("=", 1)[0]
    flags = [o for o in parser._option_string_actions if o.startswith("--") and o != "--help"]
    near = difflib.get_close_matches(flag, flags, n=1)
    hint = f"; did you mean {near[0]}?" if near else f": {parser.prog} --help lists the flags"
    return f"unknown flag {flag}{hint}"


# The arguments that differ between the runs of a pack; the others are the pack's, shared.
PER_RUN = ("train_config_path", "train_config_paths", "train_weights", "train_schedule", "eval_config_path",
           "eval_config_paths", "eval_config_labels", "seed", "out", "exp_name")


class DefaultsShown(argparse.HelpFormatter):
    """--help with each flag's default, where its help does not already name one and it has a value."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if "default" in text or action.default in (None, "", [], argparse.SUPPRESS) or not action.option_strings:
            return text
        return text + " (default: %(default)s)"


class OneLineErrors(argparse.ArgumentParser):
    """An error in one line with where the flags are listed, not after a usage block of every flag (about 45 lines)."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} ({self.prog} --help lists every flag)\n")


def parse_args(argv: Optional[List[str]] = None) -> Args:
    """The flags of Args: --snake-case names, booleans as --flag / --no-flag."""
    # No abbreviations: kage.bench refuses the per-run flags by their full names, which an abbreviation would pass.
    parser = OneLineErrors(prog=PROG, description=DESCRIPTION, allow_abbrev=False, formatter_class=DefaultsShown)
    for f in dataclasses.fields(Args):
        flag = "--" + f.name.replace("_", "-")
        default = f.default_factory() if f.default_factory is not dataclasses.MISSING else f.default
        if f.type is bool:
            parser.add_argument(flag, action=argparse.BooleanOptionalAction, default=default, help=f.metadata["help"])
        elif f.type in (List[str], List[float]):
            parser.add_argument(flag, nargs="+", type=str if f.type == List[str] else float, default=default,
                                help=f.metadata["help"])
        else:
            kind = next(t for t in (int, float, str) if f.type in (t, Optional[t]))
            parser.add_argument(flag, type=kind, default=default, help=f.metadata["help"],
                                choices=f.metadata.get("choices"))
    parser.add_argument("--pack", help="train the runs listed in this JSON file together (written by kage.bench)")
    given = sys.argv[1:] if argv is None else argv
    for flag, one in ONE_EACH.items():  # argparse keeps the last silently, where a user may expect them combined
        times = times_given(given, flag)
        if times > 1:
            parser.error(f"{flag} given {times} times: {one}")
    known, extras = parser.parse_known_args(argv)
    if extras:  # one line naming the nearest flag, instead of argparse's usage block
        raise SystemExit(f"{parser.prog}: {unknown_argument(parser, extras[0])}")
    namespace = vars(known)
    pack = namespace.pop("pack")
    if pack:
        runs = read_pack(pack, parser)
        for args in runs:
            problems = validate(args)
            if problems:
                parser.error(f"{pack}: run {args.out}: " + "; ".join(problems))
        return runs
    args = with_config_files(Args(**namespace))
    problems = validate(args)
    if problems:
        parser.error("; ".join(problems))
    return args


def read_pack(path: str, parser: argparse.ArgumentParser) -> List[Args]:
    """The runs of a --pack file ({"runs": [arguments, ...]}, written by kage.bench), each value of its field's
    kind; anything else is refused naming the file (an OSError is left to the trainer's one line)."""
    fix = "let kage.bench run write it again, or give the run's flags on the command line"
    with open(path) as f:
        try:
            runs = json.load(f)
        except ValueError as e:
            parser.error(f"--pack {path}: not JSON ({e}): {fix}")
    runs = runs.get("runs") if isinstance(runs, dict) else None
    if not isinstance(runs, list) or not runs or not all(isinstance(run, dict) for run in runs):
        parser.error(f"--pack {path}: not a pack file (an object whose \"runs\" lists each run's arguments): {fix}")
    kinds = {f.name: f.type for f in dataclasses.fields(Args)}
    for number, run in enumerate(runs, 1):
        wrong = [f"'{k}' is not an argument" if k not in kinds else f"'{k}': {v!r:.40} is not {kind_name(kinds[k])}"
                 for k, v in run.items() if k not in kinds or not of_kind(v, kinds[k])]
        if wrong:
            parser.error(f"--pack {path}: run {number}: {'; '.join(wrong)}: {fix}")
    return [Args(**run) for run in runs]


def of_kind(value, kind) -> bool:
    """Whether a JSON value is one of an Args field's type (a float field takes an int, never a bool)."""
    if kind in (Optional[int], Optional[float], Optional[str]) and value is None:
        return True
    if kind == List[str]:
        return isinstance(value, list) and all(isinstance(v, str) for v in value)
    if kind == List[float]:
        return isinstance(value, list) and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    if kind is bool:
        return isinstance(value, bool)
    if isinstance(value, bool):
        return False
    if kind in (float, Optional[float]):
        return isinstance(value, (int, float))
    return isinstance(value, int if kind in (int, Optional[int]) else str)


def kind_name(kind) -> str:
    return {bool: "a boolean", int: "an integer", float: "a number", str: "a string", List[str]: "a list of strings",
            Optional[int]: "an integer or null", Optional[float]: "a number or null",
            Optional[str]: "a string or null", List[float]: "a list of numbers"}.get(kind, str(kind))


MAX_INT32 = 2**31 - 1  # the environment API's counts are int32


def range_problems(args: Args) -> List[str]:
    """Values outside what the baseline's arguments mean (§2.1): a discount above 1, a negative or infinite
    learning rate, a clip norm that would not clip (or ascend), counts that are not positive."""
    problems = []

    def need(ok: bool, text: str) -> None:
        if not ok:
            problems.append(text)

    finite = math.isfinite
    need(finite(args.learning_rate) and args.learning_rate > 0, f"--learning-rate {args.learning_rate}: a positive "
         "finite step size")
    need(0 <= args.gamma <= 1, f"--gamma {args.gamma}: a discount in [0, 1]")
    need(0 <= args.gae_lambda <= 1, f"--gae-lambda {args.gae_lambda}: in [0, 1]")
    need(finite(args.clip_coef) and args.clip_coef > 0, f"--clip-coef {args.clip_coef}: positive and finite")
    need(finite(args.ent_coef) and args.ent_coef >= 0, f"--ent-coef {args.ent_coef}: finite and not negative")
    need(finite(args.vf_coef) and args.vf_coef >= 0, f"--vf-coef {args.vf_coef}: finite and not negative")
    need(math.isfinite(args.drac_coef) and args.drac_coef >= 0, f"--drac-coef {args.drac_coef}: finite and not "
         "negative")
    need(args.max_grad_norm > 0, f"--max-grad-norm {args.max_grad_norm}: a positive norm (a negative one would "
         "ascend the gradient; inf turns clipping off)")
    need(not math.isnan(args.reward_clip_min) and not math.isnan(args.reward_clip_max)
         and args.reward_clip_min <= args.reward_clip_max,
         f"--reward-clip-min {args.reward_clip_min} and --reward-clip-max {args.reward_clip_max}: min <= max")
    need(args.update_epochs > 0, f"--update-epochs {args.update_epochs}: a positive number")
    need(args.num_minibatches > 0, f"--num-minibatches {args.num_minibatches}: a positive number")
    need(args.total_timesteps > 0, f"--total-timesteps {args.total_timesteps}: a positive number")
    need(0 <= args.seed < 2**63, f"--seed {args.seed}: in [0, 2**63)")
    need(args.save_checkpoint_every >= 0, f"--save-checkpoint-every {args.save_checkpoint_every}: 0 (at the end "
         "only) or a positive number of iterations")
    need(args.threads is None or 0 < args.threads <= 4096, f"--threads {args.threads}: a positive number of threads")
    need(args.asset_root is None or os.path.isdir(args.asset_root), f"--asset-root {args.asset_root}: no such "
         "directory (it replaces each config's own folder as the base of its relative asset paths)")
    need(args.num_envs <= MAX_INT32 and args.eval_num_envs <= MAX_INT32 and args.num_steps <= MAX_INT32,
         f"--num-envs, --eval-num-envs and --num-steps: at most {MAX_INT32}")
    return problems


def validate(args: Args) -> List[str]:
    """What is wrong with a combination of flags, each with its fix."""
    problems = range_problems(args)
    given = [flag for flag, value in (("--train-config-path", args.train_config_path),
                                      ("--train-config-paths", args.train_config_paths),
                                      ("--train-schedule", args.train_schedule)) if value]
    if not given:
        problems.append("--train-config-path is required (or --train-config-paths or --train-schedule)")
    elif len(given) > 1:
        problems.append(f"give one of {' and '.join(given)}: each says what the run trains on")
    if args.train_weights and not args.train_config_paths:
        problems.append("--train-weights splits --train-config-paths: give those too, or drop --train-weights")
    if args.eval_config_path and args.eval_config_paths:
        problems.append("give --eval-config-path or --eval-config-paths, not both")
    if args.out and os.path.exists(args.out) and not os.path.isdir(args.out):
        problems.append(f"--out {args.out}: exists and is not a directory: choose another --out")
    if args.device not in ("cuda", "cpu"):
        problems.append(f"--device {args.device}: use cuda or cpu")
    if args.num_envs <= 0 or args.num_steps <= 0:
        problems.append("--num-envs and --num-steps must be positive")
    elif args.num_minibatches > 0 and args.batch_size % args.num_minibatches:
        problems.append(f"--num-minibatches {args.num_minibatches} must divide the batch (num_envs * num_steps "
                        f"= {args.batch_size})")
    elif args.num_minibatches > 0 and args.num_iterations < 1:
        problems.append(f"--total-timesteps {args.total_timesteps} is less than one batch ({args.batch_size})")
    if args.run_eval_every < 0:
        problems.append(f"--run-eval-every {args.run_eval_every} must not be negative (0: no evaluation)")
    elif args.run_eval_every > 0 and (args.eval_episodes <= 0 or args.eval_num_envs <= 0):
        problems.append(f"--eval-episodes {args.eval_episodes} and --eval-num-envs {args.eval_num_envs} must be "
                        "positive while evaluation is on: to train without evaluations, pass --run-eval-every 0")
    n_evals = len(eval_paths(args))
    if args.eval_config_labels and len(args.eval_config_labels) != n_evals:
        problems.append(f"--eval-config-labels gives {len(args.eval_config_labels)} labels for {n_evals} eval configs")
    if args.device == "cpu" and (args.bf16 or args.cuda_graph):
        problems.append("--bf16 and --cuda-graph are for --device cuda")
    if args.video_every < 0:
        problems.append("--video-every must not be negative")
    if args.agent != plugins.BASELINE_AGENT and (args.fused_input or args.channels_last or args.triton_conv):
        problems.append("--fused-input, --channels-last and --triton-conv rewrite the baseline's network: drop them "
                        "with --agent")
    if args.augment is not None and not args.augment.strip():
        problems.append(f"--augment {args.augment!r}: name an augmentation as module:function (e.g. "
                        "kage.ppo.augment:random_shift), or leave the flag out")
    elif args.augment_mode and not args.augment:
        problems.append(f"--augment-mode {args.augment_mode} needs --augment module:fn (e.g. "
                        "kage.ppo.augment:color_jitter), or drop --augment-mode")
    elif args.augment_mode is not None and args.augment_mode not in AUGMENT_MODES:
        problems.append(f"--augment-mode {args.augment_mode!r}: use drac, rollout or update")
    mode = args.augment_mode or (DEFAULT_AUGMENT_MODE if args.augment else None)
    if args.drac_coef != DRAC_COEF and mode != "drac":
        problems.append(f"--drac-coef {args.drac_coef} weighs DrAC's regularisers, which run only with --augment "
                        f"under --augment-mode drac (the default){f', not {mode}' if mode else ''}: drop --drac-coef, "
                        "or train with DrAC")
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
    """(label, path) of every config of a run: those it trains on ("train", then "train.1", "train.2", ... for the
    other configs of a mixture or schedule, in order of first appearance), then the eval configs."""
    return [(training_label(i), path) for i, path in enumerate(schedule.distinct_configs(stages_of(args)))] + \
        list(zip(eval_labels(args), eval_paths(args)))


def stages_of(args: Args) -> List[schedule.Stage]:
    """What the run trains on, as stages (kage.ppo.schedule); a schedule or weights that cannot train end the
    trainer with their located line."""
    try:
        return schedule.stages_of(args)
    except schedule.ScheduleError as e:
        raise SystemExit(f"kage.ppo.train: {e}") from None


def training_label(index: int) -> str:
    """The label of a run's index-th distinct training config: "train" for the first (the evaluation's "train"
    target, the config eval configs are certified against), "train.<index>" for the others."""
    return "train" if index == 0 else f"train.{index}"


def first_train_config(args: Args) -> str:
    """The config a run trains on, or the first of its mixture or schedule: the one its directory is named after
    and its eval configs are certified against."""
    return schedule.distinct_configs(stages_of(args))[0]


def with_config_files(args: Args) -> Args:
    """`args` with each shipped config's name (kage_bench/bases/shape_black) replaced by its installed file, so
    that every later step, run.json included, sees one path."""
    return dataclasses.replace(args, train_config_path=args.train_config_path and config_file(args.train_config_path),
                               train_config_paths=[config_file(p) for p in args.train_config_paths],
                               eval_config_path=args.eval_config_path and config_file(args.eval_config_path),
                               eval_config_paths=[config_file(p) for p in args.eval_config_paths])


def config_file(config: str) -> str:
    """`config`'s file or folder, a shipped config's name resolved; kept as given when it is neither (the run
    refuses it by name when it opens its configs)."""
    try:
        return resources.config_path(config)
    except FileNotFoundError:
        return config


def eval_labels(args: Args) -> List[str]:
    """Labels of the eval configs: given, or the file base name with spaces as underscores (§3.5)."""
    labels = args.eval_config_labels or [os.path.basename(p.rstrip("/")).replace(" ", "_") for p in eval_paths(args)]
    if len(set(labels)) != len(labels):
        raise SystemExit(f"kage.ppo.train: eval configs share a label ({labels}); name them with --eval-config-labels")
    training = {training_label(i) for i in range(len(schedule.distinct_configs(stages_of(args))))}
    taken = [label for label in labels if label in training]
    if taken:
        raise SystemExit(f"kage.ppo.train: eval config label {taken[0]!r} is a training config's label: name the eval "
                         "configs otherwise with --eval-config-labels")
    return labels
