"""The update's network work alone (forward, loss, backward, Adam) for K packed agents on random frames,
per variant of the speed flags: milliseconds per minibatch, the update-only steps/s it allows, and the
top CUDA kernels of the first variant. Picks the flags before a full `kage.bench speed` run.

usage: python3 lab/tools/profile_update.py [--packs 16] [--minibatch 2048] [--profile]
"""
import argparse

import torch

from cuda_timing import median_ms
from kage.ppo.agent import Agent

VARIANTS = [  # (bf16, channels_last, fused_input, triton_conv)
    (False, False, False, False), (False, False, True, False), (True, False, True, False), (True, True, False, False),
    (True, True, True, False), (True, False, True, True)]


def minibatch_ms(k: int, minibatch: int, bf16: bool, channels_last: bool, fused: bool, triton_conv: bool,
                 profile: bool) -> float:
    agent = Agent(list(range(k)), device="cuda", bf16=bf16, channels_last=channels_last, fused_input=fused,
                  triton_conv=triton_conv)
    optimizer = torch.optim.Adam(agent.parameters(), lr=5e-4, eps=1e-5)
    obs = torch.randint(0, 256, (k, minibatch, 128, 128, 3), dtype=torch.uint8, device="cuda")

    def step():
        with torch.autocast("cuda", dtype=torch.bfloat16, enabled=bf16):
            logits, value = agent(obs)
        loss = logits.float().logsumexp(-1).mean() + value.float().pow(2).mean()
        optimizer.zero_grad()
        loss.backward()
        optimizer.step()

    ms = median_ms(step)
    if profile:
        from torch.profiler import ProfilerActivity
        with torch.profiler.profile(activities=[ProfilerActivity.CUDA]) as prof:
            step()
            torch.cuda.synchronize()
        print(prof.key_averages().table(sort_by="cuda_time_total", row_limit=12, max_name_column_width=70))
    return ms


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--packs", type=int, default=16)
    p.add_argument("--minibatch", type=int, default=2048)
    p.add_argument("--profile", action="store_true")
    a = p.parse_args()
    torch.backends.cudnn.benchmark = True
    torch.set_float32_matmul_precision("high")
    print(f"{torch.cuda.get_device_name()}, torch {torch.__version__}, K = {a.packs}, minibatch {a.minibatch}")
    print("| bf16 | channels last | fused input | triton conv | ms per minibatch | update-only steps/s |")
    print("|---|---|---|---|---|---|")
    for i, (bf16, cl, fused, tri) in enumerate(VARIANTS):
        ms = minibatch_ms(a.packs, a.minibatch, bf16, cl, fused, tri, a.profile and i in (0, len(VARIANTS) - 1))
        torch.cuda.empty_cache()
        # An iteration is 24 minibatches of 2,048 per run: steps/s = K * 16,384 / (24 * ms).
        print(f"| {bf16} | {cl} | {fused} | {tri} | {ms:.1f} | {a.packs * 16384 / (24 * ms / 1e3):,.0f} |", flush=True)


if __name__ == "__main__":
    main()
