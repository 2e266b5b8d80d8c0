"""Prints, for every run under DIR (its metrics.jsonl), the evaluation points on the train config
(return and success_once) and the success_once on each held-out eval config, the policy entropy every 20
iterations, and the mean approx_kl and clipfrac: what the device scripts' learning checks compare.
   python3 lab/tools/learning_summary.py DIR"""
import glob
import json
import os
import sys


def held_out_series(points: list, name: str) -> str:
    """The success_once on eval config `name` at each evaluation point that has it."""
    return "  ".join(f"{r['iteration']}: {r['evals'][name]['success_once']:.2f}" for r in points
                     if name in r.get("evals", {}))


def summary(path: str) -> str:
    rows = [json.loads(line) for line in open(path)]
    train = [r for r in rows if r["kind"] == "train"]
    points = [r for r in rows if r["kind"] == "eval"]
    evals = "  ".join(f"{r['iteration']}: {r['train']['return']:.1f} ({r['train']['success_once']:.2f})"
                      for r in points)
    held_out = "".join(f"\n  held out {name}: {held_out_series(points, name)}"
                       for name in sorted({name for r in points for name in r.get("evals", {})}))
    entropy = " ".join("nan" if r["losses/entropy"] is None else f"{r['losses/entropy']:.2f}"
                       for r in train if r["iteration"] % 20 == 0)
    finite = [r for r in train if r["losses/approx_kl"] is not None]
    kl = sum(r["losses/approx_kl"] for r in finite) / max(len(finite), 1)
    clipfrac = sum(r["losses/clipfrac"] for r in finite) / max(len(finite), 1)
    return (f"  eval {evals}{held_out}\n  entropy every 20 iterations {entropy}\n"
            f"  mean approx_kl {kl:.4f}, clipfrac {clipfrac:.3f}")


def main(root: str) -> None:
    for path in sorted(glob.glob(os.path.join(root, "**", "metrics.jsonl"), recursive=True)):
        print(os.path.relpath(os.path.dirname(path), root))
        print(summary(path))


if __name__ == "__main__":
    main(sys.argv[1])
