"""python3 -m kage.bench slurm SUITE --seeds 1-10 --out DIR [--pack K] [--partition P] [--time T]
[--gpus-per-task N] [--array-parallelism M] [--submit] [trainer flags]

Writes DIR/slurm/kage_bench.sbatch, a Slurm job array with one array task per task of the benchmark's task
table (a run, or under --pack K a group of up to K runs that one process trains together); array task I
runs `python3 -m kage.bench run ... --task I` on the shared DIR. The script names the interpreter, the
package, the suite and DIR by absolute paths and sets the working directory (--chdir), so a task resolves
the same configs and assets on whichever node Slurm starts it. Tasks are requeueable: a requeued or
preempted task resumes its runs from their checkpoints, and a task whose runs are finished exits at once.
Without --submit the script (which lists the task table) is printed; with --submit it goes to sbatch and
the job id is printed. Then: `kage.bench status DIR` while it runs, `kage.bench report DIR` for the tables.
"""
import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
from typing import List

from kage.bench import run, tasks
from kage.ppo.args import times_given
from kage.util.files import atomic_write, os_error_text
from kage.util.text import plural

PATH_FLAGS = ("--asset-root",)  # trainer flags that name a path: made absolute for the tasks


def absolute_paths(trainer_args: List[str]) -> List[str]:
    out = list(trainer_args)
    for i, arg in enumerate(out):
        flag, eq, value = arg.partition("=")
        if flag in PATH_FLAGS and eq:
            out[i] = f"{flag}={os.path.abspath(value)}"
        elif arg in PATH_FLAGS and i + 1 < len(out):
            out[i + 1] = os.path.abspath(out[i + 1])
    return out


def package_root() -> str:
    """The directory that holds the `kage` package this process imported (PYTHONPATH for the tasks)."""
    import kage
    return os.path.dirname(os.path.dirname(os.path.abspath(kage.__file__)))


def one_line(value: str, what: str) -> str:
    """`value` for a line of the script; a newline (or another control character) would end that line and put
    the rest of the value on a line of its own, which the shell runs: refused."""
    if any(ord(c) < 32 or ord(c) == 127 for c in value):
        raise SystemExit(f"kage.bench slurm: {what} {value!r} holds a newline or another control character, which "
                         "would become a line of the script of its own: rename it")
    return value


def directive(option: str, value: str, what: str) -> str:
    """#SBATCH's `--option=value`, the value in double quotes (with \\, " and # escaped) where it has spaces or
    one of those characters: sbatch reads the line's arguments with those rules, so the value stays one."""
    value = one_line(value, what)
    if any(c in value for c in ' \t"\\#\''):
        value = '"' + "".join("\\" + c if c in '"\\#' else c for c in value) + '"'
    return f"--{option}={value}"


def script(bench: run.Bench, table: List[List[tasks.Job]], args: argparse.Namespace) -> str:
    last = len(table) - 1
    limit = f"%{args.array_parallelism}" if args.array_parallelism else ""
    gpus = args.gpus_per_task if args.gpus_per_task is not None else (1 if bench.device == "cuda" else 0)
    cwd = one_line(os.getcwd(), "the working directory")
    one_line(bench.suite, "the suite path")
    one_line(package_root(), "the package's directory")
    directives = [directive("job-name", args.job_name, "--job-name"), f"--array=0-{last}{limit}",
                  directive("chdir", cwd, "the working directory"),
                  directive("output", os.path.join(bench.out, "slurm", "task_%a.log"), "--out"),
                  "--open-mode=append", "--ntasks=1", "--requeue"]
    if args.partition:
        directives.append(directive("partition", args.partition, "--partition"))
    if args.time:
        directives.append(directive("time", args.time, "--time"))
    if gpus:
        directives.append(f"--gpus-per-task={gpus}")
    command = " ".join(map(shlex.quote, bench.run_command()))
    lines = ["#!/bin/bash",
             f"# kage.bench: {plural(len(table), 'task')}, {plural(sum(map(len, table)), 'run')} of {bench.suite} "
             f"into {bench.out}",
             "# (written by python3 -m kage.bench slurm; progress: python3 -m kage.bench status DIR)",
             *(f"#SBATCH {d}" for d in directives),
             "set -euo pipefail",
             "# Specs name asset directories relative to the working directory: every task resolves from this one",
             f"cd {shlex.quote(os.getcwd())}",
             f"export PYTHONPATH={shlex.quote(package_root())}${{PYTHONPATH:+:$PYTHONPATH}}",
             f"exec {command} --task \"$SLURM_ARRAY_TASK_ID\"",
             "",
             "# Task table: array task -> the runs it trains (DIR/tasks.json)",
             *(f"# task {i}: {tasks.describe(task)}" for i, task in enumerate(table))]
    return "\n".join(lines) + "\n"


