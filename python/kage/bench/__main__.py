"""python3 -m kage.bench {run,report,speed} ...: the benchmark's command line."""
import argparse
import sys
from typing import List, Optional


def main(argv: Optional[List[str]] = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="python3 -m kage.bench", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True, metavar="{run,report,speed}")
    commands.add_parser("run", help="train every (pair, seed) of a suite; trainer flags pass through",
                        add_help=False)
    commands.add_parser("speed", help="training steps/s of K packed runs and where the time goes", add_help=False)
    report = commands.add_parser("report", help="write the tables and plots of a benchmark directory")
    report.add_argument("dir", help="a directory written by `python3 -m kage.bench run`")
    report.add_argument("--out", help="where to write (default DIR/report)")
    if argv[:1] == ["run"]:
        from kage.bench import run
        return run.main(argv[1:])
    if argv[:1] == ["speed"]:
        from kage.bench import speed
        return speed.main(argv[1:])
    args = parser.parse_args(argv)
    from kage.bench import report as report_module
    written = report_module.report(args.dir, args.out)
    print(f"kage.bench report: wrote {written['out_dir']}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
