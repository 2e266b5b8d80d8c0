import runpy, sys, torch
from torch.profiler import profile, ProfilerActivity
sys.argv = ["kage.bench", "speed", "--packs", "5", "--warmup", "2", "--iterations", "2", "--device", "cuda", "--bf16", "--fused-input", "--triton-conv", "--augment", "kage.ppo.augment:color_jitter", "--augment-mode", "drac"]
with profile(activities=[ProfilerActivity.CUDA]) as p:
    try: runpy.run_module("kage.bench", run_name="__main__")
    except SystemExit: pass
print(p.key_averages().table(sort_by="cuda_time_total", row_limit=40, max_name_column_width=90))