def submit(path: str) -> str:
    """sbatch's job id."""
    if shutil.which("sbatch") is None:
        raise SystemExit(f"kage.bench slurm: sbatch is not on PATH: run on a Slurm login node, or submit {path} "
                         "there with sbatch")
    result = subprocess.run(["sbatch", "--parsable", path], capture_output=True, text=True, timeout=120)
    if result.returncode != 0:
        raise SystemExit(f"kage.bench slurm: sbatch {path} failed (exit {result.returncode}): "
                         f"{result.stderr.strip() or result.stdout.strip()}")
    job = result.stdout.strip().split(";")[0]
    if not re.fullmatch(r"\d+", job):
        raise SystemExit(f"kage.bench slurm: sbatch answered {result.stdout.strip()!r}, not a job id")
    return job


def main(argv: List[str]) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m kage.bench slurm", description=__doc__.split("\n\n")[1],
                                     epilog="Any other flag is a trainer flag (python3 -m kage.ppo.train --help).",
                                     allow_abbrev=False)  # --seed is a trainer flag, not --seeds
    run.add_bench_arguments(parser)
    parser.add_argument("--partition", help="the Slurm partition (default: the cluster's default)")
    parser.add_argument("--time", help="time limit per array task, e.g. 4:00:00 (default: the partition's)")
    parser.add_argument("--gpus-per-task", type=int, help="GPUs per array task (default 1; 0 under --device cpu)")
    parser.add_argument("--array-parallelism", type=int, help="at most M array tasks at once (default: no limit)")
    parser.add_argument("--job-name", default="kage-bench", help="the Slurm job name (default kage-bench)")
    parser.add_argument("--submit", action="store_true", help="submit the script with sbatch and print the job id")
    args, trainer_args = parser.parse_known_args(argv)
    for flag in ("--task", "--gpus"):
        if times_given(trainer_args, flag):
            raise SystemExit(f"kage.bench slurm: {flag} is for kage.bench run; each array task is one task")
    for name in ("gpus_per_task", "array_parallelism"):
        value = getattr(args, name)
        if value is not None and value < (1 if name == "array_parallelism" else 0):
            raise SystemExit(f"kage.bench slurm: --{name.replace('_', '-')} {value}: out of range")
    try:
        return write_script(args, trainer_args)
    except OSError as e:  # a DIR the file system refuses: a file, read-only, full, no permission
        raise SystemExit(os_error_text("kage.bench slurm", e, "--out")) from None


def write_script(args: argparse.Namespace, trainer_args: List[str]) -> int:
    """main() once its flags are checked, without its handling of file-system errors."""
    bench = run.plan(args, absolute_paths(trainer_args))
    table = bench.table()
    text = script(bench, table, args)  # its values checked before anything is written
    run.record(bench)
    path = os.path.join(bench.out, "slurm", "kage_bench.sbatch")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    atomic_write(path, text.encode())
    if not args.submit:
        sys.stdout.write(text)
        print(f"kage.bench slurm: wrote {path} ({len(table)} array tasks); submit it with sbatch, or rerun with "
              "--submit", file=sys.stderr)
        return 0
    job = submit(path)
    print(job)
    print(f"kage.bench slurm: submitted {path} as job {job} ({len(table)} array tasks); follow it with "
          f"python3 -m kage.bench status {bench.out}", file=sys.stderr)
    return 0
