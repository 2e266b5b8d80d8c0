"""The Python package on the GPU: the same bytes as the CPU, zero copy into torch, JAX and CuPy, device
actions in place (int32, int64, strided), stream ordering, deferred action checks, no sync per step."""
import time

import cupy
import numpy as np
import pytest
import torch

import kage
from support import NEAR_GOAL, NOISY_SKELETON, ROOT, SIMPLEST, policy

HARDEST = str(ROOT / "configs/throughput/hardest.yaml")


def outputs(obs, reward, terminated, truncated, info):
    """Host copies of every output (final_obs only in its final rows)."""
    host = lambda a: a.numpy() if isinstance(a, kage.DeviceArray) else np.array(a)
    final = host(info["_final"]).astype(bool)
    out = {"obs": host(obs), "reward": host(reward), "terminated": host(terminated), "truncated": host(truncated),
           "_final": final, "final_obs": host(info["final_obs"])[final]}
    for name, _, _ in kage.INFO_FIELDS:
        out[name] = host(info[name])
        out["final/" + name] = host(info["final_info"][name])[final]
    return out


@pytest.mark.parametrize("config", [NEAR_GOAL, NOISY_SKELETON, HARDEST])
def test_gpu_equals_cpu(config):
    n, steps = 6, 45
    actions = policy(11, n, steps)
    with kage.make_vec(config, n, device="cuda") as gpu, kage.make_vec(config, n, device="cpu") as cpu:
        gobs, ginfo = gpu.reset(seed=5)
        cobs, cinfo = cpu.reset(seed=5)
        assert np.array_equal(gobs.numpy(), cobs)
        finals = 0
        for t, a in enumerate(actions):
            g = outputs(*gpu.step(torch.as_tensor(a, device="cuda")))
            c = outputs(*cpu.step(a))
            finals += int(c["_final"].sum())
            for key in c:
                assert np.array_equal(g[key], c[key]), f"{config}: step {t + 1}, {key}"
        if config != HARDEST:
            assert finals > 0, "an episode ended, so final_obs was compared"


def test_outputs_are_the_runtime_memory():
    with kage.make_vec(SIMPLEST, 64, device="cuda") as env:
        obs, info = env.reset(seed=0)
        handle = env._handle
        t = torch.from_dlpack(obs)
        assert t.is_cuda and t.data_ptr() == handle.data_ptr("obs") == obs.data_ptr
        assert tuple(t.shape) == (64, 128, 128, 3) and t.dtype == torch.uint8
        for name, _, _ in kage.INFO_FIELDS:
            assert torch.from_dlpack(info[name]).data_ptr() == handle.data_ptr(f"info/{name}")
            assert torch.from_dlpack(info["final_info"][name]).data_ptr() == handle.data_ptr(f"final_info/{name}")
        _, reward, terminated, truncated, info = env.step(torch.full((64,), 2, device="cuda"))
        for name, array in (("reward", reward), ("terminated", terminated), ("truncated", truncated),
                            ("final_mask", info["_final"]), ("final_obs", info["final_obs"])):
            assert torch.from_dlpack(array).data_ptr() == handle.data_ptr(name), name
        assert torch.equal(t, torch.from_dlpack(env._handle.output("obs"))), "the view follows the steps"


def test_jax_and_cupy_read_without_copy():
    import jax
    import cupy
    with kage.make_vec(SIMPLEST, 8, device="cuda") as env:
        obs, _ = env.reset(seed=1)
        expected = obs.numpy()
        j = jax.dlpack.from_dlpack(obs)
        assert j.shape == (8, 128, 128, 3) and str(j.dtype) == "uint8"
        assert np.array_equal(np.asarray(j), expected)
        assert j.unsafe_buffer_pointer() == obs.data_ptr, "JAX views the runtime's buffer"
        c = cupy.asarray(obs)  # __cuda_array_interface__
        assert c.data.ptr == obs.data_ptr and np.array_equal(cupy.asnumpy(c), expected)


def test_device_actions_of_every_layout():
    n = 16
    actions = policy(3, n, 30)
    runs = []
    for make in (lambda a: a,                                                        # host int64
                 lambda a: torch.as_tensor(a, device="cuda"),                         # int64
                 lambda a: torch.as_tensor(a, device="cuda", dtype=torch.int32),      # int32
                 lambda a: torch.stack([torch.as_tensor(a, device="cuda")] * 3, 1)[:, 1],  # strided view
                 lambda a: cupy.asarray(a)):                                         # __cuda_array_interface__
        with kage.make_vec(NEAR_GOAL, n, device="cuda") as env:
            env.reset(seed=2)
            for a in actions:
                obs, *_ = env.step(make(a))
            runs.append(obs.numpy())
    for r in runs[1:]:
        assert np.array_equal(r, runs[0])


