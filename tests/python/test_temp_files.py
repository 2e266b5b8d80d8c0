"""Files replaced whole are written beside their target under a name nobody can predict, created exclusively
(a planted symlink is never followed), removed when the write fails (a full disk keeps no stray), and the
strays of writers that died are removed when a run or benchmark directory is opened again."""
import errno
import os
import socket

import pytest

from kage.ppo import train
from kage.util import files
from support import NOISY_SKELETON, dead_pid

FLAGS = ["--train-config-path", NOISY_SKELETON, "--seed", "2", "--device", "cpu", "--threads", "1",
         "--total-timesteps", "32", "--num-envs", "2", "--num-steps", "16", "--num-minibatches", "2",
         "--update-epochs", "1", "--run-eval-every", "0"]


def test_a_planted_symlink_at_the_predictable_name_is_not_followed(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    target = tmp_path / "run.json"
    for name in (f"run.json.tmp.{socket.gethostname()}.{os.getpid()}", "run.json.tmp"):
        (tmp_path / name).symlink_to(victim)
    files.atomic_write(str(target), b"{}\n")
    assert victim.read_text() == "precious"
    assert target.read_bytes() == b"{}\n" and not target.is_symlink()


def test_two_writes_in_one_process_use_different_names(tmp_path, monkeypatch):
    names = []
    replace = os.replace

    def noting(src, dst):
        names.append(os.path.basename(src))
        replace(src, dst)

    monkeypatch.setattr(os, "replace", noting)
    files.atomic_write(str(tmp_path / "a"), b"1")
    files.atomic_write(str(tmp_path / "a"), b"2")
    assert len(set(names)) == 2 and all(n.startswith("a.tmp.") for n in names)


@pytest.mark.parametrize("error", [errno.ENOSPC, errno.EROFS, errno.EIO])
def test_a_failed_write_leaves_no_stray(tmp_path, monkeypatch, error):
    def failing(fd):
        raise OSError(error, os.strerror(error))

    monkeypatch.setattr(os, "fsync", failing)
    (tmp_path / "summary.json").write_text("old")
    with pytest.raises(OSError):
        files.atomic_write(str(tmp_path / "summary.json"), b"x" * 100000)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]
    assert (tmp_path / "summary.json").read_text() == "old"


def test_a_dead_writers_strays_are_removed_when_the_run_starts_again(tmp_path):
    out = tmp_path / "run"
    (out / "checkpoints").mkdir(parents=True)
    host = socket.gethostname()
    strays = [out / f"metrics.jsonl.tmp.{host}.{dead_pid()}", out / "checkpoints" / f"latest.pt.tmp.{host}.{dead_pid()}.ab12cd",
              out / "checkpoints" / f"latest.json.tmp.{host}.{dead_pid()}"]
    for stray in strays:
        stray.write_bytes(b"\0" * 4096)
    live = out / f"bench_state.json.tmp.{host}.{os.getpid()}.ff00ff"  # a live writer's (this process)
    live.write_bytes(b"{}")
    assert train.main(FLAGS + ["--out", str(out)]) == 0
    assert not any(stray.exists() for stray in strays)
    assert live.exists()


def test_another_hosts_strays_are_removed_once_old(tmp_path):
    old = tmp_path / "run.json.tmp.elsewhere.4242.0a0a0a"
    young = tmp_path / "summary.json.tmp.elsewhere.4243.0b0b0b"
    for stray in (old, young):
        stray.write_bytes(b"x")
    os.utime(old, (1, 1))
    files.remove_strays(str(tmp_path))
    assert not old.exists() and young.exists()
