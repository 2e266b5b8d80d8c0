"""python3 -m kage.bench speed [--packs 1,4,8,16,32] [--iterations 3] [trainer flags]

Training speed of kage.ppo.train with K runs packed in one process, at the spec's per-run hyperparameters
(or the trainer flags given), with evaluation at the spec's defaults. For each K it trains K runs of one
pair (seeds 1..K) for a few iterations after a warm-up, then evaluates once, and reports:
- the aggregate training steps/s (K x 16,384 steps per iteration over the median iteration time);
- the share of an iteration's GPU timeline spent stepping the environments, in the forward passes
  (rollout and bootstrap), augmenting frames (--augment), in the update's forward and loss (DrAC's second
  forward pass included), in the backward pass and in the optimizer (gradient clipping and Adam), measured with
  CUDA events (CPU clocks on the CPU), and the rest;
- the time of one evaluation point (128 episodes on each of the two configs, per run);
- the projected wall time of a pack through a full run (1,525 iterations and 32 evaluation points), per
  run, and for the 340-run table, and the aggregate steps/s of that full run (evaluations counted).
This is a benchmark command, not a test: its numbers depend on the machine (record them in lab/
with the GPU, the date and the command).
"""
import argparse
import dataclasses
import json
import statistics
import tempfile
import time
from typing import Dict, List

import torch

from kage.ppo import train

PHASES = ("env", "forward", "augment", "update_forward", "backward", "optimizer")


class PhaseTimer:
    """Times the phases of kage.ppo.train's iterations (train's `timer("phase")` blocks) from the
    `warmup`-th on, with CUDA events on the GPU (one synchronisation per iteration, at its end)."""

    def __init__(self, device: str, warmup: int):
        self.cuda = device == "cuda"
        self.warmup = warmup
        self.iterations = 0
        self.marks: List[tuple] = []  # (phase, start, end)
        self.totals: Dict[str, float] = {p: 0.0 for p in PHASES}
        self.iteration_seconds: List[float] = []
        self.eval_seconds: List[float] = []
        self._iteration_start = time.perf_counter()

    def __call__(self, phase: str):
        timer = self

        class Span:
            def __enter__(self):
                self.start = timer._now()

            def __exit__(self, *exc):
                timer.marks.append((phase, self.start, timer._now()))

        return Span()

    def _now(self):
        if not self.cuda:
            return time.perf_counter()
        event = torch.cuda.Event(enable_timing=True)
        event.record()
        return event

    def _seconds(self, start, end) -> float:
        return end - start if not self.cuda else start.elapsed_time(end) / 1e3

    def end_iteration(self) -> None:
        if self.cuda:
            torch.cuda.synchronize()
        now = time.perf_counter()
        self.iterations += 1
        timed = self.iterations > self.warmup
        for phase, start, end in self.marks:
            if phase == "eval":
                self.eval_seconds.append(self._seconds(start, end))
            elif timed:
                self.totals[phase] += self._seconds(start, end)
        if timed:
            self.iteration_seconds.append(now - self._iteration_start)
        self.marks.clear()
        self._iteration_start = now

    def finish(self) -> None:
        """Collects the marks after the last iteration (the final evaluation)."""
        if self.cuda:
            torch.cuda.synchronize()
        for phase, start, end in self.marks:
            if phase == "eval":
                self.eval_seconds.append(self._seconds(start, end))
        self.marks.clear()


def measure(base: train.Args, packs: int, warmup: int, iterations: int, workdir: str) -> dict:
    pack = [dataclasses.replace(base, seed=seed, out=f"{workdir}/k{packs}_seed{seed}") for seed in range(1, packs + 1)]
    timer = PhaseTimer(base.device, warmup)
    start = time.perf_counter()
    train.train(pack, timer=timer, stop_after=warmup + iterations)
    timer.finish()
    wall = time.perf_counter() - start
    iteration = statistics.median(timer.iteration_seconds)
    timed = sum(timer.iteration_seconds)
    shares = {p: timer.totals[p] / timed for p in PHASES}
    shares["other"] = max(0.0, 1.0 - sum(shares.values()))
    eval_point = timer.eval_seconds[-1]  # the final one: warm
    full_run = base.num_iterations * iteration + 32 * eval_point  # a 25 M-step run has 32 evaluation points
    return {"K": packs, "steps_per_s": packs * base.batch_size / iteration, "iteration_s": iteration,
            "steps_per_s_with_evals": packs * base.batch_size * base.num_iterations / full_run,
            "shares": shares, "eval_point_s": eval_point, "first_eval_point_s": timer.eval_seconds[0],
            "full_run_hours": full_run / 3600, "gpu_hours_per_run": full_run / 3600 / packs,
            "table_gpu_hours": 340 * full_run / 3600 / packs, "command_wall_s": wall,
            "max_memory_gib": torch.cuda.max_memory_allocated() / 2**30 if base.device == "cuda" else None}


def main(argv: List[str]) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m kage.bench speed", description=__doc__.split("\n\n")[0],
                                     epilog="Any other flag is a trainer flag (python3 -m kage.ppo.train --help).")
    parser.add_argument("--packs", default="1,4,8,16,32", help="the K to measure, e.g. 1,4,8,16,32")
    parser.add_argument("--warmup", type=int, default=2, help="iterations before the timed ones")
    parser.add_argument("--iterations", type=int, default=3, help="timed iterations per K")
    parser.add_argument("--json", help="also append one JSON line per K to this file")
    args, trainer_args = parser.parse_known_args(argv)
    if not {"--train-config-path", "--train-config-paths", "--train-schedule"} & set(trainer_args):
        trainer_args = ["--train-config-path", "configs/kage_bench/bases/shape_black.yaml",
                        "--eval-config-path", "configs/kage_bench/background/1-eval.yaml", *trainer_args]
    base = train.parse_args(trainer_args)
    flags = " ".join(trainer_args)
    print(f"kage.bench speed: {torch.cuda.get_device_name() if base.device == 'cuda' else 'cpu'}, torch "
          f"{torch.__version__}, {flags}", flush=True)
    print("| K | steps/s | iteration s | env | forward | augment | update fwd | backward | optimizer | other "
          "| eval point s | full run h (wall, per pack) | steps/s with evals | GPU h per run | 340 runs GPU h | peak GiB |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|", flush=True)
    with tempfile.TemporaryDirectory() as workdir:
        for packs in [int(k) for k in args.packs.split(",")]:
            try:
                r = measure(base, packs, args.warmup, args.iterations, workdir)
            except (RuntimeError, torch.cuda.OutOfMemoryError) as e:  # e.g. out of memory: report and go on
                print(f"| {packs} | failed: {str(e).splitlines()[0][:120]} |", flush=True)
                torch.cuda.empty_cache() if base.device == "cuda" else None
                continue
            s = r["shares"]
            print(f"| {packs} | {r['steps_per_s']:,.0f} | {r['iteration_s']:.3f} | "
                  + " | ".join(f"{100 * s[p]:.0f} %" for p in PHASES + ("other",))
                  + f" | {r['eval_point_s']:.2f} | {r['full_run_hours']:.2f} | {r['steps_per_s_with_evals']:,.0f} | "
                  f"{r['gpu_hours_per_run']:.3f} | "
                  f"{r['table_gpu_hours']:.1f} | {r['max_memory_gib'] or 0:.1f} |", flush=True)
            if args.json:
                with open(args.json, "a") as f:
                    f.write(json.dumps({"flags": flags, **r}) + "\n")
            if base.device == "cuda":
                torch.cuda.empty_cache()
                torch.cuda.reset_peak_memory_stats()
    return 0
