"""Timing for the device scripts' microbenchmarks: CUDA events around a step, after warm-up."""
import statistics

import torch


def median_ms(step, warmup: int = 3, repeats: int = 5) -> float:
    """The median over `repeats` calls of `step()`, in milliseconds of GPU time, after `warmup` calls."""
    for _ in range(warmup):
        step()
    times = []
    for _ in range(repeats):
        start, end = torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)
        start.record()
        step()
        end.record()
        torch.cuda.synchronize()
        times.append(start.elapsed_time(end))
    return statistics.median(times)
