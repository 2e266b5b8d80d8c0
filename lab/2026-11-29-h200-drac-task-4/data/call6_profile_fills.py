import runpy, sys, torch
from torch.profiler import profile, ProfilerActivity
sys.argv = ["kage.bench", "speed", "--packs", "5", "--warmup", "1", "--iterations", "1", "--device", "cuda", "--bf16", "--fused-input", "--triton-conv", "--augment", "kage.ppo.augment:color_jitter", "--augment-mode", "drac"]
with profile(activities=[ProfilerActivity.CPU, ProfilerActivity.CUDA], record_shapes=True, with_stack=True) as p:
    try: runpy.run_module("kage.bench", run_name="__main__")
    except SystemExit: pass
ev = [e for e in p.key_averages(group_by_input_shape=True, group_by_stack_n=6) if e.key in ("aten::fill_", "aten::zero_", "aten::zeros", "aten::full", "aten::zeros_like", "aten::new_zeros")]
ev.sort(key=lambda e: -e.device_time_total)
for e in ev[:12]:
    print(e.key, e.count, round(e.device_time_total/1e3, 1), "ms", e.input_shapes)
    print("   ", "\n    ".join(e.stack[:6]))
