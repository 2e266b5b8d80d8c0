"""The augmentation speed table from kage.bench speed's JSON lines (augment_device.sh's speed.jsonl): per
augmentation and mode, the steps/s with evaluations counted, as a share of the plain fast path's (the mean of the
plain runs measured first and last), the training steps/s, the phase shares and the peak memory.
    python3 lab/2026-11-27-h100-augmentation/speed_table.py speed.jsonl"""
import json
import re
import sys

PHASES = ("env", "forward", "augment", "update_forward", "backward", "optimizer", "other")
FLOOR = {"update": 0.85, "rollout": 0.85, "drac": 0.60}  # the targets, of the plain path with evaluations


def main(path: str) -> None:
    rows = [json.loads(line) for line in open(path)]
    plain = [r for r in rows if "--augment" not in r["flags"]]
    base = sum(r["steps_per_s_with_evals"] for r in plain) / len(plain)
    base_train = sum(r["steps_per_s"] for r in plain) / len(plain)
    each = ", ".join(f"{r['steps_per_s_with_evals']:,.0f}" for r in plain)
    print(f"plain fast path (K = {plain[0]['K']}, {len(plain)} measurements): {base:,.0f} steps/s with evaluations, "
          f"{base_train:,.0f} training ({each})\n")
    print("| augmentation | mode | steps/s with evals | of plain | target | training steps/s | "
          + " | ".join(PHASES) + " | eval point s | peak GiB |")
    print("|---|---|---:|---:|---:|---:|" + "---:|" * len(PHASES) + "---:|---:|")
    for r in rows:
        if r in plain:
            continue
        name = re.search(r"--augment kage\.ppo\.augment:(\w+)", r["flags"]).group(1)
        mode = re.search(r"--augment-mode (\w+)", r["flags"]).group(1)
        share = r["steps_per_s_with_evals"] / base
        mark = "met" if share >= FLOOR[mode] else "MISSED"
        print(f"| {name} | {mode} | {r['steps_per_s_with_evals']:,.0f} | {100 * share:.0f} % | "
              f"{100 * FLOOR[mode]:.0f} % {mark} | {r['steps_per_s']:,.0f} | "
              + " | ".join(f"{100 * r['shares'].get(p, 0):.0f} %" for p in PHASES)
              + f" | {r['eval_point_s']:.2f} | {r['max_memory_gib']:.1f} |")


if __name__ == "__main__":
    main(sys.argv[1])
