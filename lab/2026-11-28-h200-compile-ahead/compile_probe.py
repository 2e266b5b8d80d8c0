"""Where a GPU batch's start goes: kage.compile_kernels and kage.make_vec, each from an empty kernel cache of its own,
in one process, with the wall and CPU time of each (lab/2026-11-28-h200-compile-ahead). Run from the repository
root on a GPU machine: python3 lab/2026-11-28-h200-compile-ahead/compile_probe.py"""
import os
import resource
import tempfile
import time

import kage

BENCH = "configs/kage_bench"
CONFIGS = [f"{BENCH}/bases/image_skeleton.yaml", f"{BENCH}/filters/3-eval.yaml", f"{BENCH}/filters/4-eval.yaml",
           f"{BENCH}/filters/5-eval.yaml", f"{BENCH}/filters/6-eval.yaml", f"{BENCH}/effects/1-eval.yaml"]


def cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def timed(label: str, work) -> None:
    os.environ["KAGE_CACHE_DIR"] = tempfile.mkdtemp()  # the runtime reads it at every lookup
    wall, cpu = time.perf_counter(), cpu_seconds()
    out = work()
    print(f"{label}: wall {time.perf_counter() - wall:.2f} s, cpu {cpu_seconds() - cpu:.2f} s, {out}", flush=True)


timed("compile_kernels 1 config", lambda: kage.compile_kernels(CONFIGS[:1]))
timed("make_vec 1 config uncached", lambda: kage.make_vec(CONFIGS[1], 128, device="cuda").close())
timed("compile_kernels 3 configs", lambda: kage.compile_kernels(CONFIGS[2:5]))
timed("make_vec 1 config uncached (again)", lambda: kage.make_vec(CONFIGS[5], 128, device="cuda").close())
timed("make_vec of compile_kernels's first config uncached", lambda: kage.make_vec(CONFIGS[0], 128, device="cuda").close())
