"""One training iteration of kage.ppo.train under torch.profiler: the share of each phase (CUDA events, as
`kage.bench speed` measures them), the kernels' summed GPU time per phase, the top kernels by GPU time overall
and per phase. K packed runs of one pair (seeds 1..K) at the spec's per-run hyperparameters, without evaluation;
the trainer flags default to the fastest recorded (lab/2026-11-24-h200-triton-conv). Iterations: `--warmup`
untimed ones (autotuning, graph capture, cuDNN's search), one timed without the profiler, one profiled.

usage: python3 lab/tools/profile_iteration.py [--packs 16] [--warmup 1] [--top 25] [--trace FILE.json]
       [trainer flags]   (shape_black unless they name --train-config-path, --train-config-paths or --train-schedule)
"""
import argparse
import collections
import contextlib
import dataclasses
import tempfile
import time
from typing import Dict, List, Tuple

import torch
from torch.autograd import DeviceType
from torch.profiler import ProfilerActivity, profile, record_function

from kage.bench.speed import PHASES
from kage.ppo import train

FASTEST = ["--bf16", "--fused-input", "--cuda-graph", "--triton-conv"]
MARK = "phase/"  # the profiler ranges' prefix


class ProfilingTimer:
    """kage.ppo.train's timer: each phase a profiler range and a pair of CUDA events; after iteration `warmup` + 1
    (timed) the profiler records iteration `warmup` + 2."""

    def __init__(self, warmup: int):
        self.warmup = warmup
        self.iterations = 0
        self.marks: List[tuple] = []
        self.measured: List[Tuple[float, Dict[str, float]]] = []  # (wall s, GPU s per phase) per timed iteration
        self.profiler = profile(activities=[ProfilerActivity.CPU, ProfilerActivity.CUDA])
        self._start = time.perf_counter()

    @contextlib.contextmanager
    def __call__(self, phase: str):
        start, end = torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)
        with record_function(MARK + phase):
            start.record()
            yield
            end.record()
        self.marks.append((phase, start, end))

    def end_iteration(self) -> None:
        torch.cuda.synchronize()
        now = time.perf_counter()
        self.iterations += 1
        if self.iterations > self.warmup:
            phases = collections.Counter()
            for phase, start, end in self.marks:
                phases[phase] += start.elapsed_time(end) / 1e3
            self.measured.append((now - self._start, phases))
        self.marks.clear()
        if self.iterations == self.warmup + 1:
            self.profiler.start()
        elif self.iterations == self.warmup + 2:
            self.profiler.stop()
        self._start = time.perf_counter()


def phase_of(event) -> str:
    """The phase range enclosing a CPU event (a kernel's launch), or "(none)"."""
    while event is not None:
        if event.name.startswith(MARK):
            return event.name[len(MARK):]
        event = event.cpu_parent
    return "(none)"


def kernel_times(events) -> Tuple[Dict[str, Dict[str, list]], Dict[str, list]]:
    """Per phase and overall: kernel name -> [GPU microseconds, launches]. A kernel is attributed to the phase of
    its launch (a graph's kernels to the phase of the graph's launch)."""
    per_phase = collections.defaultdict(lambda: collections.defaultdict(lambda: [0.0, 0]))
    for event in events:
        if event.device_type == DeviceType.CPU and event.kernels:
            phase = phase_of(event)
            for kernel in event.kernels:
                entry = per_phase[phase][kernel.name]
                entry[0] += kernel.duration
                entry[1] += 1
    overall = collections.defaultdict(lambda: [0.0, 0])
    for event in events:  # the device's own records, ranges excluded: kernels whose launch was not linked count too
        if event.device_type == DeviceType.CUDA and not getattr(event, "is_user_annotation", False):
            entry = overall[event.name]
            entry[0] += event.time_range.elapsed_us()
            entry[1] += 1
    return per_phase, overall


