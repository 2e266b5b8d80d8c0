"""One writer per run and benchmark directory: a second kage.ppo.train or kage.bench run on a directory in use
refuses at once, naming the holder (host, process, start) and the way out; a dead holder is taken over (this
host: its process is gone; another host: its heartbeat is old), never waited on; of several processes
racing for a lock exactly one gets it; and a runner's death takes its trainers with it."""
import json
import multiprocessing
import os
import signal
import socket
import subprocess
import sys
import time

import pytest

from kage.util import lock
from support import NOISY_SKELETON, ROOT

SUITE = """suite: locks
pairs:
  - name: alone
    axis: background
    train: {config}
    eval: {config}
"""
# Thousands of 32-step iterations: a run that is still training when the test looks at it.
# kage.bench run sets the config and the seed of each run itself, so it gets TRAINING alone.
TRAINING = ["--device", "cpu", "--threads", "1", "--total-timesteps", "640000", "--num-envs", "2",
            "--num-steps", "16", "--num-minibatches", "2", "--update-epochs", "1", "--run-eval-every", "0", "--save-checkpoint-every", "2"]
LONG = ["--train-config-path", NOISY_SKELETON, "--seed", "1", *TRAINING]


def start(module, *args, **popen):
    return subprocess.Popen([sys.executable, "-m", module, *args], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, **popen)


def wait_for(predicate, what, timeout=120):
    deadline = time.time() + timeout
    while time.time() < deadline:
        if predicate():
            return
        time.sleep(0.1)
    pytest.fail(f"timed out waiting for {what}")


def train_rows(out):
    try:
        return [json.loads(line) for line in open(out / "metrics.jsonl") if '"kind": "train"' in line]
    except FileNotFoundError:
        return []


def stop(process) -> str:
    if process.poll() is None:
        process.kill()
    return process.communicate(timeout=60)[0]


def test_a_second_trainer_on_a_run_refuses_and_a_dead_ones_run_is_taken_over(tmp_path):
    out = tmp_path / "run"
    first = start("kage.ppo.train", *LONG, "--out", str(out))
    try:
        wait_for(lambda: (out / "checkpoints" / "latest.json").exists(), "the first trainer's checkpoint")
        began = time.time()
        second = start("kage.ppo.train", *LONG, "--out", str(out))
        text = second.communicate(timeout=120)[0]
        assert second.returncode != 0, text
        assert time.time() - began < 60, "refused at once, not after waiting"
        assert f"process {first.pid} on host {socket.gethostname()}" in text and "another --out" in text, text
        assert "Traceback" not in text, text
        iterations = [r["iteration"] for r in train_rows(out)]
        assert iterations == sorted(set(iterations)), "one writer: no row twice"
    finally:
        first.send_signal(signal.SIGKILL)
        first.wait()
    before = max(r["iteration"] for r in train_rows(out))
    third = start("kage.ppo.train", *LONG, "--out", str(out))
    try:
        wait_for(lambda: third.poll() is not None or max((r["iteration"] for r in train_rows(out)), default=0) > before,
                 "the dead trainer's run to be taken over", timeout=300)
        assert third.poll() is None, third.stdout.read()
    finally:
        text = stop(third)
    assert f"took over {out / 'run.lock'}" in text and "resuming" in text, text


def plant(directory, holder: dict, age_s: float = 0.0):
    path = directory / "run.lock"
    path.write_text(json.dumps(holder))
    if age_s:
        os.utime(path, (time.time() - age_s, time.time() - age_s))


def test_another_hosts_lock_holds_while_its_heartbeat_is_fresh(tmp_path):
    plant(tmp_path, {"host": "elsewhere", "pid": 77, "started": "yesterday", "program": "kage.ppo.train", "token": "x"})
    with pytest.raises(lock.LockHeld, match="process 77 on host elsewhere, since yesterday"):
        lock.DirectoryLock(str(tmp_path), "run", "test").acquire("use another --out")


@pytest.mark.parametrize("content", ["not json", "[]", '{"pid": "x"}', '{"host": "elsewhere"}'])
def test_a_lock_that_names_no_writer_says_so_and_how_to_clear_it(tmp_path, content):
    (tmp_path / "run.lock").write_text(content)
    with pytest.raises(lock.LockHeld) as held:
        lock.DirectoryLock(str(tmp_path), "run", "test").acquire("use another --out")
    assert f"has a lock that names no writer ({tmp_path / 'run.lock'}" in str(held.value)
    assert "delete it if no process uses" in str(held.value) and "?" not in str(held.value)


