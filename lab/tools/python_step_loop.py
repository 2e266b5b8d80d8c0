"""Steps/s of a random-policy loop through the Python package on the GPU, with torch sampling the actions
on the device and taking each observation through DLPack: the figure to set beside the "steps/s with
obs" column of `kagec bench --gpu` for the same config and environment count.

usage: python3 lab/tools/python_step_loop.py CONFIG [CONFIG ...] [--log2-envs 14] [--steps 200] [--repeats 7]
Prints one JSON line per config: the median over repeats of steps/s (GPU time from CUDA events on the
stream the loop runs on, and wall time with a final synchronisation), after a warm-up.
"""
import argparse
import json
import statistics
import time

import torch

import kage


def measure(config: str, num_envs: int, steps: int, repeats: int) -> dict:
    env = kage.make_vec(config, num_envs, device="cuda")
    env.reset(seed=0)

    def loop(k: int) -> None:
        for _ in range(k):
            actions = torch.randint(0, 8, (num_envs,), device="cuda", dtype=torch.int32)
            obs, reward, terminated, truncated, info = env.step(actions)
            torch.from_dlpack(obs)

    loop(50)  # warm-up: kernels loaded, caches and clocks settled
    torch.cuda.synchronize()
    event_rates, wall_rates = [], []
    for _ in range(repeats):
        start, end = torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)
        t0 = time.perf_counter()
        start.record()
        loop(steps)
        end.record()
        torch.cuda.synchronize()
        wall = time.perf_counter() - t0
        event_rates.append(steps * num_envs / (start.elapsed_time(end) / 1e3))
        wall_rates.append(steps * num_envs / wall)
    env.close()
    return {"config": config, "envs": num_envs, "steps_per_s_events": statistics.median(event_rates),
            "steps_per_s_wall": statistics.median(wall_rates), "repeats": repeats, "steps": steps}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("configs", nargs="+")
    p.add_argument("--log2-envs", type=int, default=14)
    p.add_argument("--steps", type=int, default=200)
    p.add_argument("--repeats", type=int, default=7)
    args = p.parse_args()
    print(json.dumps({"device": torch.cuda.get_device_name(), "torch": torch.__version__}))
    for config in args.configs:
        print(json.dumps(measure(config, 1 << args.log2_envs, args.steps, args.repeats)), flush=True)


if __name__ == "__main__":
    main()
