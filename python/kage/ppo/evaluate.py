"""python3 -m kage.ppo.evaluate CHECKPOINT --config C [C ...] [--out DIR] [--video OUT.gif|OUT.mp4]

Scores a saved policy (a kage.ppo.train run directory, or its checkpoints/latest.pt) with the baseline's
evaluation protocol (kage-ppo-baseline.md §3.2: fresh environments, sampled actions, --episodes finished
episodes per config, the metrics of §4.1), at the checkpoint's iteration with the run's seed unless --seed
says otherwise:
- --config C ...: each config on its own (the i-th with the eval seed offset 10,000 + 1,000 i); tables
  DIR/configs.md and DIR/configs.csv, and DIR/evaluation.json with every value;
- --video OUT: one episode on the one --config, with the metrics beside each frame (kage.ppo.video).
A checkpoint is refused on a config whose observation shape or action count differs from its network's.
Checkpoints are read as data only (kage.ppo.checkpoint): scoring one that others share runs none of its
contents. A checkpoint of another agent than the baseline's names its module; that module's code runs
only when --agent names it on the command line.
Both sides of every pair of a suite: `python3 -m kage.bench score CHECKPOINT --suite S` (kage.bench.score).
"""
import argparse
import json
import os
import sys
from typing import List, Optional

import torch

import kage
from kage import resources
from kage.ppo import checkpoint, plugins, rundir, video
from kage.ppo.args import MAX_INT32
from kage.errors import ConfigError
from kage.fields import EPISODE_METRICS, SCORER_MARKDOWN, SCORER_METRICS, SUCCESS_NOTE
from kage.util import tables
from kage.ppo.evaluation import EvalSettings, evaluate, evaluation_seed
from kage.util.files import atomic_write, os_error_text, output_folder, read_regular, write_json

CONFIG_COLUMNS = ("episodes",) + SCORER_METRICS  # configs.csv; configs.md shows the episodes and SCORER_MARKDOWN


def fail(message: str):
    raise SystemExit(f"kage.ppo.evaluate: {message}")


def checkpoint_file(path: str) -> str:
    file = os.path.join(path, "checkpoints", "latest.pt") if os.path.isdir(path) else path
    if os.path.exists(file) and not os.path.isfile(file):
        fail(f"{file} is not a regular file (a FIFO or a device?): give a kage.ppo.train run directory or its "
             "checkpoints/latest.pt")
    if not os.path.isfile(file):
        fail(f"{file} not found: give a kage.ppo.train run directory or its checkpoints/latest.pt")
    return file


def load_policy(file: str, device: str, agent_flag: Optional[str] = None):
    """The checkpoint's network (K = 1, evaluation mode) and what it was trained with (agent_spec). The network
    is the baseline's, or `agent_flag`'s (--agent): never a module that only the checkpoint names."""
    try:
        state = checkpoint.load(file)
    except checkpoint.CheckpointError as e:
        fail(str(e))
    spec = state.get("agent_spec") or spec_from_run_dir(file)
    problem = policy_problem(state, spec)
    if problem:
        fail(f"{file}: not a policy this command can score ({problem}): give a checkpoint that kage.ppo.train wrote")
    spec = dict(spec, agent=agent_to_import(file, plugins.current_reference(spec["agent"]), agent_flag))
    agent = plugins.build_agent(spec["agent"], spec["observation_shape"], spec["num_actions"], [spec["seed"]], device)
    problem = checkpoint.structure_problem({n: agent.run_view(p)[0] for n, p in agent.named_parameters()},
                                           state["agent"], "/agent")
    if problem:
        fail(f"{file}: its parameters are not those of --agent {spec['agent']} ({problem}): the agent's code changed "
             "since the run; evaluate with the code it was trained with")
    with torch.no_grad():
        for name, p in agent.named_parameters():
            agent.run_view(p)[0].copy_(state["agent"][name])
    agent.eval()
    return agent, spec, state


