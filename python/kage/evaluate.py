"""python3 -m kage.evaluate CHECKPOINT (--config C [C ...] | --suite S [--pairs NAME ...]) [--out DIR]
                           [--video OUT.gif|OUT.mp4]

Scores a saved policy (a kage.train run directory, or its checkpoints/latest.pt) with the baseline's
evaluation protocol (kage-ppo-baseline.md §3.2: fresh environments, sampled actions, --episodes finished
episodes per config, the metrics of §4.1), at the checkpoint's iteration with the run's seed unless --seed
says otherwise:
- --config C ...: each config on its own (the i-th with the eval seed offset 10,000 + 1,000 i); tables
  DIR/configs.md and DIR/configs.csv;
- --suite S: both sides of every pair (or of the --pairs chosen), offsets as in training (20,000 for the
  train side), then the benchmark report's tables (kage.bench.tables: axes, pairs, sweeps, runs) with one
  checkpoint in place of the maxima over a run; DIR/evaluation.json holds every value;
- --video OUT: one episode on the one --config, with the metrics beside each frame (kage.video).
A checkpoint is refused on a config whose observation shape or action count differs from its network's.
"""
import argparse
import json
import os
import sys
from types import SimpleNamespace
from typing import List, Optional

import torch

import kage
from kage import _kage, plugins, rundir, video
from kage.bench import report, tables
from kage.errors import ConfigError
from kage.evaluation import EVAL_OFFSET, EVAL_OFFSET_STEP, METRICS, evaluate, evaluation_rows
from kage.files import atomic_write, write_json

PROTOCOL = ("One checkpoint, evaluated once on each side of each pair (the protocol of an evaluation point during "
            "training): a pair's values are that evaluation's (n = 1, SEM 0); per axis, the mean ± SEM of the "
            "pairs' values, each pair weighted equally. gap = train - eval and drop = 100 (train - eval) / train; "
            "n/a where train is 0. \"max abs diff\" is |train - eval| of the evaluation.")
CONFIG_COLUMNS = ("episodes", "return", "length", "success_once", "success", "passed_distance", "progress",
                  "jump_count", "x", "y", "vx_mean", "vy_mean")


def fail(message: str):
    raise SystemExit(f"kage.evaluate: {message}")


def checkpoint_file(path: str) -> str:
    file = os.path.join(path, "checkpoints", "latest.pt") if os.path.isdir(path) else path
    if not os.path.isfile(file):
        fail(f"{file} not found: give a kage.train run directory or its checkpoints/latest.pt")
    return file


def load_policy(file: str, device: str):
    """The checkpoint's network (K = 1, evaluation mode) and what it was trained with (agent_spec)."""
    try:
        state = torch.load(file, map_location="cpu", weights_only=False)  # a kage.train checkpoint
    except Exception as e:  # torch raises many kinds on a damaged or foreign file
        fail(f"{file} is not a readable kage.train checkpoint ({type(e).__name__}: {e})")
    if not (isinstance(state, dict) and "agent" in state and "iteration" in state):
        fail(f"{file} is not a kage.train checkpoint (no parameters and iteration)")
    spec = state.get("agent_spec") or spec_from_run_dir(file)
    agent = plugins.build_agent(spec["agent"], spec["observation_shape"], spec["num_actions"], [spec["seed"]], device)
    with torch.no_grad():
        for name, p in agent.named_parameters():
            if name not in state["agent"]:
                fail(f"{file} has no parameter '{name}' for --agent {spec['agent']}: the agent's code changed since "
                     "the run; evaluate with the code it was trained with")
            agent.run_view(p)[0].copy_(state["agent"][name])
    agent.eval()
    return agent, spec, state


def spec_from_run_dir(file: str) -> dict:
    """The agent_spec of a checkpoint written before checkpoints carried one (the baseline's network then),
    from its run directory: run.json's arguments and the train config's resolved Spec."""
    run_dir = os.path.dirname(os.path.dirname(os.path.abspath(file)))
    try:
        with open(os.path.join(run_dir, "run.json")) as f:
            args = json.load(f)["args"]
        with open(os.path.join(run_dir, "configs", "train.json")) as f:
            config = json.load(f)["config"]
    except (OSError, ValueError, KeyError) as e:
        fail(f"{file} does not name its network, and its run directory {run_dir} cannot tell it ({e}): give the "
             "checkpoint inside its kage.train run directory")
    channels = 3 * (4 if args["use_frame_stack"] else 1)
    return {"agent": args.get("agent", plugins.BASELINE_AGENT), "num_actions": 8,  # KAGE's 3 action bits
            "observation_shape": [config["H"], config["W"], channels], "use_frame_stack": args["use_frame_stack"],
            "seed": args["seed"]}


