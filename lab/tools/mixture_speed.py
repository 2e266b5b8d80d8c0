"""Steps/s of a mixture on the GPU against each of its configs alone: the price of running several configs'
kernels in one batch (each part launches its own reset, step and render kernels on its rows).

usage: python3 lab/tools/mixture_speed.py [--configs A.yaml B.yaml ...] [--num-envs 16384] [--steps 200]
                                          [--repeats 7] [--warmup 50] [--json OUT.json]

A step is env.step(actions) with the actions already on the device (a torch CUDA tensor, cycled from a
pool made beforehand), which steps every environment and renders its observation. Each batch (the mixture of
all --configs with equal weights, and each config alone with --num-envs environments) is warmed up, then
timed `--repeats` times over `--steps` steps, the batches taking turns within each repeat so that clock and
thermal drift fall on all of them alike. The rate of a repeat is steps * num_envs / GPU time (CUDA events on
the default stream, which the batches use); wall time with a final synchronisation is reported beside it. The
figure of merit is the mixture's median rate as a percentage of the mean of the parts' median rates: 100 %
means the mixture costs what its parts cost alone, on average.
"""
import argparse
import json
import pathlib
import statistics
import time

import torch

import kage

BENCH = pathlib.Path(__file__).resolve().parents[2] / "configs/kage_bench"
DEFAULT_CONFIGS = [str(BENCH / c) for c in (  # the filters pairs' training config and three evaluation configs
    "bases/image_skeleton.yaml", "filters/3-eval.yaml", "filters/5-eval.yaml", "filters/9-eval.yaml")]


def timed(env, pool, steps: int):
    """(GPU seconds, wall seconds) of `steps` steps with device actions from `pool`."""
    start, end = torch.cuda.Event(enable_timing=True), torch.cuda.Event(enable_timing=True)
    torch.cuda.synchronize()
    t0 = time.perf_counter()
    start.record()
    for t in range(steps):
        env.step(pool[t % len(pool)])
    end.record()
    env.synchronize()  # also raises a deferred action error, of which there must be none
    torch.cuda.synchronize()
    return start.elapsed_time(end) / 1e3, time.perf_counter() - t0


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    p.add_argument("--configs", nargs="+", default=DEFAULT_CONFIGS,
                   help="YAML configs that certify as a mixture (kagec diff --mixture); default: four of the "
                        "filters pairs' configs")
    p.add_argument("--num-envs", type=int, default=1 << 14, help="environments of the mixture and of each part alone")
    p.add_argument("--steps", type=int, default=200, help="steps per timed repeat")
    p.add_argument("--repeats", type=int, default=7, help="timed repeats (the median is reported)")
    p.add_argument("--warmup", type=int, default=50, help="untimed steps of each batch first")
    p.add_argument("--json", help="also write the results to this JSON file")
    args = p.parse_args()
    if not torch.cuda.is_available():
        raise SystemExit("mixture_speed.py needs a CUDA GPU and torch with CUDA")
    n = args.num_envs
    device = torch.cuda.get_device_name()
    print(f"device: {device}; torch {torch.__version__}; {n} environments; {args.steps} steps x {args.repeats} "
          f"repeats after {args.warmup} warm-up steps; step = env.step(device actions) + render", flush=True)

    # A pool of random device actions, the same for every batch (made before any timing).
    gen = torch.Generator(device="cuda").manual_seed(0)
    pool = [torch.randint(0, 8, (n,), device="cuda", dtype=torch.int32, generator=gen) for _ in range(16)]

    batches = {"mixture": kage.make_vec(args.configs, n, device="cuda")}
    for k, config in enumerate(args.configs):
        batches[f"part {k}"] = kage.make_vec(config, n, device="cuda")
    mixture = batches["mixture"]
    print(f"mixture of {len(args.configs)} configs, counts {mixture.counts}, spec {mixture.spec_hash[:12]}", flush=True)
    for env in batches.values():
        env.reset(seed=0)
        for t in range(args.warmup):
            env.step(pool[t % len(pool)])
        env.synchronize()

    gpu_rates = {name: [] for name in batches}
    wall_rates = {name: [] for name in batches}
    for _ in range(args.repeats):
        for name, env in batches.items():  # turns within a repeat
            gpu_s, wall_s = timed(env, pool, args.steps)
            gpu_rates[name].append(args.steps * n / gpu_s)
            wall_rates[name].append(args.steps * n / wall_s)
    for env in batches.values():
        env.close()

    median = {name: statistics.median(r) for name, r in gpu_rates.items()}
    results = []
    labels = {"mixture": "mixture of all"} | {f"part {k}": c for k, c in enumerate(args.configs)}
    print(f"\n{'batch':<8} {'steps/s (GPU)':>15} {'steps/s (wall)':>15}  config")
    for name in batches:
        wall = statistics.median(wall_rates[name])
        print(f"{name:<8} {median[name]:>15,.0f} {wall:>15,.0f}  {labels[name]}")
        results.append({"batch": name, "config": labels[name], "steps_per_s_gpu": median[name],
                        "steps_per_s_wall": wall, "gpu_rates": gpu_rates[name]})
    parts_mean = statistics.mean(median[f"part {k}"] for k in range(len(args.configs)))
    ratio = 100.0 * median["mixture"] / parts_mean
    print(f"\nmixture: {median['mixture']:,.0f} steps/s = {ratio:.1f} % of the parts' mean {parts_mean:,.0f} steps/s "
          f"({device}, {n} environments)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"device": device, "torch": torch.__version__, "num_envs": n, "steps": args.steps,
                       "repeats": args.repeats, "warmup": args.warmup, "configs": args.configs,
                       "counts": list(mixture.counts), "results": results, "parts_mean_steps_per_s": parts_mean,
                       "mixture_percent_of_parts_mean": ratio}, f, indent=1)


if __name__ == "__main__":
    main()
