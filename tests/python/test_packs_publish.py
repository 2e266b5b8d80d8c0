"""lab/tools/packs_publish.py publishes the task packs a device call brought home: checksums checked, the lease's
note added after the list's date, files readable by all, and a published pack never replaced by another."""
import hashlib
import io
import os
import stat
import subprocess
import sys
import tarfile

from support import ROOT

PUBLISH = ROOT / "lab/tools/packs_publish.py"
NOTE = "the lease, in full in lab/x: calls 1 and 2 ran `bash lab/tools/table_device.sh`"


def call_files(folder, task, content=b"metrics\n", bundled=False):
    """task_I.tar.gz and task_I.sha256 as pack_task.py writes them, read-only as a call's files come home (or
    bundled into more_tasks.tar)."""
    folder.mkdir(exist_ok=True)
    archive = io.BytesIO()
    with tarfile.open(fileobj=archive, mode="w:gz") as tar:
        member = tarfile.TarInfo("runs/a/seed_1/metrics.jsonl")
        member.size = len(content)
        tar.addfile(member, io.BytesIO(content))
    data = archive.getvalue()
    listing = (f"# device: 2 x NVIDIA H200 (driver 580.159.04)\n# commit: c2921fe\n"
               f"# date: 2026-11-29 22:26-22:41 UTC (trained), 22:41 UTC (packed)\n"
               f"{hashlib.sha256(data).hexdigest()}  task_{task}.tar.gz\n"
               f"{hashlib.sha256(content).hexdigest()}  runs/a/seed_1/metrics.jsonl\n").encode()
    files = {f"task_{task}.tar.gz": data, f"task_{task}.sha256": listing}
    if bundled:
        with tarfile.open(folder / "more_tasks.tar", "a") as tar:
            for name, body in files.items():
                member = tarfile.TarInfo(name)
                member.size = len(body)
                tar.addfile(member, io.BytesIO(body))
    else:
        for name, body in files.items():
            (folder / name).write_bytes(body)
            os.chmod(folder / name, 0o444)
    return data, listing.decode()


def publish(source, dest, note=NOTE):
    return subprocess.run([sys.executable, str(PUBLISH), str(source), str(dest), "--note", note],
                          capture_output=True, text=True)


def test_packs_are_published_with_the_note_after_the_date_and_readable_by_all(tmp_path):
    data_0, listing_0 = call_files(tmp_path / "call", 0)
    data_3, listing_3 = call_files(tmp_path / "call", 3, b"other\n", bundled=True)
    dest = tmp_path / "results/methods/m/packs"
    done = publish(tmp_path / "call", dest)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [f"packs_publish: task 0: published in {dest}",
                                        f"packs_publish: task 3: published in {dest}"]
    for task, data, listing in ((0, data_0, listing_0), (3, data_3, listing_3)):
        assert (dest / f"task_{task}.tar.gz").read_bytes() == data
        lines = listing.splitlines(keepends=True)
        assert (dest / f"task_{task}.sha256").read_text() == "".join(lines[:3] + [f"# note: {NOTE}\n"] + lines[3:])
        for name in (f"task_{task}.tar.gz", f"task_{task}.sha256"):
            assert stat.S_IMODE(os.stat(dest / name).st_mode) == 0o644

    again = publish(tmp_path / "call", dest)
    assert again.returncode == 0, again.stderr
    assert "task 0: already published, the same archive" in again.stdout


def test_a_damaged_archive_and_another_archive_of_a_published_task_are_refused(tmp_path):
    call_files(tmp_path / "call", 0)
    archive = tmp_path / "call/task_0.tar.gz"
    os.chmod(archive, 0o644)
    archive.write_bytes(archive.read_bytes()[:-3])
    dest = tmp_path / "packs"
    damaged = publish(tmp_path / "call", dest)
    assert damaged.returncode != 0
    assert f"{archive}: sha256" in damaged.stderr and "bring it home again" in damaged.stderr
    assert not (dest / "task_0.tar.gz").exists() and not (dest / "task_0.sha256").exists()

    call_files(tmp_path / "first", 0)
    assert publish(tmp_path / "first", dest).returncode == 0
    call_files(tmp_path / "second", 0, b"retrained\n")
    other = publish(tmp_path / "second", dest)
    assert other.returncode != 0
    assert f"{dest}/task_0.tar.gz is another archive of task 0: remove it" in other.stderr


def test_bad_input_is_named(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    nothing = publish(empty, tmp_path / "packs")
    assert nothing.returncode != 0 and "nothing to publish" in nothing.stderr
    two_lines = publish(empty, tmp_path / "packs", "a\nb")
    assert two_lines.returncode != 0 and "--note: one line of text" in two_lines.stderr
    call_files(tmp_path / "call", 1)
    (tmp_path / "call/task_1.sha256").unlink()
    alone = publish(tmp_path / "call", tmp_path / "packs")
    assert alone.returncode != 0 and "came without its list" in alone.stderr
