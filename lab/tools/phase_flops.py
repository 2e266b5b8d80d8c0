"""The work of each phase of a PPO-CNN training iteration, from `kage.bench speed --json` rows: the network's
FLOPs per frame (its layers' shapes on the spec's 128 x 128 x 3 frames), the frames each phase passes (the
rollout's forward pass one a step, the update's forward and backward passes `update_epochs` a step), and so the
TFLOP/s each phase reached; then what a target rate with evaluations asks of them: the longest iteration it
allows (in the run of 25 M steps that the row's rate with evaluations describes, its evaluations as long) and the
TFLOP/s the network's passes must then average, with the other phases (environment, augmentation, optimizer,
other) as measured. Issue 38's 500 k is the default target. The rollout's bootstrap values (one forward a pack's
environment an iteration, under 1 % of its frames) are not counted.

usage: python3 lab/tools/phase_flops.py SPEED.jsonl [...] [--target 500000]
"""
import argparse
import json
import sys
from typing import Dict, List, Tuple

import torch
import torch.nn.functional as F

from kage.ppo.agent import Agent
from kage.ppo.args import Args

FRAME = (128, 128, 3)  # the observation, H x W x C (kage-ppo-baseline.md §1)
NETWORK_PHASES = ("forward", "update_forward", "backward")


def network_flops() -> Tuple[int, int]:
    """(forward, backward) FLOPs of one frame through one run's network: a multiply-add counts 2. The backward
    pass computes each layer's weight and input gradients (each as many FLOPs as its forward pass), but not the
    frames' gradient under conv1."""
    agent = Agent([1], channels=FRAME[2], height=FRAME[0], width=FRAME[1])
    x = torch.zeros(1, FRAME[2], FRAME[0], FRAME[1])
    layers = []
    for conv in (agent.conv1, agent.conv2, agent.conv3):
        x = F.conv2d(x, conv.weight, stride=conv.stride)
        layers.append(2 * x.numel() * conv.weight[0].numel())  # each output: in channels x kernel multiply-adds
    for weight in (agent.fc_weight, agent.actor_weight, agent.critic_weight):
        layers.append(2 * weight.shape[1] * weight.shape[2])
    forward = sum(layers)
    return forward, 2 * forward - layers[0]


def phase_work(row: dict, args: Args, target: float, forward: int, backward: int) -> Dict[str, object]:
    """Per network phase of the row: its seconds, TFLOP and TFLOP/s (`forward`, `backward`: FLOPs a frame); and
    the target's iteration bound."""
    iteration = row["iteration_s"]
    steps = row["steps_per_s"] * iteration  # an iteration's: K runs' batches
    frames = {"forward": steps, "update_forward": steps * args.update_epochs, "backward": steps * args.update_epochs}
    flops = {"forward": forward, "update_forward": forward, "backward": backward}
    phases = {}
    for phase in NETWORK_PHASES:
        seconds = row["shares"][phase] * iteration
        tflop = frames[phase] * flops[phase] / 1e12
        phases[phase] = {"s": seconds, "tflop": tflop, "tflops": tflop / seconds}
    # The run whose rate with evaluations the row gives: its iterations, and its evaluations' seconds beside them.
    full_run = row["full_run_hours"] * 3600
    run_steps = row["steps_per_s_with_evals"] * full_run
    iterations = run_steps / steps
    evaluations = full_run - iterations * iteration
    bound = (run_steps / target - evaluations) / iterations
    rest = iteration * (1 - sum(row["shares"][p] for p in NETWORK_PHASES))
    network_tflop = sum(p["tflop"] for p in phases.values())
    needed = network_tflop / (bound - rest) if bound > rest else float("inf")
    return {"phases": phases, "iteration_bound_s": bound, "rest_s": rest, "network_tflop": network_tflop,
            "needed_tflops": needed}


def report(row: dict, work: Dict[str, object], target: float) -> List[str]:
    lines = [f"K = {row['K']}: {row['steps_per_s']:,.0f} steps/s, {row['steps_per_s_with_evals']:,.0f} with "
             f"evaluations, an iteration {row['iteration_s']:.3f} s",
             "| phase | s | TFLOP | TFLOP/s |", "|---|---:|---:|---:|"]
    for phase, p in work["phases"].items():
        lines.append(f"| {phase} | {p['s']:.3f} | {p['tflop']:.1f} | {p['tflops']:.0f} |")
    fastest = max(p["tflops"] for p in work["phases"].values())
    lines.append(f"{target:,.0f} steps/s with evaluations: an iteration of at most {work['iteration_bound_s']:.3f} s; "
                 f"with the other phases' {work['rest_s']:.3f} s, the network's {work['network_tflop']:.1f} TFLOP "
                 f"at {work['needed_tflops']:.0f} TFLOP/s on average ({work['needed_tflops'] / fastest:.2f} x the "
                 f"fastest phase now)")
    return lines


def main(argv: List[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("speed", nargs="+", help="`kage.bench speed --json` files (one row a line)")
    parser.add_argument("--target", type=float, default=500_000, help="steps/s with evaluations (default 500 k)")
    options = parser.parse_args(argv)
    args = Args()  # the spec's update epochs, which kage.bench speed keeps
    forward, backward = network_flops()
    print(f"network: {forward / 1e6:.2f} MFLOP a frame forward, {backward / 1e6:.2f} backward")
    for path in options.speed:
        with open(path) as f:
            for number, line in enumerate(f, 1):
                try:
                    row = json.loads(line)
                    work = phase_work(row, args, options.target, forward, backward)
                except (ValueError, KeyError) as error:
                    sys.exit(f"phase_flops: {path}:{number}: not a `kage.bench speed --json` row ({error})")
                print(f"\n{path}:{number}")
                print("\n".join(report(row, work, options.target)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
