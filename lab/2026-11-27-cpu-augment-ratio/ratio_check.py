"""The augmentation issue's own check of the collapse, on the CPU: IMAGE_SKELETON trained with color_jitter for a
few iterations under each --augment-mode, and without augmentation, at one seed and a small batch (16 environments
x 128 steps, 4 minibatches, 3 epochs), printing per iteration the last minibatch's clip fraction, approximate KL
and policy entropy (metrics.jsonl), and the first iteration's too. Under update, PPO's ratio compares the policy on
augmented frames with the rollout's on plain ones, so it strays from 1 once the policy depends on its input.
    PYTHONPATH=build/python python3 lab/2026-11-27-cpu-augment-ratio/ratio_check.py OUT_DIR [ITERATIONS]"""
import json
import os
import sys

from kage.ppo import train

CONFIG = "configs/kage_bench/bases/image_skeleton.yaml"


def main(out: str, iterations: int) -> None:
    variants = {"plain": [], **{mode: ["--augment", "kage.ppo.augment:color_jitter", "--augment-mode", mode]
                                for mode in ("update", "rollout", "drac")}}
    for name, flags in variants.items():
        path = os.path.join(out, name)
        train.main(["--train-config-path", CONFIG, "--seed", "1", "--device", "cpu", "--num-envs", "16",
                    "--num-steps", "128", "--num-minibatches", "4", "--total-timesteps", str(16 * 128 * iterations),
                    "--run-eval-every", "0", "--save-checkpoint-every", "0", "--out", path, *flags])
        rows = [json.loads(line) for line in open(os.path.join(path, "metrics.jsonl"))]
        print(f"{name}: iteration clipfrac approx_kl entropy")
        for r in rows:
            if r["kind"] == "train":
                print(f"  {r['iteration']:3d} {r['losses/clipfrac']:.3f} {r['losses/approx_kl']:.4f} "
                      f"{r['losses/entropy']:.3f}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 12)