def policy_problem(state: dict, spec) -> Optional[str]:
    """What a checkpoint lacks for scoring: the network's description (agent_spec) and its counters."""
    problem = checkpoint.structure_problem(
        {"agent": "", "observation_shape": [], "num_actions": 0, "use_frame_stack": False, "seed": 0}, spec,
        "/agent_spec") or checkpoint.structure_problem({"iteration": 0, "global_step": 0},
                                                       {k: state.get(k) for k in ("iteration", "global_step")})
    if problem:
        return problem
    shape = spec["observation_shape"]
    if not (len(shape) == 3 and all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in shape) and
            spec["num_actions"] > 0 and spec["seed"] >= 0 and state["iteration"] >= 0 and state["global_step"] >= 0):
        return (f"observation shape {shape}, {spec['num_actions']} actions, seed {spec['seed']}, iteration "
                f"{state['iteration']}, step {state['global_step']}")
    return None


def agent_to_import(file: str, recorded: str, agent_flag: Optional[str]) -> str:
    """The agent factory to import: --agent if given (the user's consent to run that module), else the baseline's,
    which is part of this package. A checkpoint naming another module without --agent is refused: importing a
    module named by a file someone shared would run its code."""
    if agent_flag:
        if plugins.current_reference(agent_flag) != recorded:
            print(f"kage.ppo.evaluate: note: {file} was trained with --agent {recorded}; building --agent {agent_flag}",
                  file=sys.stderr)
        return agent_flag
    if recorded != plugins.BASELINE_AGENT:
        fail(f"{file} was trained with --agent {recorded}; building its network imports that module, which runs its "
             f"code: if you trust it, pass --agent {recorded}")
    return recorded


def spec_from_run_dir(file: str) -> dict:
    """The agent_spec of a checkpoint written before checkpoints carried one (the baseline's network then),
    from its run directory: run.json's arguments and the train config's resolved Spec."""
    run_dir = os.path.dirname(os.path.dirname(os.path.abspath(file)))
    try:
        args = json.loads(read_regular(os.path.join(run_dir, "run.json")))["args"]
        config = json.loads(read_regular(os.path.join(run_dir, "configs", "train.json")))["config"]
    except (OSError, ValueError, KeyError, TypeError, RecursionError) as e:
        fail(f"{file} does not name its network, and its run directory {run_dir} cannot tell it ({e}): give the "
             "checkpoint inside its kage.ppo.train run directory")
    channels = 3 * (4 if args["use_frame_stack"] else 1)
    return {"agent": args.get("agent", plugins.BASELINE_AGENT), "num_actions": 8,  # KAGE's 3 action bits
            "observation_shape": [config["H"], config["W"], channels], "use_frame_stack": args["use_frame_stack"],
            "seed": args["seed"]}


def open_env(config: str, num_envs: int, spec: dict, file: str, options) -> "kage.VecEnv":
    """A batch on `config`, refused where the policy of `file` does not fit its observations or actions."""
    try:
        config = resources.config_path(config)
    except FileNotFoundError as e:
        fail(str(e))
    try:
        env = kage.make_vec(config, num_envs, device=options.device, asset_root=options.asset_root,
                            threads=options.threads)
    except ConfigError as e:
        fail(f"{e}\nkage.ppo.evaluate: config '{config}' has the errors above: fix the config first")
    except (ValueError, RuntimeError, OSError) as e:  # too large for the memory, no GPU, not a config
        fail(f"config '{config}': {e}")
    h, w, c = env.single_observation_space.shape
    shape = [h, w, c * (4 if spec["use_frame_stack"] else 1)]
    if shape != list(spec["observation_shape"]) or env.single_action_space.n != spec["num_actions"]:
        env.close()
        fail(f"{config}: its observations are {'x'.join(map(str, shape))} with {env.single_action_space.n} actions, "
             f"but {file} holds a policy for {'x'.join(map(str, spec['observation_shape']))} with "
             f"{spec['num_actions']} actions: evaluate it on configs of the size it was trained on (keys H and W)")
    return env


