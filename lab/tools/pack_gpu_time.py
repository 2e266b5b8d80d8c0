"""The GPU time of an unpacked benchmark directory, from its runs' own metrics: per pack (DIR/packs/task_I_pack_J.json,
the runs one trainer process trained side by side on one GPU), the training seconds of its first run (the last
iteration's global_step over its charts/SPS, which is the run's steps over its training time so far, resumes
included) and its evaluation points' seconds (each point evaluates the whole pack at once, so every run of the pack
logs the same seconds). Neither the start of a pack (kernels compiled, batches opened) nor its checkpoints count.
The devices are those the packs' checksum lists name (`# device:` lines)."""
import glob
import json
import os
from typing import List

RUNS = "runs"


def pack_seconds(root: str, pack_file: str) -> tuple:
    """(training s, evaluation s) of one pack, from its first run's metrics.jsonl under `root`."""
    with open(pack_file) as f:
        first = json.load(f)["runs"][0]["out"]
    # The pack file names the run by the path it trained in on the device: its runs/... tail is the same here.
    run = os.path.join(root, first[first.rindex(os.sep + RUNS + os.sep) + 1:])
    train, evals = None, 0.0
    with open(os.path.join(run, "metrics.jsonl")) as f:
        for line in f:
            row = json.loads(line)
            if row["kind"] == "train":
                train = row
            elif row["kind"] == "eval":
                evals += row["seconds"]
    if train is None:
        raise ValueError(f"{run}/metrics.jsonl has no training row")
    return train["global_step"] / train["charts/SPS"], evals


def gpu_time(root: str) -> dict:
    """{packs, train_hours, eval_hours} of the benchmark directory `root`."""
    packs = sorted(glob.glob(os.path.join(root, "packs", "task_*_pack_*.json")))
    seconds = [pack_seconds(root, p) for p in packs]
    return {"packs": len(packs), "train_hours": sum(s[0] for s in seconds) / 3600,
            "eval_hours": sum(s[1] for s in seconds) / 3600}


def devices(packs: str) -> List[str]:
    """The devices named by the checksum lists in the folder of packs, each once, sorted."""
    named = set()
    for path in glob.glob(os.path.join(packs, "task_*.sha256")):
        with open(path) as f:
            named.update(line[len("# device:"):].strip() for line in f if line.startswith("# device:"))
    return sorted(named)
