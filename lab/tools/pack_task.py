"""Packs one finished task of a benchmark directory for the trip home from a device machine: the task's run
folders (metrics, summaries, configs, certificates, logs; neither checkpoints nor the TensorBoard events, which
hold the same values as metrics.jsonl at twice its size: the whole table must travel to a device) with the
directory's bench.json, suite.json, tasks.json and the task's pack logs, as DEST/task_I.tar.gz (paths relative
to DIR, so the archives of all tasks unpack into one benchmark directory), and DEST/task_I.sha256: `#` lines of
provenance ($KAGE_PACK_PROVENANCE and the date), the archive's checksum, then each packed file's. Refuses,
naming the runs, while any run of the task has no summary.json.
TASK `new` packs every finished task that this DIR has not packed before (DIR/packed/task_I marks it), for a
runner of all tasks (`kage.bench run --gpus`) whose tasks finish while it runs: finished there means that the
runner has also marked each run done (bench_state.json), since until its trainer exits it rewrites that file
every 30 s, and a file rewritten between the archive and its checksum would not match on unpacking. With
MAX_FILES (the device machine's limit on the files a call brings back), `new` packs a task as its two files
while they fit, then the rest into one file, DEST/more_tasks.tar (each task's two files, which
lab/tools/packs_publish.py publishes at home), since the call that finds the runner ended may be the lease's last; only when not even
that fits does it name the finished tasks it left for the next call and exit with status 3
(LEFT_FOR_NEXT_CALL), so that the call can end at once and the next bring them home before the lease ends.

usage: python3 lab/tools/pack_task.py DIR TASK|new DEST [MAX_FILES]"""
import hashlib
import json
import os
import re
import shutil
import sys
import tarfile
import tempfile
import time

PROVENANCE = "KAGE_PACK_PROVENANCE"
TOP = ("bench.json", "suite.json", "tasks.json")
LEFT_OUT = ("checkpoints", "tensorboard")
LEFT_FOR_NEXT_CALL = 3
BUNDLE = "more_tasks.tar"
PACK_FILE = re.compile(r"^task_(\d+(?:\+\d+)*)_pack_\d+\.(?:json|log)$")


def sha256(path: str) -> str:
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def trained(root: str, files: list) -> tuple:
    """When the task's training began and ended, from its runs' own files: a run writes run.json as it starts
    (never again: a resumed run checks it) and summary.json as it ends."""
    def times(name: str) -> list:
        return [os.path.getmtime(os.path.join(root, n)) for n in files if n.endswith("/" + name)]
    return min(times("run.json")), max(times("summary.json"))


def provenance(root: str, files: list) -> str:
    """The checksum list's `#` lines: $KAGE_PACK_PROVENANCE's (device, commit, command; table_device.sh sets
    it), the dates of training and of packing."""
    lines = [line for line in os.environ.get(PROVENANCE, "").splitlines() if line.strip()]
    began, ended = trained(root, files)
    day, clock = "%Y-%m-%d %H:%M", "%H:%M"
    lines.append(f"date: {time.strftime(day, time.gmtime(began))}-{time.strftime(clock, time.gmtime(ended))} "
                 f"UTC (trained), {time.strftime(clock, time.gmtime())} UTC (packed)")
    return "".join(f"# {line}\n" for line in lines)


def task_table(root: str) -> list:
    with open(os.path.join(root, "tasks.json")) as f:
        return json.load(f)["tasks"]


def task_runs(table: list, task: int) -> list:
    return [os.path.join("runs", job["unit"], f"seed_{job['seed']}") for job in table[task]]


def unfinished_runs(root: str, runs: list) -> list:
    return [r for r in runs if not os.path.exists(os.path.join(root, r, "summary.json"))]


def marked_done(root: str, runs: list) -> bool:
    for run in runs:
        try:
            with open(os.path.join(root, run, "bench_state.json")) as f:
                if json.load(f)["state"] != "done":
                    return False
        except (OSError, ValueError, KeyError):  # absent, or being rewritten
            return False
    return True


def packed_tasks(pack_file: str) -> list:
    """The tasks whose runs a pack file of DIR/packs holds: task_3_pack_0.log -> [3], and task_3+4_pack_0.log,
    of tasks trained as one (kage.bench run --task 3+4), -> [3, 4], which both archives carry."""
    match = PACK_FILE.match(pack_file)
    return [int(task) for task in match.group(1).split("+")] if match else []