def compile_ahead(options) -> None:
    """The configs' GPU kernels compiled side by side (kage.compile_kernels) before their batches open one by one."""
    try:
        kage.compile_kernels(options.config, asset_root=options.asset_root)
    except ConfigError as e:
        fail(f"{e}\nkage.ppo.evaluate: a config has the errors above: fix the config first")
    except (ValueError, RuntimeError, OSError) as e:  # no GPU, not a config, NVRTC's log
        fail(f"compiling the kernels of the configs: {e}")


def evaluate_configs(agent, spec: dict, file: str, state: dict, options) -> List[dict]:
    """--config: each config's results (§3.2), one evaluation for all of them together; the i-th config takes
    the i-th eval config's seed."""
    if options.device == "cuda" and len(options.config) > 1:
        compile_ahead(options)
    envs = [open_env(c, options.num_envs, spec, file, options) for c in options.config]
    seeds = [evaluation_seed(options.seed, i + 1, state["iteration"]) for i in range(len(envs))]
    results = evaluate(agent, [envs], [seeds], settings_of(spec, options))[0]
    for env in envs:
        env.close()
    return [dict(result, config=path) for path, result in zip(options.config, results)]


def settings_of(spec: dict, options) -> EvalSettings:
    """The evaluation settings of the command line, for a network trained with or without stacked frames."""
    return EvalSettings(episodes=options.episodes, frame_stack=spec["use_frame_stack"], greedy=options.greedy)


def write_config_tables(out: str, results: List[dict], header: str) -> List[str]:
    rows = [[r["config"]] + [r[c] for c in CONFIG_COLUMNS] for r in results]
    markdown = tables.md_table(("config", "episodes") + SCORER_MARKDOWN,
                               [[r["config"], r["episodes"]] + [tables.fmt_value(r[m]) for m in SCORER_MARKDOWN]
                                for r in results], 1)
    atomic_write(os.path.join(out, "configs.csv"), tables.csv_text(("config",) + CONFIG_COLUMNS, rows).encode())
    atomic_write(os.path.join(out, "configs.md"), f"# {header}\n\n{markdown}\n{SUCCESS_NOTE}\n".encode())
    return ["configs.csv", "configs.md"]


def add_scoring_arguments(parser: argparse.ArgumentParser) -> None:
    """The flags every checkpoint scorer shares (this one and kage.bench score)."""
    parser.add_argument("checkpoint", help="a kage.ppo.train run directory, or its checkpoints/latest.pt")
    parser.add_argument("--episodes", type=int, default=128, help="finished episodes per config (default 128, §3.2)")
    parser.add_argument("--num-envs", type=int, default=32, help="parallel environments per config (default 32)")
    parser.add_argument("--seed", type=int, help="evaluation seed (default: the run's)")
    parser.add_argument("--greedy", action="store_true", help="most likely actions (QUIRK off: sampled, §3.2)")
    parser.add_argument("--device", default="cuda", help="cuda or cpu (default: cuda)")
    parser.add_argument("--threads", type=int, help="CPU threads (default: all cores)")
    parser.add_argument("--asset-root", help="resolve the configs' asset paths here")
    parser.add_argument("--agent", help="module:factory of the checkpoint's network when it is not the baseline's "
                                        "(importing it runs that module's code: name only code you trust)")


