"""kage.compile_kernels on a GPU: configs compiled side by side into an empty kernel cache (a config named twice,
once), taken from it on the next call, and the batches opened afterwards step as those of a process that compiled
nothing ahead (the same observations, byte for byte)."""
import json
import os
import subprocess
import sys

from support import ROOT

BENCH = ROOT / "configs/kage_bench"
CONFIGS = [str(BENCH / "bases/image_skeleton.yaml"), str(BENCH / "filters/5-eval.yaml"),
           str(BENCH / "effects/1-eval.yaml")]

# A child process per cache, so that KAGE_CACHE_DIR is read afresh: compile ahead (or not), then open and step.
CHILD = """
import hashlib, json, sys
import numpy as np, torch
import kage
configs, ahead = json.loads(sys.argv[1]), sys.argv[2] == "ahead"
report = [kage.compile_kernels(configs + configs[:1]), kage.compile_kernels(configs)] if ahead else []
digests = []
for config in configs:
    with kage.make_vec(config, 16, device="cuda", seed=3) as env:
        env.reset()
        for step in range(40):
            env.step(np.full(16, step % 8, dtype=np.int32))
        frames = torch.from_dlpack(env.outputs()[0]).cpu().numpy()
        digests.append(hashlib.sha256(frames.tobytes()).hexdigest())
print(json.dumps({"report": report, "digests": digests}))
"""


def child(cache, mode: str) -> dict:
    env = dict(os.environ, KAGE_CACHE_DIR=str(cache))
    out = subprocess.run([sys.executable, "-c", CHILD, json.dumps(CONFIGS), mode], env=env, capture_output=True,
                         text=True, timeout=900)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.splitlines()[-1])


def test_compiled_ahead_side_by_side_then_cached_and_the_same_batches(tmp_path):
    ahead = child(tmp_path / "ahead", "ahead")
    assert ahead["report"] == [{"compiled": 3, "cached": 0}, {"compiled": 0, "cached": 3}]
    opened = child(tmp_path / "opened", "opened")
    assert len(set(ahead["digests"])) == 3  # three configs, three different frames
    assert ahead["digests"] == opened["digests"]
