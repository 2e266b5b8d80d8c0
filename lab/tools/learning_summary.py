"""Prints, for every run under DIR (its metrics.jsonl), the evaluation points on the train config
(return and success_once), the policy entropy every 20 iterations, and the mean approx_kl and clipfrac:
what the device scripts' learning checks compare.   python3 lab/tools/learning_summary.py DIR"""
import glob
import json
import os
import sys


def summary(path: str) -> str:
    rows = [json.loads(line) for line in open(path)]
    train = [r for r in rows if r["kind"] == "train"]
    evals = "  ".join(f"{r['iteration']}: {r['train']['return']:.1f} ({r['train']['success_once']:.2f})"
                      for r in rows if r["kind"] == "eval")
    entropy = " ".join("nan" if r["losses/entropy"] is None else f"{r['losses/entropy']:.2f}"
                       for r in train if r["iteration"] % 20 == 0)
    finite = [r for r in train if r["losses/approx_kl"] is not None]
    kl = sum(r["losses/approx_kl"] for r in finite) / max(len(finite), 1)
    clipfrac = sum(r["losses/clipfrac"] for r in finite) / max(len(finite), 1)
    return f"  eval {evals}\n  entropy every 20 iterations {entropy}\n  mean approx_kl {kl:.4f}, clipfrac {clipfrac:.3f}"


def main(root: str) -> None:
    for path in sorted(glob.glob(os.path.join(root, "**", "metrics.jsonl"), recursive=True)):
        print(os.path.relpath(os.path.dirname(path), root))
        print(summary(path))


if __name__ == "__main__":
    main(sys.argv[1])
