"""A VecEnv under threads: calls from several threads are serialised, each one whole; closing, deleting or
collecting a batch that another thread is stepping waits for that step, and later calls raise. A crash
would take pytest with it, so the closing cases run in a child interpreter."""
import subprocess
import sys
import textwrap
import threading

import numpy as np

import kage
from support import ROOT, SIMPLEST

PYTHONPATH_CHILD = [str(ROOT / "tests/python")]


def run_child(body: str) -> subprocess.CompletedProcess:
    """`body` in a fresh interpreter with a batch `env` of 256 environments (a step takes milliseconds)."""
    script = textwrap.dedent("""
        import gc, sys, threading, time
        import numpy as np
        import kage
        sys.path[:0] = {path!r}
        from support import SIMPLEST
        """).format(path=PYTHONPATH_CHILD) + textwrap.dedent(body)
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)


def test_close_while_another_thread_steps():
    result = run_child("""
        for attempt in range(5):
            env = kage.make_vec(SIMPLEST, 256, threads=2)
            env.reset(seed=attempt)
            actions = np.full(256, 2)
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
            time.sleep(0.01 * attempt)
            env.close()
            worker.join(timeout=60)
            assert not worker.is_alive(), "the stepping thread hangs after close"
            assert outcome and "closed" in outcome[0], outcome
            assert env.closed
        print("ok")
        """)
    assert result.returncode == 0, f"exit {result.returncode}: {result.stderr[-2000:]}"
    assert result.stdout.strip() == "ok"


def test_the_bindings_handle_serialises_too():
    # kage._kage.Env, under VecEnv and any other front end: its own lock, not VecEnv's.
    result = run_child("""
        for attempt in range(3):
            handle = kage.make_vec(SIMPLEST, 256, threads=2)._handle
            handle.reset(np.arange(256, dtype=np.uint64), None)
            outcome = []

            def stepper():
                try:
                    while True:
                        handle.step_host(np.full(256, 2, dtype=np.int64))
                except RuntimeError as e:
                    outcome.append(str(e))

            worker = threading.Thread(target=stepper)
            worker.start()
            time.sleep(0.01 + 0.02 * attempt)
            handle.close()
            worker.join(timeout=60)
            assert outcome and "closed" in outcome[0], outcome
        print("ok")
        """)
    assert result.returncode == 0, f"exit {result.returncode}: {result.stderr[-2000:]}"
    assert result.stdout.strip() == "ok"


def test_delete_and_collect_while_another_thread_steps():
    result = run_child("""
        env = kage.make_vec(SIMPLEST, 256, threads=2)
        env.reset(seed=0)
        steps = []
        started = threading.Event()

        def stepper(e):
            started.set()
            for _ in range(20):
                obs = e.step(np.full(256, 6))[0]
                steps.append(int(obs.sum() > 0))

        worker = threading.Thread(target=stepper, args=(env,))
        worker.start()
        started.wait()
        del env
        gc.collect()
        worker.join(timeout=60)
        assert steps == [1] * 20, steps
        print("ok")
        """)
    assert result.returncode == 0, f"exit {result.returncode}: {result.stderr[-2000:]}"
    assert result.stdout.strip() == "ok"


def sequential_states(num_envs: int, steps: int, action: int) -> list:
    """save_state() after each of `steps` steps of one thread with the same action every step."""
    with kage.make_vec(SIMPLEST, num_envs, threads=2) as env:
        env.reset(seed=7)
        states = [env.save_state()]
        for _ in range(steps):
            env.step(np.full(num_envs, action))
            states.append(env.save_state())
    return states


def test_four_threads_stepping_one_batch_equal_one_thread():
    # Every step has the same actions, so serialised steps from any threads end where one thread would.
    n, per_thread = 64, 15
    expected = sequential_states(n, 4 * per_thread, 6)
    with kage.make_vec(SIMPLEST, n, threads=2) as env:
        env.reset(seed=7)
        errors = []

        def stepper():
            try:
                for _ in range(per_thread):
                    env.step(np.full(n, 6))
            except Exception as e:  # reported below: an exception in a thread is otherwise lost
                errors.append(e)

        workers = [threading.Thread(target=stepper) for _ in range(4)]
        for w in workers:
            w.start()
        for w in workers:
            w.join()
        assert not errors, errors
        assert env.save_state() == expected[-1]


def test_state_saved_while_another_thread_steps_is_a_whole_step():
    n, steps = 64, 30
    expected = set(sequential_states(n, steps, 2))
    with kage.make_vec(SIMPLEST, n, threads=2) as env:
        env.reset(seed=7)
        saved, done = [], threading.Event()

        def saver():
            while not done.is_set():
                saved.append(env.save_state())

        worker = threading.Thread(target=saver)
        worker.start()
        for _ in range(steps):
            env.step(np.full(n, 2))
        done.set()
        worker.join()
    assert saved
    assert all(s in expected for s in saved), "a state saved mid-step"


def test_reset_and_step_from_two_threads_return_whole_outputs():
    # Each call's outputs are the batch's views: whole steps, whatever the interleaving.
    with kage.make_vec(SIMPLEST, 32, threads=2) as env:
        env.reset(seed=1)
        errors = []

        def resetter():
            try:
                for i in range(20):
                    obs, info = env.reset(seed=i)
                    assert obs.shape == (32, 128, 128, 3) and "final_obs" in info
            except Exception as e:
                errors.append(e)

        worker = threading.Thread(target=resetter)
        worker.start()
        for _ in range(40):
            obs, reward, terminated, truncated, info = env.step(np.full(32, 2))
            assert obs is not None and info["timestep"].shape == (32,)
        worker.join()
        assert not errors, errors


def test_a_call_from_inside_a_call_on_the_same_thread_raises_instead_of_hanging():
    # An actions object whose __array__ calls back into the batch runs while step() holds it: waiting for
    # itself, the thread would hang forever.
    result = run_child("""
        outcomes = {}
        for name in ("close", "step", "reset", "save_state"):
            env = kage.make_vec(SIMPLEST, 2, threads=1)
            env.reset(seed=0)

            class CallsBack:
                def __array__(self, dtype=None, copy=None):
                    getattr(env, name)(*([np.zeros(2, dtype=np.int64)] if name == "step" else []))
                    return np.array([2, 2])

            def stepper():
                try:
                    env.step(CallsBack())
                    outcomes[name] = "stepped"
                except RuntimeError as e:
                    outcomes[name] = str(e)

            worker = threading.Thread(target=stepper, daemon=True)
            worker.start()
            worker.join(timeout=30)
            assert not worker.is_alive(), f"{name} from inside step hangs"
            assert "from inside another" in outcomes[name], outcomes
            assert not env.closed
            env.step(np.array([2, 2]))  # the batch is still usable
        print("ok")
        """)
    assert result.returncode == 0, f"exit {result.returncode}: {result.stderr[-2000:]}"
    assert result.stdout.strip() == "ok"