def print_kernels(title: str, kernels: Dict[str, list], total_us: float, top: int) -> None:
    print(f"\n{title}\n| GPU ms | share | launches | mean us | kernel |\n|---|---|---|---|---|")
    for name, (us, count) in sorted(kernels.items(), key=lambda item: -item[1][0])[:top]:
        print(f"| {us / 1e3:.2f} | {100 * us / total_us:.1f} % | {count} | {us / count:.1f} | {name[:110]} |")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                epilog="Any other flag is a trainer flag (python3 -m kage.ppo.train --help); "
                                       f"none given: {' '.join(FASTEST)}.")
    p.add_argument("--packs", type=int, default=16, help="K, the runs packed in the process")
    p.add_argument("--warmup", type=int, default=1, help="untimed iterations before the timed and profiled ones")
    p.add_argument("--top", type=int, default=25, help="kernels listed overall (a quarter of it per phase)")
    p.add_argument("--trace", help="also write the profiled iteration's Chrome trace here (Perfetto opens it)")
    a, trainer_flags = p.parse_known_args()
    trainer_flags = trainer_flags or FASTEST
    # shape_black unless the flags name what to train on (a config, a mixture or a schedule)
    named = any(flag in trainer_flags for flag in ("--train-config-path", "--train-config-paths", "--train-schedule"))
    default = [] if named else ["--train-config-path", "configs/kage_bench/bases/shape_black.yaml"]
    base = train.parse_args([*default, "--device", "cuda", "--run-eval-every", "0", *trainer_flags])
    import triton  # the versions the figures belong to
    print(f"{torch.cuda.get_device_name()}, torch {torch.__version__}, triton {triton.__version__}, K = {a.packs}, "
          f"{' '.join(trainer_flags)}", flush=True)

    timer = ProfilingTimer(a.warmup)
    with tempfile.TemporaryDirectory() as workdir:
        pack = [dataclasses.replace(base, seed=seed, out=f"{workdir}/seed{seed}") for seed in range(1, a.packs + 1)]
        train.train(pack, timer=timer, stop_after=a.warmup + 2)
    (wall, phases), (profiled_wall, profiled_phases) = timer.measured
    events = timer.profiler.events()
    per_phase, overall = kernel_times(events)
    kernel_total = sum(us for us, _ in overall.values())
    attributed = {phase: sum(us for us, _ in kernels.values()) for phase, kernels in per_phase.items()}

    print(f"\ntimed iteration: {wall:.3f} s, {a.packs * base.batch_size / wall:,.0f} steps/s; profiled iteration: "
          f"{profiled_wall:.3f} s; kernels of the profiled iteration: {kernel_total / 1e6:.3f} s of GPU time")
    # Kernel time against the unprofiled span: how busy the GPU is within a phase (the rest is launch gaps).
    print("\n| phase | GPU span s (timed) | share | GPU span s (profiled) | kernel s in phase | kernel s / timed span "
          "|\n|---|---|---|---|---|---|")
    for phase in PHASES:
        kernels_s = attributed.get(phase, 0.0) / 1e6
        print(f"| {phase} | {phases[phase]:.3f} | {100 * phases[phase] / wall:.1f} % | {profiled_phases[phase]:.3f} | "
              f"{kernels_s:.3f} | {100 * kernels_s / max(phases[phase], 1e-9):.0f} % |")
    other = wall - sum(phases[phase] for phase in PHASES)
    print(f"| other (host, logging, gaps) | {other:.3f} | {100 * other / wall:.1f} % | | "
          f"{(kernel_total - sum(attributed.values())) / 1e6:.3f} (outside the phases) | |")
    for phase in PHASES:  # the profiler attaches after --cuda-graph's capture: say so if a graph's kernels were lost
        if phases[phase] > 0 and not attributed.get(phase):
            print(f"note: no kernel was linked to phase {phase} (its kernels count under 'outside the phases')")

    print_kernels("Top kernels of the profiled iteration, all phases", overall, kernel_total, a.top)
    for phase in PHASES:
        if per_phase.get(phase):
            print_kernels(f"Top kernels of phase {phase}", per_phase[phase], attributed[phase], max(5, a.top // 4))
    if a.trace:
        timer.profiler.export_chrome_trace(a.trace)
        print(f"\ntrace: {a.trace}")


if __name__ == "__main__":
    main()
