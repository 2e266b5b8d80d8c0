"""python3 -m kage.bench {run,slurm,status,report,compare,score,speed} ...: the benchmark's command line."""
import argparse
import sys
from typing import List, Optional

from kage.fields import INTERVAL_METRICS, SUCCESS_SHOWN


def main(argv: Optional[List[str]] = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="python3 -m kage.bench", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True,
                                     metavar="{run,slurm,status,report,compare,score,speed}")
    commands.add_parser("run", help="train every (pair, seed) of a suite; trainer flags pass through",
                        add_help=False)
    commands.add_parser("slurm", help="write (or submit) a Slurm job array over the suite's runs", add_help=False)
    commands.add_parser("speed", help="training steps/s of K packed runs and where the time goes", add_help=False)
    commands.add_parser("score", help="evaluate a checkpoint on both sides of a suite's pairs", add_help=False)
    commands.add_parser("compare", help="two or more benchmark directories of one suite side by side, with intervals",
                        add_help=False)
    status = commands.add_parser("status", help="runs done, running and failed in a benchmark directory")
    status.add_argument("dir", help="a directory written by `python3 -m kage.bench run` or `slurm`")
    report = commands.add_parser("report", help="write the tables and plots of a benchmark directory")
    report.add_argument("dir", help="a directory written by `python3 -m kage.bench run`")
    report.add_argument("--out", help="where to write (default DIR/report, DIR/report_final with --protocol final; "
                                      "the metric's name appended for another --metric: DIR/report_progress)")
    report.add_argument("--protocol", choices=("max", "final"), default="max",
                        help="a run's value: its maximum over training (the paper's) or its last evaluation")
    report.add_argument("--reps", type=int, default=50000, help="bootstrap resamples of the interval estimates")
    report.add_argument("--metric", choices=INTERVAL_METRICS, default=SUCCESS_SHOWN,
                        help="the metric of the interval estimates and profiles")
    report.add_argument("--partial", action="store_true",
                        help="an interim report: unfinished runs too, at their latest evaluation "
                             "(default DIR/report_interim)")
    if argv[:1] == ["run"]:
        from kage.bench import run
        return run.main(argv[1:])
    if argv[:1] == ["slurm"]:
        from kage.bench import slurm
        return slurm.main(argv[1:])
    if argv[:1] == ["score"]:
        from kage.bench import score
        return score.main(argv[1:])
    if argv[:1] == ["compare"]:
        from kage.bench import compare
        return compare.main(argv[1:])
    if argv[:1] == ["speed"]:
        from kage.bench import speed
        return speed.main(argv[1:])
    args = parser.parse_args(argv)
    if args.command == "status":
        from kage.bench import status as status_module
        status_module.status(args.dir, sys.stdout)
        return 0
    from kage.bench import report as report_module
    written = report_module.report(args.dir, args.out, args.protocol, args.reps, args.partial, args.metric)
    print(f"kage.bench report: wrote {written['out_dir']}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