def open_env(config: str, num_envs: int, spec: dict, file: str, options) -> "kage.VecEnv":
    """A batch on `config`, refused where the policy of `file` does not fit its observations or actions."""
    if not os.path.exists(config):
        fail(f"config '{config}' not found")
    try:
        env = kage.make_vec(config, num_envs, device=options.device, asset_root=options.asset_root,
                            threads=options.threads)
    except ConfigError as e:
        fail(f"{e}\nkage.evaluate: fix the config first")
    h, w, c = env.single_observation_space.shape
    shape = [h, w, c * (4 if spec["use_frame_stack"] else 1)]
    if shape != list(spec["observation_shape"]) or env.single_action_space.n != spec["num_actions"]:
        env.close()
        fail(f"{config}: its observations are {'x'.join(map(str, shape))} with {env.single_action_space.n} actions, "
             f"but {file} holds a policy for {'x'.join(map(str, spec['observation_shape']))} with "
             f"{spec['num_actions']} actions: evaluate it on configs of the size it was trained on (keys H and W)")
    return env


def resolved(config: str, asset_root: Optional[str]) -> dict:
    return json.loads(_kage.resolve(config, asset_root or ""))


def evaluate_configs(agent, spec: dict, file: str, state: dict, options) -> List[dict]:
    """--config: each config's results (§3.2), one evaluation for all of them together."""
    envs = [open_env(c, options.num_envs, spec, file, options) for c in options.config]
    configs = [resolved(c, options.asset_root)["config"] for c in options.config]
    seeds = [options.seed + EVAL_OFFSET + EVAL_OFFSET_STEP * i + state["iteration"] for i in range(len(envs))]
    results = evaluate(agent, [envs], [seeds], [[c["dist_to_success"] for c in configs]], options.episodes,
                       max(c["episode_length"] for c in configs), protocol_args(spec, options))[0]
    for env in envs:
        env.close()
    return [dict(result, config=path) for path, result in zip(options.config, results)]


def protocol_args(spec: dict, options) -> SimpleNamespace:
    """The trainer arguments kage.evaluation reads."""
    return SimpleNamespace(eval_episodes=options.episodes, use_frame_stack=spec["use_frame_stack"], bf16=False,
                           eval_greedy=options.greedy)


def write_config_tables(out: str, results: List[dict], header: str) -> List[str]:
    rows = [[r["config"]] + [r[c] for c in CONFIG_COLUMNS] for r in results]
    markdown = tables.md_table(("config",) + CONFIG_COLUMNS[:8],
                               [[r[0], r[1]] + [tables.fmt_value(v) for v in r[2:9]] for r in rows], 1)
    atomic_write(os.path.join(out, "configs.csv"), tables.csv_text(("config",) + CONFIG_COLUMNS, rows).encode())
    atomic_write(os.path.join(out, "configs.md"), f"# {header}\n\n{markdown}\n{tables.SUCCESS_NOTE}\n".encode())
    return ["configs.csv", "configs.md"]


def evaluate_suite(agent, spec: dict, file: str, state: dict, options) -> dict:
    """--suite: every chosen pair or sweep evaluated like a training run's evaluation point, then the
    report's three levels (kage.bench.report.aggregate) over these single evaluations."""
    try:
        suite = json.loads(_kage.suite_report(options.suite))
    except ConfigError as e:
        fail(f"{e}\nkage.evaluate: fix the suite first")
    units = report.units_of(suite)
    if options.pairs:
        unknown = sorted(set(options.pairs) - {u.name for u in units})
        if unknown:
            fail(f"no pair or sweep named {', '.join(unknown)} in {options.suite}; it has "
                 f"{', '.join(u.name for u in units[:6])} ...")
        units = [u for u in units if u.name in options.pairs]
    runs = {}
    for index, unit in enumerate(units, start=1):
        configs = [("train", unit.pairs[0]["train"]["name"])] + [(report.label_of(p), p["eval"]["name"])
                                                                for p in unit.pairs]
        envs = {label: open_env(path, options.num_envs, spec, file, options) for label, path in configs}
        run = SimpleNamespace(args=SimpleNamespace(seed=options.seed), eval_envs=envs,
                              specs={label: resolved(path, options.asset_root) for label, path in configs})
        row = evaluation_rows(agent, [run], protocol_args(spec, options), state["iteration"], state["global_step"])[0]
        for env in envs.values():
            env.close()
        runs[unit.name] = [report.Run(options.seed, file, rundir.summarize([row])["stats"], [row])]
        shown = ", ".join(f"{label} {fmt(row['evals'][label])}" for label in row["evals"])
        print(f"[{index}/{len(units)}] {unit.name}: success_once train {fmt(row['train'])}, {shown}", file=sys.stderr)
    levels = report.aggregate(units, runs)
    status = {"finished": len(units), "unfinished": [], "not_started": []}
    return {"suite": suite.get("suite", "suite"), "levels": levels, "status": status}