def test_another_hosts_lock_with_an_old_heartbeat_is_taken_over(tmp_path):
    plant(tmp_path, {"host": "elsewhere", "pid": 77, "token": "x"}, age_s=lock.STALE_S + 60)
    held = lock.DirectoryLock(str(tmp_path), "run", "test")
    held.acquire("")
    assert json.loads((tmp_path / "run.lock").read_text())["pid"] == os.getpid()
    held.release()
    assert not (tmp_path / "run.lock").exists()


def test_this_hosts_lock_of_a_gone_process_is_taken_over(tmp_path):
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    plant(tmp_path, {"host": socket.gethostname(), "boot_id": lock.boot_id(), "pid": gone.pid, "token": "x"})
    with lock.DirectoryLock(str(tmp_path), "run", "test") as held:
        held.acquire("")
        assert json.loads((tmp_path / "run.lock").read_text())["pid"] == os.getpid()


def test_a_reused_process_id_is_not_the_holder(tmp_path):
    plant(tmp_path, {"host": socket.gethostname(), "boot_id": lock.boot_id(), "pid": os.getppid(),
                     "proc_start": "1", "token": "x"})  # a live process, but not the one that took the lock
    with lock.DirectoryLock(str(tmp_path), "run", "test") as held:
        held.acquire("")


def racer(directory, barrier, results, all_tried):
    barrier.wait()
    try:
        lock.DirectoryLock(directory, "run", "racer").acquire("")
        results.put(os.getpid())
        all_tried.wait(timeout=60)  # hold it until every racer has tried, however slowly they are scheduled
    except lock.LockHeld:
        results.put(None)


@pytest.mark.parametrize("dead_first", [False, True], ids=["free", "dead-holder"])
def test_of_eight_racing_processes_exactly_one_gets_the_lock(tmp_path, dead_first):
    if dead_first:
        plant(tmp_path, {"host": "elsewhere", "pid": 1, "token": "old"}, age_s=lock.STALE_S + 60)
    context = multiprocessing.get_context("fork")
    barrier, results, all_tried = context.Barrier(8), context.Queue(), context.Event()
    racers = [context.Process(target=racer, args=(str(tmp_path), barrier, results, all_tried)) for _ in range(8)]
    for r in racers:
        r.start()
    try:
        won = [results.get(timeout=60) for _ in racers]
    finally:
        all_tried.set()
    for r in racers:
        r.join()
    assert sum(w is not None for w in won) == 1, won


def write_suite(tmp_path):
    suite = tmp_path / "suite.yaml"
    suite.write_text(SUITE.format(config=NOISY_SKELETON))
    return suite


def test_a_second_benchmark_runner_on_a_directory_refuses(tmp_path):
    suite, out = write_suite(tmp_path), tmp_path / "bench"
    flags = [str(suite), "--seeds", "1", "--out", str(out), *TRAINING]
    first = start("kage.bench", "run", *flags)
    try:
        wait_for(lambda: len(train_rows(out / "runs" / "alone" / "seed_1")) >= 1, "the first runner's training")
        second = start("kage.bench", "run", *flags)
        text = second.communicate(timeout=120)[0]
        assert second.returncode != 0, text
        assert f"process {first.pid} on host {socket.gethostname()}" in text and "Traceback" not in text, text
    finally:
        first.terminate()
        first.communicate(timeout=300)


def test_killing_the_runners_process_group_stops_its_trainer(tmp_path):
    suite, out = write_suite(tmp_path), tmp_path / "bench"
    runner = start("kage.bench", "run", str(suite), "--seeds", "1", "--out", str(out), *TRAINING,
                   start_new_session=True)
    run_lock = out / "runs" / "alone" / "seed_1" / "run.lock"
    wait_for(lambda: len(train_rows(out / "runs" / "alone" / "seed_1")) >= 1, "the trainer")
    trainer = json.loads(run_lock.read_text())["pid"]
    os.killpg(runner.pid, signal.SIGKILL)
    runner.communicate(timeout=60)

    def gone():
        try:
            os.kill(trainer, 0)
            return False
        except ProcessLookupError:
            return True
    wait_for(gone, f"trainer {trainer} to end with its runner", timeout=180)
