"""The cost of a checkpoint in a pack's training clock, from its runs' metrics.jsonl: each iteration's seconds
(the batch's steps over its charts/SPS_update), their median, and the median excess over it of the iterations 0, 1
and 2 past a checkpoint, over iterations 61-1,499; the batch and the checkpoints' period are the run's own
(run.json's num_envs x num_steps and save_checkpoint_every).

usage: python3 checkpoint_iterations.py RUN_DIR ...  (one run of each pack: a pack's runs share its clock)"""
import json
import os
import statistics
import sys


def iteration_seconds(run_dir: str, batch: int) -> dict:
    seconds = {}
    with open(os.path.join(run_dir, "metrics.jsonl")) as f:
        for line in f:
            row = json.loads(line)
            if row.get("kind") == "train" and row.get("charts/SPS_update"):
                seconds[row["iteration"]] = batch / row["charts/SPS_update"]
    return seconds


def main(run_dirs):
    for run_dir in run_dirs:
        with open(os.path.join(run_dir, "run.json")) as f:
            args = json.load(f)["args"]
        every = args["save_checkpoint_every"]
        seconds = iteration_seconds(run_dir, args["num_envs"] * args["num_steps"])
        window = [i for i in sorted(seconds) if 60 < i < 1500]
        median = statistics.median(seconds[i] for i in window if i % every > 2)
        excess = [statistics.median(seconds[i] - median for i in window if i % every == k) for k in (0, 1, 2)]
        total = sum(seconds[i] for i in window) - median * len(window)
        print(f"{run_dir}: median {median:.3f} s an iteration; past a checkpoint {excess[0]:+.3f} {excess[1]:+.3f} "
              f"{excess[2]:+.3f} s (iterations 0, 1, 2 past it); {total:.1f} s above the median over {len(window)}")


if __name__ == "__main__":
    main(sys.argv[1:])