def task_files(root: str, task: int) -> list:
    """The files to pack, relative to root; exits naming the unfinished runs if any."""
    table = task_table(root)
    if not 0 <= task < len(table):
        sys.exit(f"pack_task: {root}/tasks.json has tasks 0 to {len(table) - 1}, not {task}")
    runs = task_runs(table, task)
    unfinished = unfinished_runs(root, runs)
    if unfinished:
        sys.exit(f"pack_task: task {task} is not finished: no summary.json in {', '.join(unfinished)}")
    files = [name for name in TOP if os.path.exists(os.path.join(root, name))]
    packs = os.path.join(root, "packs")
    if os.path.isdir(packs):
        files += [os.path.join("packs", n) for n in sorted(os.listdir(packs)) if task in packed_tasks(n)]
    for run in runs:
        for folder, dirs, names in os.walk(os.path.join(root, run)):
            dirs[:] = sorted(d for d in dirs if d not in LEFT_OUT)
            files += [os.path.relpath(os.path.join(folder, n), root) for n in sorted(names)]
    return files


def pack(root: str, task: int, dest: str) -> None:
    files = task_files(root, task)
    os.makedirs(dest, exist_ok=True)
    archive = os.path.join(dest, f"task_{task}.tar.gz")
    with tarfile.open(archive + ".part", "w:gz") as tar:
        for name in files:
            tar.add(os.path.join(root, name), arcname=name)
    with open(os.path.join(dest, f"task_{task}.sha256"), "w") as f:
        f.write(provenance(root, files))
        f.write(f"{sha256(archive + '.part')}  task_{task}.tar.gz\n")
        f.writelines(f"{sha256(os.path.join(root, n))}  {n}\n" for n in files)
    os.replace(archive + ".part", archive)  # last: a killed call leaves no archive that looks whole
    print(f"pack_task: task {task}: {len(files)} files, {os.path.getsize(archive) / 1e6:.1f} MB in {archive}")


def bundle(root: str, task: int, dest: str) -> None:
    """Packs the task into DEST/more_tasks.tar beside the tasks already there, replacing it whole, so that a
    killed call leaves the previous bundle intact."""
    path = os.path.join(dest, BUNDLE)
    with tempfile.TemporaryDirectory() as staging:
        pack(root, task, staging)
        if os.path.exists(path):
            shutil.copyfile(path, path + ".part")
        with tarfile.open(path + ".part", "a") as tar:
            for name in (f"task_{task}.tar.gz", f"task_{task}.sha256"):
                tar.add(os.path.join(staging, name), arcname=name)
    os.replace(path + ".part", path)
    print(f"pack_task: task {task} bundled in {path}")


def pack_new(root: str, dest: str, max_files: int) -> list:
    """Packs the tasks newly finished; returns those finished but left for the next call."""
    if not os.path.exists(os.path.join(root, "tasks.json")):
        return []  # the runner has not written its task table yet
    table = task_table(root)
    marks = os.path.join(root, "packed")
    os.makedirs(marks, exist_ok=True)
    left = []
    for task in range(len(table)):
        mark = os.path.join(marks, f"task_{task}")
        runs = task_runs(table, task)
        if os.path.exists(mark) or unfinished_runs(root, runs) or not marked_done(root, runs):
            continue
        used = len(os.listdir(dest)) if os.path.isdir(dest) else 0
        if used + 2 <= max_files:
            pack(root, task, dest)
        elif used + 1 <= max_files or os.path.exists(os.path.join(dest, BUNDLE)):
            bundle(root, task, dest)
        else:
            left.append(str(task))
            continue
        open(mark, "w").close()
    if left:
        print(f"pack_task: task(s) {', '.join(left)} finished but not packed: {dest} would pass the {max_files} "
              "files a call brings back; call again in this lease to bring them")
    return left


def main() -> None:
    if len(sys.argv) not in (4, 5):
        sys.exit(__doc__.splitlines()[-1])
    root, task, dest = sys.argv[1:4]
    if task == "new":
        if pack_new(root, dest, int(sys.argv[4]) if len(sys.argv) == 5 else sys.maxsize):
            sys.exit(LEFT_FOR_NEXT_CALL)
    else:
        pack(root, int(task), dest)


if __name__ == "__main__":
    main()
