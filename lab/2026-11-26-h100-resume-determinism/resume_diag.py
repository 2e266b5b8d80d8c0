"""How far apart two uninterrupted CUDA runs of tests/gpu/test_resume_gpu.py's flags end, and a run stopped
after iteration 2 and resumed, per parameter: under the trainer's default (cuDNN autotuned) algorithms, then
under deterministic ones. Run from the repository root on a GPU machine after lab/tools/device_build.sh:
    python3 lab/2026-11-26-h100-resume-determinism/resume_diag.py"""
import pathlib
import sys
import tempfile
import time

sys.path[:0] = ["tests/gpu", "tests/python"]
import torch  # noqa: E402

import test_resume_gpu  # noqa: E402
from kage.ppo import checkpoint  # noqa: E402


def parameters(run_dir):
    return checkpoint.load(run_dir / "checkpoints/latest.pt")["agent"]


def report(label, a, b):
    """Each parameter's largest difference, and how many elements the test's old bound (rtol 1e-3, atol 1e-4)
    would refuse."""
    parts = []
    for name, p in a.items():
        refused = ~torch.isclose(b[name], p, rtol=1e-3, atol=1e-4)
        parts.append(f"{name}: max {(b[name] - p).abs().max().item():.3g} bad {int(refused.sum())}/{p.numel()}")
    print(label, "|", "; ".join(parts), flush=True)


for mode in ("default", "deterministic"):
    if mode == "deterministic":
        torch.backends.cudnn.deterministic = True
        torch.use_deterministic_algorithms(True, warn_only=True)
    root = pathlib.Path(tempfile.mkdtemp())
    start = time.time()
    test_resume_gpu.run(root / "w1")
    test_resume_gpu.run(root / "w2")
    test_resume_gpu.run(root / "r", stop_after=2)
    test_resume_gpu.run(root / "r")
    w1, w2, r = parameters(root / "w1"), parameters(root / "w2"), parameters(root / "r")
    report(f"{mode} whole vs whole", w1, w2)
    report(f"{mode} whole vs resumed", w1, r)
    print(mode, f"{time.time() - start:.0f} s", flush=True)
