"""Opening GPU batches of several configs from an empty kernel cache, timed two ways, each in a process of its own
with a cache of its own: `opened` (each batch compiles its config as it opens, one after another, as the trainer
did before kage.compile_kernels) and `ahead` (kage.compile_kernels first, side by side, then the batches open from
the cache). One JSON line per way on stdout.

usage: python3 lab/tools/compile_speed.py CONFIG... [--num-envs N]"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

CHILD = """
import json, sys, time
import kage
configs, mode, num_envs = json.loads(sys.argv[1]), sys.argv[2], int(sys.argv[3])
start = time.perf_counter()
report = kage.compile_kernels(configs) if mode == "ahead" else None
compiled = time.perf_counter() - start
envs = [kage.make_vec(c, num_envs, device="cuda") for c in configs]
opened = time.perf_counter() - start
for env in envs:
    env.close()
print(json.dumps({"mode": mode, "configs": len(configs), "cpus": len(__import__("os").sched_getaffinity(0)),
                  "compile_kernels": report, "compile_s": round(compiled, 2), "all_open_s": round(opened, 2)}))
"""


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("configs", nargs="+")
    parser.add_argument("--num-envs", type=int, default=128)
    args = parser.parse_args()
    for mode in ("opened", "ahead"):
        with tempfile.TemporaryDirectory(prefix=f"kage-cache-{mode}-") as cache:
            out = subprocess.run([sys.executable, "-c", CHILD, json.dumps(args.configs), mode, str(args.num_envs)],
                                 env=dict(os.environ, KAGE_CACHE_DIR=cache), capture_output=True, text=True)
        if out.returncode != 0:
            print(f"compile_speed: {mode} failed:\n{out.stderr[-3000:]}", file=sys.stderr)
            return 1
        print(out.stdout.strip().splitlines()[-1], flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
