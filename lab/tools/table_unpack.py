"""Unpacks the packed tasks of the whole KAGE-Bench table (results/kage-bench-table/packs, written by
lab/tools/pack_task.py) into one benchmark directory for `kage.bench report` and `kage.bench compare`. Each
archive's checksum is checked before it is opened, and each unpacked file's after; a mismatch stops with the
file's name. A checksum list's `#` lines (its provenance) are skipped, as `sha256sum -c` skips them. The archives
must come from one benchmark (one `kage.bench run` layout: pairs, seeds, --pack, trainer flags): an archive whose
files would replace different ones already unpacked stops with both names, since report and compare read the
benchmark's runs from its bench.json and would silently lose those of the other layout.

usage: python3 lab/tools/table_unpack.py PACKS DIR"""
import json
import os
import re
import sys
import tarfile

from pack_task import sha256  # the checksums' one definition, beside this file


def read_sums(path: str) -> list:
    """[(line number, digest, name)], the archive's first."""
    sums = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            if line.startswith("#"):
                continue
            digest, sep, name = line.rstrip("\n").partition("  ")
            if not sep or len(digest) != 64:
                sys.exit(f"table_unpack: {path}:{number}: not a sha256sum line (DIGEST  NAME)")
            sums.append((number, digest, name))
    return sums


# Where the benchmark's files may differ between archives of one benchmark: the path each runner was started with.
SAME_BUT = {"bench.json": lambda d: {k: v for k, v in d.items() if k != "suite"},
            "suite.json": lambda d: [(p["pair"], p["train"]["spec_sha256"], p["eval"]["spec_sha256"])
                                     for p in d.get("pairs", [])]}


def check_no_replacement(tar: tarfile.TarFile, archive: str, dest: str) -> None:
    """Stops where a file of `archive` would replace a different one that an archive unpacked before left in `dest`."""
    for member in tar.getmembers():
        path = os.path.join(dest, member.name)
        if not member.isfile() or not os.path.exists(path):
            continue
        data = tar.extractfile(member).read()
        with open(path, "rb") as f:
            before = f.read()
        if member.name in SAME_BUT:
            same = SAME_BUT[member.name](json.loads(data)) == SAME_BUT[member.name](json.loads(before))
        else:
            same = data == before
        if not same:
            sys.exit(f"table_unpack: {archive}: its {member.name} differs from {path}, unpacked before it: the "
                     "archives come from different benchmarks (another --pairs, --seeds, --pack or trainer flags); "
                     "unpack each benchmark's archives into a folder of its own")


def unpack(packs: str, archive_name: str, dest: str) -> int:
    archive = os.path.join(packs, archive_name)
    sums_path = archive[:-len(".tar.gz")] + ".sha256"
    if not os.path.exists(sums_path):
        sys.exit(f"table_unpack: {archive} has no checksum list {sums_path}: bring it with the archive")
    (number, archive_sum, listed), *files = read_sums(sums_path)
    if listed != archive_name or sha256(archive) != archive_sum:
        sys.exit(f"table_unpack: {archive}: its sha256 is not the one in {sums_path}:{number}; the archive is "
                 "damaged")
    with tarfile.open(archive) as tar:
        check_no_replacement(tar, archive, dest)
        tar.extractall(dest, filter="data")
    for number, digest, name in files:
        if sha256(os.path.join(dest, name)) != digest:
            sys.exit(f"table_unpack: {os.path.join(dest, name)}: not the file of {sums_path}:{number}; the archive "
                     "and its checksum list disagree: bring both again")
    return len(files)


TASK_ARCHIVE = re.compile(r"task_(\d+)\.tar\.gz")  # pack_task.py's name for task I's archive


def unpack_all(packs: str, dest: str, say=print) -> int:
    """Unpacks every task_I.tar.gz of `packs` into `dest`, in task order, each checked; the number of tasks."""
    if not os.path.isdir(packs):
        sys.exit(f"table_unpack: {packs}: not a directory: give the packs folder (results/.../packs)")
    names = [n for n in os.listdir(packs) if n.endswith(".tar.gz")]
    for name in names:
        if not TASK_ARCHIVE.fullmatch(name):
            sys.exit(f"table_unpack: {os.path.join(packs, name)}: not a task archive (task_I.tar.gz, as pack_task.py "
                     "names them): rename it to its task's name, with its checksum list, or move it out of the folder")
    names.sort(key=lambda n: int(TASK_ARCHIVE.fullmatch(n)[1]))
    if not names:
        sys.exit(f"table_unpack: {packs}: no task_I.tar.gz archives")
    os.makedirs(dest, exist_ok=True)
    for name in names:
        say(f"table_unpack: {name}: {unpack(packs, name, dest)} files checked")
    return len(names)


def main() -> None:
    if len(sys.argv) != 3:
        sys.exit(__doc__.splitlines()[-1])
    packs, dest = sys.argv[1:]
    tasks = unpack_all(packs, dest)
    print(f"table_unpack: {tasks} tasks in {dest}; then: python3 -m kage.bench report {dest}")


if __name__ == "__main__":
    main()