def load_for_scoring(parser: argparse.ArgumentParser, options):
    """Checks the shared flags, then loads the checkpoint: (file, agent, agent_spec, state); sets options.seed
    to the run's seed where --seed is not given."""
    if options.episodes < 1 or options.num_envs < 1:
        parser.error("--episodes and --num-envs must be positive")
    if options.num_envs > MAX_INT32 or (options.threads is not None and not 0 < options.threads <= MAX_INT32):
        parser.error(f"--num-envs and --threads: positive, at most {MAX_INT32}")
    if options.seed is not None and not 0 <= options.seed < 2**63:
        parser.error(f"--seed {options.seed}: in [0, 2**63)")
    if options.device not in ("cuda", "cpu"):
        parser.error(f"--device {options.device}: use cuda or cpu")
    if options.device == "cuda" and not torch.cuda.is_available():
        fail("--device cuda, but torch sees no GPU: use --device cpu")
    torch.set_num_threads(options.threads or os.cpu_count() or 1)
    file = checkpoint_file(options.checkpoint)
    agent, spec, state = load_policy(file, options.device, options.agent)
    options.seed = spec["seed"] if options.seed is None else options.seed
    print(f"{parser.prog}: {file}: --agent {spec['agent']}, iteration {state['iteration']}, "
          f"step {state['global_step']:,}, seed {options.seed}", file=sys.stderr)
    return file, agent, spec, state


def result_of(file: str, spec: dict, state: dict, options) -> dict:
    """The head of evaluation.json: what was scored, and how."""
    return {"kage_evaluation": 1, "checkpoint": file, "agent": spec["agent"], "iteration": state["iteration"],
            "global_step": state["global_step"], "seed": options.seed, "episodes": options.episodes,
            "metrics": list(EPISODE_METRICS)}


def main(argv: Optional[List[str]] = None) -> int:
    try:
        return evaluate_command(argv)
    except OSError as e:  # an --out or --video the file system refuses
        raise SystemExit(os_error_text("kage.ppo.evaluate", e, "--out or --video")) from None


def evaluate_command(argv: Optional[List[str]]) -> int:
    """main() without its handling of file-system errors."""
    parser = argparse.ArgumentParser(prog="python3 -m kage.ppo.evaluate", description=__doc__.split("\n\n")[0])
    add_scoring_arguments(parser)
    parser.add_argument("--config", nargs="+", required=True, help="configs to evaluate on (YAML or kagec compile dirs)")
    parser.add_argument("--out", help="where to write the tables (created)")
    parser.add_argument("--video", help="record an episode on the one --config into this .gif (or .mp4)")
    parser.add_argument("--video-stride", type=int, default=1, help="keep every k-th step of the episode (default 1)")
    options = parser.parse_args(argv)
    if options.video is None and options.out is None:
        parser.error("give --out DIR for the tables, or --video FILE, or both")
    if options.video is not None:
        if len(options.config) != 1:
            parser.error("--video records one episode on one config: give exactly one --config")
        video.check_path(options.video)
    if options.video_stride < 1:
        parser.error("--video-stride must be positive")
    file, agent, spec, state = load_for_scoring(parser, options)
    if options.out:
        output_folder(options.out)
        header = f"checkpoint {file} (iteration {state['iteration']}, seed {options.seed})"
        result = dict(result_of(file, spec, state, options), configs=evaluate_configs(agent, spec, file, state, options))
        files = write_config_tables(options.out, result["configs"], header)
        write_json(os.path.join(options.out, "evaluation.json"), dict(result, files=files + ["evaluation.json"]))
        print(f"kage.ppo.evaluate: wrote {', '.join(files)} and evaluation.json into {options.out}", file=sys.stderr)
    if options.video:
        env = open_env(options.config[0], 1, spec, file, options)  # the fit check; record() opens its own
        env.close()
        length = video.record(agent, 0, options.config[0], options.seed + state["iteration"], options.video,
                              f"{os.path.basename(options.config[0])} · iteration {state['iteration']}",
                              device=options.device, asset_root=options.asset_root,
                              use_frame_stack=spec["use_frame_stack"], greedy=options.greedy,
                              stride=options.video_stride)
        print(f"kage.ppo.evaluate: wrote {options.video} ({length} steps, {video.size_note(options.video)})",
              file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
