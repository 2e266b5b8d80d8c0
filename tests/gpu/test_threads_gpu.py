"""A GPU batch under threads and at close: calls from several threads run one at a time, closing waits for a
step in progress, and the batch's memory is freed only after the device has run the work queued on it,
including a consumer's kernels on its own stream that still read an output."""
import subprocess
import sys
import textwrap
import threading

import numpy as np
import torch

import kage
from support import ROOT, SIMPLEST


def test_close_while_another_thread_steps():
    # In a child interpreter: a crash would take pytest with it.
    script = textwrap.dedent(f"""
        import sys, threading, time
        import torch
        import kage
        sys.path.insert(0, {str(ROOT / "tests/python")!r})
        from support import SIMPLEST
        for attempt in range(5):
            env = kage.make_vec(SIMPLEST, 4096, device="cuda")
            env.reset(seed=attempt)
            actions = torch.full((4096,), 2, device="cuda")
            inside, outcome = threading.Event(), []

            def stepper():
                try:
                    while True:
                        inside.set()
                        env.step(actions)
                except RuntimeError as e:
                    outcome.append(str(e))

            worker = threading.Thread(target=stepper)
            worker.start()
            inside.wait()
            time.sleep(0.005 * attempt)
            env.close()
            worker.join(timeout=60)
            assert outcome and "closed" in outcome[0], outcome
        torch.cuda.synchronize()
        print("ok")
        """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, f"exit {result.returncode}: {result.stderr[-2000:]}"
    assert result.stdout.strip() == "ok"


def test_four_threads_stepping_one_batch_equal_one_thread():
    n, per_thread = 256, 20
    actions = torch.full((n,), 6, device="cuda")
    with kage.make_vec(SIMPLEST, n, device="cuda") as one:
        one.reset(seed=7)
        for _ in range(4 * per_thread):
            one.step(actions)
        expected = one.save_state()
    with kage.make_vec(SIMPLEST, n, device="cuda") as env:
        env.reset(seed=7)
        errors = []

        def stepper():
            try:
                for _ in range(per_thread):
                    env.step(actions)
            except Exception as e:  # reported below: an exception in a thread is otherwise lost
                errors.append(e)

        workers = [threading.Thread(target=stepper) for _ in range(4)]
        for w in workers:
            w.start()
        for w in workers:
            w.join()
        assert not errors, errors
        assert env.save_state() == expected


def test_close_frees_after_a_consumer_on_another_stream_has_read():
    side = torch.cuda.Stream()
    env = kage.make_vec(SIMPLEST, 256, device="cuda")
    obs = env.reset(seed=3)[0]
    expected = obs.numpy()
    with torch.cuda.stream(side):
        view = torch.from_dlpack(obs)  # ordered after the batch's stream for `side`
        torch.cuda._sleep(500_000_000)  # the consumer is still busy when the batch goes
        copy = view.clone()
    del view, obs
    env.close()  # the last reference: the memory may go only once `side` has read it
    with kage.make_vec(SIMPLEST, 256, device="cuda") as other:
        other.reset(seed=4)  # new batches take freed memory first
        side.synchronize()
        assert not np.array_equal(other.outputs()[0].numpy(), expected), "the two resets differ"
    assert np.array_equal(copy.cpu().numpy(), expected)


def test_close_right_after_queued_steps_then_a_new_batch_matches_the_cpu():
    actions = np.tile(np.array([2, 6, 2, 0], dtype=np.int64), 64)
    for _ in range(3):
        env = kage.make_vec(SIMPLEST, 256, device="cuda")
        env.reset(seed=1)
        for _ in range(50):
            env.step(torch.as_tensor(actions, device="cuda"))
        env.close()  # no synchronize: 50 steps may still be queued
    with kage.make_vec(SIMPLEST, 256, device="cuda") as gpu, kage.make_vec(SIMPLEST, 256) as cpu:
        gpu.reset(seed=2)
        cpu.reset(seed=2)
        for _ in range(10):
            gpu.step(torch.as_tensor(actions, device="cuda"))
            cpu.step(actions)
        assert np.array_equal(gpu.outputs()[0].numpy(), cpu.outputs()[0])