def test_out_of_range_device_action_is_reported_later():
    with kage.make_vec(SIMPLEST, 8, device="cuda") as env:
        env.reset(seed=0)
        bad = torch.tensor([0, 1, 2, 3, 4, 5, 6, 9], device="cuda")
        env.step(bad)
        with pytest.raises(ValueError, match=r"step 1 held 9 for environment 7"):
            env.synchronize()
        env.step(torch.zeros(8, dtype=torch.int64, device="cuda"))
        env.synchronize()  # reported once


def test_device_actions_of_the_wrong_kind():
    with kage.make_vec(SIMPLEST, 8, device="cuda") as env:
        env.reset(seed=0)
        with pytest.raises(ValueError, match=r"shape \(4,\), expected \(8,\)"):
            env.step(torch.zeros(4, dtype=torch.int64, device="cuda"))
        with pytest.raises(ValueError, match="int32 or int64"):
            env.step(torch.zeros(8, dtype=torch.float32, device="cuda"))


def test_a_learner_stream_orders_with_the_env():
    """Env on a side stream, actions produced on it: the same frames as on the default stream."""
    n = 32
    actions = policy(9, n, 40)
    side = torch.cuda.Stream()
    results = []
    for stream in (None, side):
        with kage.make_vec(NEAR_GOAL, n, device="cuda", stream=stream) as env:
            with torch.cuda.stream(side if stream is not None else torch.cuda.default_stream()):
                env.reset(seed=4)
                total = torch.zeros(n, device="cuda")
                for a in actions:
                    # A slow producer: the step must wait for these kernels through the stream, not the host.
                    x = torch.as_tensor(a, device="cuda")
                    for _ in range(20):
                        x = (x * 3 + 1) % 8
                    x = (x * 0 + torch.as_tensor(a, device="cuda"))
                    obs, reward, *_ = env.step(x)
                    total += torch.from_dlpack(reward)
                results.append((torch.from_dlpack(obs).cpu().numpy(), total.cpu().numpy()))
    assert np.array_equal(results[0][0], results[1][0]) and np.array_equal(results[0][1], results[1][1])


def test_state_moves_between_gpu_and_cpu():
    actions = policy(5, 4, 60)
    with kage.make_vec(NOISY_SKELETON, 4, device="cuda") as gpu, kage.make_vec(NOISY_SKELETON, 4) as cpu:
        gpu.reset(seed=3)
        for a in actions[:20]:
            gpu.step(torch.as_tensor(a, device="cuda"))
        restored, _ = cpu.load_state(gpu.save_state())
        assert np.array_equal(restored, gpu._handle.output("obs").numpy())
        for a in actions[20:]:
            g = outputs(*gpu.step(torch.as_tensor(a, device="cuda")))
            c = outputs(*cpu.step(a))
            for key in c:
                assert np.array_equal(g[key], c[key]), key


def test_step_queues_without_waiting():
    """A step returns long before its kernels finish: no host synchronisation per step."""
    n = 4096
    with kage.make_vec(HARDEST, n, device="cuda") as env:
        env.reset(seed=0)
        a = torch.randint(0, 8, (n,), device="cuda")
        env.step(a)
        torch.cuda.synchronize()
        t0 = time.perf_counter()
        env.step(a)
        torch.cuda.synchronize()
        gpu_step = time.perf_counter() - t0
        t0 = time.perf_counter()
        for _ in range(10):
            env.step(a)
        queued = time.perf_counter() - t0
        torch.cuda.synchronize()
        assert gpu_step > 5e-3, "the hardest config at 4096 envs takes milliseconds per step"
        assert queued < 0.25 * 10 * gpu_step, f"10 steps queued in {queued:.4f} s vs {gpu_step:.4f} s each on the GPU"


def test_profiler_sees_no_copy_or_sync_in_a_step():
    """No copy at all, and no synchronisation between a step's call and its return (the profiler itself
    synchronises when it stops, outside the steps)."""
    from torch.profiler import ProfilerActivity, profile, record_function
    n = 1024
    with kage.make_vec(SIMPLEST, n, device="cuda") as env:
        env.reset(seed=0)
        for _ in range(3):
            env.step(torch.randint(0, 8, (n,), device="cuda"))
        torch.cuda.synchronize()
        with profile(activities=[ProfilerActivity.CPU, ProfilerActivity.CUDA]) as prof:
            for _ in range(20):
                actions = torch.randint(0, 8, (n,), device="cuda")
                with record_function("kage.step"):
                    obs, reward, *_ = env.step(actions)
                    torch.from_dlpack(obs)
        torch.cuda.synchronize()
    events = list(prof.events())
    steps = [(e.time_range.start, e.time_range.end) for e in events
             if e.name == "kage.step" and e.device_type == torch.autograd.DeviceType.CPU]
    assert len(steps) == 20
    names = [e.name for e in events]
    assert sum("kage_step" in x for x in names) == 20 and sum("kage_render" in x for x in names) == 20
    copies = [x for x in names if "memcpy" in x.lower()]
    assert not copies, copies
    syncs = [e.name for e in events if "synchronize" in e.name.lower()
             and any(a <= e.time_range.start <= b for a, b in steps)]
    assert not syncs, syncs
