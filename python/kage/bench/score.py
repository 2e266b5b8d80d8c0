"""python3 -m kage.bench score CHECKPOINT --suite S [--pairs NAME ...] --out DIR

Scores a saved policy (a kage.ppo.train run directory, or its checkpoints/latest.pt) on both sides of every
pair of a suite (or of the --pairs chosen), each pair or sweep evaluated as an evaluation point of training
is (kage-ppo-baseline.md §3.2, seed offsets as in training: 20,000 for the train side), then the benchmark
report's tables (kage.bench.tables: axes, pairs, sweeps, runs) with one checkpoint in place of the maxima
over a run; DIR/evaluation.json holds every value. To score configs one by one: python3 -m kage.ppo.evaluate.
"""
import argparse
import os
import sys
from typing import List, Optional

from kage import front_end, resources
from kage.bench import report, tables
from kage.bench.units import select, units_of
from kage.errors import ConfigError
from kage.fields import SUCCESS_SHOWN
from kage.ppo import rundir
from kage.ppo.evaluate import add_scoring_arguments, fail, load_for_scoring, open_env, result_of, settings_of
from kage.ppo.evaluation import EvalTargets, evaluation_rows
from kage.util.files import os_error_text, output_folder, write_json

PROTOCOL = ("One checkpoint, evaluated once on each side of each pair (the protocol of an evaluation point during "
            "training): a pair's values are that evaluation's (n = 1, SEM 0); per axis, the mean ± SEM of the "
            "pairs' values, each pair weighted equally. gap = train - eval and drop = 100 (train - eval) / train; "
            "n/a where train is 0. \"max abs diff\" is |train - eval| of the evaluation.")


def score_suite(agent, spec: dict, file: str, state: dict, options) -> dict:
    """Every chosen pair or sweep evaluated like a training run's evaluation point, then the report's three
    levels (kage.bench.report.aggregate) over these single evaluations."""
    try:
        suite = front_end.suite_report(options.suite)
    except ConfigError as e:
        fail(f"{e}\nkage.bench score: fix the suite first")
    units = select(units_of(suite), options.pairs, "kage.bench score")
    runs = {}
    for index, unit in enumerate(units, start=1):
        # A mixture's or schedule's "train" side is scored on its first config here (one config's batch), where
        # kage.ppo.train's own evaluations run the stage's mixture.
        configs = [("train", unit.train_configs[0])] + list(zip(unit.eval_labels, unit.evals))
        envs = {label: open_env(path, options.num_envs, spec, file, options) for label, path in configs}
        row = evaluation_rows(agent, [EvalTargets(options.seed, envs)], settings_of(spec, options), state["iteration"],
                              state["global_step"])[0]
        for env in envs.values():
            env.close()
        runs[unit.name] = [report.Run(options.seed, file, rundir.summarize([row])["stats"], [row])]
        shown = ", ".join(f"{label} {row['evals'][label][SUCCESS_SHOWN]:.2f}" for label in row["evals"])
        print(f"[{index}/{len(units)}] {unit.name}: {SUCCESS_SHOWN} train {row['train'][SUCCESS_SHOWN]:.2f}, {shown}",
              file=sys.stderr)
    levels = report.aggregate(units, runs)
    status = {"finished": len(units), "unfinished": [], "not_started": []}
    return {"suite": suite.get("suite", "suite"), "levels": levels, "status": status}


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m kage.bench score", description=__doc__.split("\n\n")[0])
    add_scoring_arguments(parser)
    parser.add_argument("--suite", required=True,
                        help="a suite manifest (a path, or a shipped suite's name): both sides of each pair")
    parser.add_argument("--pairs", nargs="+", help="only these pairs or sweeps")
    parser.add_argument("--out", required=True, help="where to write the tables (created)")
    options = parser.parse_args(argv)
    try:
        options.suite = resources.suite_path(options.suite)
    except FileNotFoundError as e:  # names the shipped suites nearest to it
        raise SystemExit(f"kage.bench score: --suite: {e}") from None
    file, agent, spec, state = load_for_scoring(parser, options)
    try:
        output_folder(options.out)
    except OSError as e:  # a file there, a read-only or full file system
        raise SystemExit(os_error_text("kage.bench score", e, "--out")) from None
    header = f"checkpoint {file} (iteration {state['iteration']}, seed {options.seed})"
    result = dict(result_of(file, spec, state, options), **score_suite(agent, spec, file, state, options))
    files = tables.write_tables(options.out, f"{result['suite']}: {header}", result["levels"], result["status"],
                                PROTOCOL)
    write_json(os.path.join(options.out, "evaluation.json"), dict(result, files=files + ["evaluation.json"]))
    print(f"kage.bench score: wrote {', '.join(files)} and evaluation.json into {options.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
