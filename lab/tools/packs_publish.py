"""Publishes the task packs that a device call brought home (lab/tools/pack_task.py: FROM/task_I.tar.gz and
FROM/task_I.sha256, and the tasks bundled in FROM/more_tasks.tar) into a packs folder of results/: each archive's
checksum checked against its list, the lease's note added to the list after its `# date:` line (`# note: NOTE`:
the calls as typed, the device kind, the times; lab/<record>/data/README.md has the whole story), both files
written read-write for all, read-only for none (the device's copies come home read-only). A task already
published is left alone if it is the same archive and refused if it is another: a pack is replaced only by
removing it first, on purpose.

usage: python3 lab/tools/packs_publish.py FROM DEST --note NOTE"""
import argparse
import os
import re
import sys
import tarfile
import tempfile

from pack_task import BUNDLE, sha256  # the packs' one definition, beside this file
from table_unpack import read_sums

TASK_FILE = re.compile(r"^task_(\d+)\.(tar\.gz|sha256)$")


def listed_checksum(listing_path: str, archive_name: str) -> str:
    """The checksum that the list gives the archive itself, on its first line after the `#` lines."""
    sums = read_sums(listing_path)
    if not sums or sums[0][2] != archive_name:
        sys.exit(f"packs_publish: {listing_path}: its first checksum is not {archive_name}'s: not a list that "
                 "pack_task.py wrote")
    return sums[0][1]


def with_note(listing: str, note: str, where: str) -> str:
    """The list with `# note: NOTE` after its `# date:` line."""
    lines = listing.splitlines(keepends=True)
    if any(line.startswith("# note:") for line in lines):
        sys.exit(f"packs_publish: {where}: already has a '# note:' line; publish the list the device wrote")
    dates = [i for i, line in enumerate(lines) if line.startswith("# date:")]
    if len(dates) != 1:
        sys.exit(f"packs_publish: {where}: {len(dates)} '# date:' lines, expected 1: not a list that pack_task.py "
                 "wrote")
    lines.insert(dates[0] + 1, f"# note: {note}\n")
    return "".join(lines)


def write_public(path: str, data: bytes) -> None:
    """`data` at `path`, mode 0644, replaced whole (a temporary file renamed)."""
    part = path + ".part"
    with open(part, "wb") as f:
        f.write(data)
    os.chmod(part, 0o644)
    os.replace(part, path)


def publish_task(source: str, task: int, dest: str, note: str) -> str:
    """Publishes task `task` of folder `source` into `dest`; what was done, in words."""
    archive, listing_path = (os.path.join(source, f"task_{task}.{ext}") for ext in ("tar.gz", "sha256"))
    if not os.path.exists(listing_path):
        sys.exit(f"packs_publish: {archive} came without its list, {listing_path}: copy both from the call's files")
    wanted = listed_checksum(listing_path, f"task_{task}.tar.gz")
    with open(listing_path) as f:
        listing = f.read()
    found = sha256(archive)
    if found != wanted:
        sys.exit(f"packs_publish: {archive}: sha256 {found}, its list says {wanted}: the archive is damaged or "
                 "not the one listed; bring it home again")
    published = os.path.join(dest, f"task_{task}.tar.gz")
    if os.path.exists(published):
        if sha256(published) == found:
            return f"task {task}: already published, the same archive"
        sys.exit(f"packs_publish: {published} is another archive of task {task}: remove it (and its .sha256) first "
                 "if this one is to replace it")
    with open(archive, "rb") as f:
        data = f.read()
    write_public(os.path.join(dest, f"task_{task}.sha256"), with_note(listing, note, listing_path).encode())
    write_public(published, data)  # last: a list without its archive is what a killed publish leaves
    return f"task {task}: published in {dest}"


def tasks_in(folder: str) -> list:
    tasks = {int(m.group(1)) for m in map(TASK_FILE.match, os.listdir(folder)) if m and m.group(2) == "tar.gz"}
    return sorted(tasks)


def publish(source: str, dest: str, note: str) -> list:
    """Publishes every task of `source`, those of its more_tasks.tar included; what was done, a line a task."""
    if not os.path.isdir(source):
        sys.exit(f"packs_publish: {source}: no such folder: give the folder of a call's files")
    os.makedirs(dest, exist_ok=True)
    done = [publish_task(source, task, dest, note) for task in tasks_in(source)]
    bundle = os.path.join(source, BUNDLE)
    if os.path.exists(bundle):
        with tempfile.TemporaryDirectory() as staging, tarfile.open(bundle) as tar:
            members = tar.getmembers()
            strays = [m.name for m in members if not (m.isfile() and TASK_FILE.match(m.name))]
            if strays:
                sys.exit(f"packs_publish: {bundle} holds {', '.join(strays[:3])}: pack_task.py bundles task files "
                         "only")
            tar.extractall(staging, members=members, filter="data")
            done += [publish_task(staging, task, dest, note) for task in tasks_in(staging)]
    if not done:
        sys.exit(f"packs_publish: {source} has no task_I.tar.gz and no {BUNDLE}: nothing to publish")
    return done


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python3 lab/tools/packs_publish.py",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("source", metavar="FROM", help="the folder of a call's files (task_I.*, more_tasks.tar)")
    parser.add_argument("dest", metavar="DEST", help="the packs folder, e.g. results/methods/METHOD/packs")
    parser.add_argument("--note", required=True, help="the lease's note: calls as typed, device kind, times")
    args = parser.parse_args(argv)
    if not args.note.strip() or "\n" in args.note:
        parser.error("--note: one line of text")
    for line in publish(args.source, args.dest, args.note.strip()):
        print(f"packs_publish: {line}")


if __name__ == "__main__":
    main()
