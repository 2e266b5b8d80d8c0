"""The GPU time of an unpacked benchmark directory, from its runs' own metrics: per pack (DIR/packs/task_I_pack_J.json,
or task_I+K_pack_J.json of tasks trained as one: the runs one trainer process trained side by side on one GPU), the
training seconds of its first run (the last iteration's global_step over its charts/SPS, which is the run's steps
over its training time so far, resumes included) and its evaluation points' seconds (each point evaluates the whole
pack at once, so every run of the pack logs the same seconds). The start of a pack (kernels compiled, batches
opened) does not count. Packs trained before 2086d34 count the host's time of each iteration only, not the device's
unfinished work, the logging or the checkpoints (lab/2026-11-29-h200-train-clock); so each pack's wall time is
given too: from its first run's run.json (written once the pack has opened) to its summary.json, as the files' times
say (the packs' archives keep them), so that a pack resumed by a later process counts the time between. The devices
are those the packs' checksum lists name (`# device:` lines)."""
import glob
import json
import os
from typing import List

RUNS = "runs"


def pack_seconds(root: str, pack_file: str) -> tuple:
    """(training s, evaluation s, wall s) of one pack, from its first run's files under `root`."""
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
    wall = os.path.getmtime(os.path.join(run, "summary.json")) - os.path.getmtime(os.path.join(run, "run.json"))
    return train["global_step"] / train["charts/SPS"], evals, wall


def gpu_time(root: str) -> dict:
    """{packs, train_hours, eval_hours, wall_hours} of the benchmark directory `root`."""
    packs = sorted(glob.glob(os.path.join(root, "packs", "task_*_pack_*.json")))
    seconds = [pack_seconds(root, p) for p in packs]
    return {"packs": len(packs), "train_hours": sum(s[0] for s in seconds) / 3600,
            "eval_hours": sum(s[1] for s in seconds) / 3600, "wall_hours": sum(s[2] for s in seconds) / 3600}


def devices(packs: str) -> List[str]:
    """The devices named by the checksum lists in the folder of packs, each once, sorted."""
    named = set()
    for path in glob.glob(os.path.join(packs, "task_*.sha256")):
        with open(path) as f:
            named.update(line[len("# device:"):].strip() for line in f if line.startswith("# device:"))
    return sorted(named)