def fmt(result: dict) -> str:
    return f"{result['success_once']:.2f}"


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m kage.evaluate", description=__doc__.split("\n\n")[0])
    parser.add_argument("checkpoint", help="a kage.train run directory, or its checkpoints/latest.pt")
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--config", nargs="+", help="configs to evaluate on (YAML or kagec compile dirs)")
    where.add_argument("--suite", help="a suite manifest: both sides of each pair")
    parser.add_argument("--pairs", nargs="+", help="with --suite: only these pairs or sweeps")
    parser.add_argument("--out", help="where to write the tables (created)")
    parser.add_argument("--video", help="record an episode on the one --config into this .gif (or .mp4)")
    parser.add_argument("--video-stride", type=int, default=1, help="keep every k-th step of the episode (default 1)")
    parser.add_argument("--episodes", type=int, default=128, help="finished episodes per config (default 128, §3.2)")
    parser.add_argument("--num-envs", type=int, default=32, help="parallel environments per config (default 32)")
    parser.add_argument("--seed", type=int, help="evaluation seed (default: the run's)")
    parser.add_argument("--greedy", action="store_true", help="most likely actions (QUIRK off: sampled, §3.2)")
    parser.add_argument("--device", default="cuda", help="cuda or cpu")
    parser.add_argument("--threads", type=int, help="CPU threads (default: all cores)")
    parser.add_argument("--asset-root", help="resolve the configs' asset paths here")
    options = parser.parse_args(argv)
    if options.video is None and options.out is None:
        parser.error("give --out DIR for the tables, or --video FILE, or both")
    if options.video is not None:
        if not options.config or len(options.config) != 1:
            parser.error("--video records one episode on one config: give exactly one --config")
        video.check_path(options.video)
    if options.pairs and not options.suite:
        parser.error("--pairs chooses among the pairs of --suite")
    if options.episodes < 1 or options.num_envs < 1 or options.video_stride < 1:
        parser.error("--episodes, --num-envs and --video-stride must be positive")
    if options.device not in ("cuda", "cpu"):
        parser.error(f"--device {options.device}: use cuda or cpu")
    if options.device == "cuda" and not torch.cuda.is_available():
        fail("--device cuda, but torch sees no GPU: use --device cpu")
    torch.set_num_threads(options.threads or os.cpu_count() or 1)

    file = checkpoint_file(options.checkpoint)
    agent, spec, state = load_policy(file, options.device)
    options.seed = spec["seed"] if options.seed is None else options.seed
    print(f"kage.evaluate: {file}: --agent {spec['agent']}, iteration {state['iteration']}, "
          f"step {state['global_step']:,}, seed {options.seed}", file=sys.stderr)
    if options.out:
        os.makedirs(options.out, exist_ok=True)
        header = f"checkpoint {file} (iteration {state['iteration']}, seed {options.seed})"
        result = {"kage_evaluation": 1, "checkpoint": file, "agent": spec["agent"], "iteration": state["iteration"],
                  "global_step": state["global_step"], "seed": options.seed, "episodes": options.episodes,
                  "metrics": list(METRICS)}
        if options.config:
            result["configs"] = evaluate_configs(agent, spec, file, state, options)
            files = write_config_tables(options.out, result["configs"], header)
        else:
            result.update(evaluate_suite(agent, spec, file, state, options))
            files = tables.write_tables(options.out, f"{result['suite']}: {header}", result["levels"],
                                        result["status"], PROTOCOL)
        write_json(os.path.join(options.out, "evaluation.json"), dict(result, files=files + ["evaluation.json"]))
        print(f"kage.evaluate: wrote {', '.join(files)} and evaluation.json into {options.out}", file=sys.stderr)
    if options.video:
        env = open_env(options.config[0], 1, spec, file, options)  # the fit check; record() opens its own
        env.close()
        length = video.record(agent, 0, options.config[0], options.seed + state["iteration"], options.video,
                              f"{os.path.basename(options.config[0])} · iteration {state['iteration']}",
                              device=options.device, asset_root=options.asset_root,
                              use_frame_stack=spec["use_frame_stack"], greedy=options.greedy,
                              stride=options.video_stride)
        print(f"kage.evaluate: wrote {options.video} ({length} steps)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
