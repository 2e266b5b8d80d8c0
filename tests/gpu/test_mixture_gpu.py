"""Mixtures on the GPU (kage.make_vec([a, b, ...], N, device="cuda")): every part's slice of every output equals
its config run alone on the GPU with the same seeds and actions, byte for byte; the GPU mixture equals the CPU
mixture; device actions of every layout; a saved state continues exactly (and across devices); an out-of-range
device action is reported with the batch's environment index."""
import numpy as np
import pytest
import torch

import kage
from support import ROOT

BENCH = ROOT / "configs/kage_bench"
# The filters pairs' training config and three of their evaluation configs (one hidden game: kagec diff
# --mixture certifies them): colour jitter (a random filter), pixelate (the frame-pass render path), radial light.
MIX = [str(BENCH / "bases/image_skeleton.yaml"), str(BENCH / "filters/5-eval.yaml"),
       str(BENCH / "filters/7-eval.yaml"), str(BENCH / "filters/9-eval.yaml")]
WEIGHTS = [5, 1, 3, 1]
# NPCs and sticky NPCs: parts whose visual states differ in extent (runtime/cuda/device_batch.cpp).
NPC_MIX = [str(BENCH / "bases/skeleton_black.yaml"), str(BENCH / "distractors/1-eval.yaml"),
           str(BENCH / "distractors/3-eval.yaml")]


def raw(a) -> torch.Tensor:
    """An output's bytes on the GPU: a kage.DeviceArray viewed in place (DLPack), a numpy array copied."""
    t = torch.from_numpy(np.ascontiguousarray(a)) if isinstance(a, np.ndarray) else torch.from_dlpack(a)
    return t.cuda().contiguous().view(torch.uint8).reshape(t.shape[0], -1)


def snapshot(outputs) -> dict:
    """Every output of a reset (obs, info) or a step (obs, reward, terminated, truncated, info) as [N, bytes]
    rows on the GPU, by name (final_info's fields as final_info/NAME)."""
    *arrays, info = outputs
    out = {name: raw(a) for name, a in zip(("obs", "reward", "terminated", "truncated"), arrays)}
    for key, value in info.items():
        if key == "final_info":
            out.update({f"final_info/{k}": raw(v) for k, v in value.items()})
        else:
            out[key] = raw(value)
    return out


def final_rows(snap: dict) -> torch.Tensor:
    return snap["_final"][:, 0].bool()


def check_part(mixed: dict, alone: dict, first: int, count: int, k: int, what: str):
    """Rows [first, first + count) of the mixture equal the config alone; final_obs and final_info only where
    the step ended an episode (other rows hold an earlier end, or nothing); info["config"] is k there, 0 alone."""
    assert mixed.keys() == alone.keys(), what
    rows = slice(first, first + count)
    final = final_rows(alone)
    for name, expected in alone.items():
        got = mixed[name][rows]
        if name in ("config", "final_info/config"):
            assert torch.equal(got.view(torch.int32), torch.full((count, 1), k, dtype=torch.int32, device="cuda")), what
            assert torch.equal(expected.view(torch.int32), torch.zeros_like(expected.view(torch.int32))), what
            continue
        if name == "final_obs" or name.startswith("final_info/"):
            got, expected = got[final], expected[final]
        assert torch.equal(got, expected), f"{what}: {name} of part {k} (environments {first}..{first + count - 1})"


def check_whole(gpu: dict, cpu: dict, what: str):
    """The GPU mixture equals the CPU mixture, every output (final ones in the final rows)."""
    assert gpu.keys() == cpu.keys(), what
    final = final_rows(cpu)
    for name, expected in cpu.items():
        got = gpu[name]
        if name == "final_obs" or name.startswith("final_info/"):
            got, expected = got[final], expected[final]
        assert torch.equal(got, expected), f"{what}: {name}, GPU mixture against CPU mixture"


def device_actions(a: np.ndarray, t: int) -> torch.Tensor:
    """Step t's actions as a torch CUDA tensor, its layout turning over: int64, int32, strided int64."""
    if t % 3 == 0:
        return torch.as_tensor(a, dtype=torch.int64, device="cuda")
    if t % 3 == 1:
        return torch.as_tensor(a, dtype=torch.int32, device="cuda")
    wide = torch.zeros((a.shape[0], 3), dtype=torch.int64, device="cuda")
    wide[:, 1] = torch.as_tensor(a, device="cuda")
    return wide[:, 1]  # stride 3


def test_each_part_equals_its_config_alone_and_the_cpu_mixture():
    seed, n, steps = 7, 1000, 510  # episode_length 500: every environment ends an episode at least once
    rng = np.random.default_rng(seed)
    actions = rng.integers(0, 8, size=(steps, n), dtype=np.int64)
    seeds = kage.env_seeds(seed, n)
    with kage.make_vec(MIX, n, device="cuda", weights=WEIGHTS) as gpu, \
            kage.make_vec(MIX, n, device="cpu", weights=WEIGHTS) as cpu:
        counts = gpu.counts
        assert counts == cpu.counts == (500, 100, 300, 100) and gpu.device == "cuda"
        firsts = np.concatenate([[0], np.cumsum(counts)[:-1]]).tolist()
        alone = [kage.make_vec(c, count, device="cuda") for c, count in zip(MIX, counts)]
        try:
            assert len({e.spec_hash for e in alone}) == len(MIX), "four different configs"
            g = snapshot(gpu.reset(seed=seed))
            c = snapshot(cpu.reset(seed=seed))
            assert g["config"].view(torch.int32)[:, 0].tolist() == sum(([k] * m for k, m in enumerate(counts)), [])
            parts = [snapshot(e.reset(seed=seeds[f:f + m].tolist())) for e, f, m in zip(alone, firsts, counts)]
            check_whole(g, c, "reset")
            for k, (p, f, m) in enumerate(zip(parts, firsts, counts)):
                check_part(g, p, f, m, k, "reset")
            finals = torch.zeros(n, dtype=torch.int64, device="cuda")
            for t, a in enumerate(actions):
                g = snapshot(gpu.step(device_actions(a, t)))
                c = snapshot(cpu.step(a))
                parts = [snapshot(e.step(a[f:f + m])) for e, f, m in zip(alone, firsts, counts)]
                what = f"step {t + 1}"
                check_whole(g, c, what)
                for k, (p, f, m) in enumerate(zip(parts, firsts, counts)):
                    check_part(g, p, f, m, k, what)
                finals += final_rows(g).long()
            # Not vacuous: every environment finished an episode (final_obs compared), and the parts look different.
            assert int((finals > 0).sum()) == n
            frames = torch.from_dlpack(gpu.step(device_actions(actions[0], 0))[0])
            assert all(not torch.equal(frames[f], frames[firsts[0]]) for f in firsts[1:])
            assert torch.unique(frames[firsts[1]]).numel() > 10
        finally:
            for e in alone:
                e.close()


def test_a_mixture_with_npcs_equals_its_configs_alone():
    """Parts whose visual states differ (no NPCs, NPCs, sticky NPCs): each renders its own state's extent."""
    seed, n, steps = 3, 96, 120
    actions = np.random.default_rng(seed).integers(0, 8, size=(steps, n), dtype=np.int64)
    seeds = kage.env_seeds(seed, n)
    with kage.make_vec(NPC_MIX, n, device="cuda", weights=[1, 2, 3]) as gpu, \
            kage.make_vec(NPC_MIX, n, device="cpu", weights=[1, 2, 3]) as cpu:
        counts = gpu.counts
        firsts = np.concatenate([[0], np.cumsum(counts)[:-1]]).tolist()
        alone = [kage.make_vec(c, m, device="cuda") for c, m in zip(NPC_MIX, counts)]
        try:
            g, c = snapshot(gpu.reset(seed=seed)), snapshot(cpu.reset(seed=seed))
            parts = [snapshot(e.reset(seed=seeds[f:f + m].tolist())) for e, f, m in zip(alone, firsts, counts)]
            for t in range(steps + 1):
                check_whole(g, c, f"step {t}")
                for k, (p, f, m) in enumerate(zip(parts, firsts, counts)):
                    check_part(g, p, f, m, k, f"step {t}")
                if t == steps:
                    break
                a = actions[t]
                g, c = snapshot(gpu.step(torch.as_tensor(a, device="cuda"))), snapshot(cpu.step(a))
                parts = [snapshot(e.step(a[f:f + m])) for e, f, m in zip(alone, firsts, counts)]
        finally:
            for e in alone:
                e.close()


def test_a_part_of_no_environments_and_a_side_stream():
    """Weights that leave a config without environments (its kernels never launch), on a side stream: the same
    bytes as the CPU mixture."""
    n, steps = 9, 60
    actions = np.random.default_rng(8).integers(0, 8, size=(steps, n), dtype=np.int64)
    side = torch.cuda.Stream()
    with kage.make_vec(MIX[:3], n, device="cuda", weights=[2, 0, 1], stream=side) as gpu, \
            kage.make_vec(MIX[:3], n, device="cpu", weights=[2, 0, 1]) as cpu:
        assert gpu.counts == cpu.counts == (6, 0, 3) and gpu.stream == side.cuda_stream
        with torch.cuda.stream(side):
            check_whole(snapshot(gpu.reset(seed=1)), snapshot(cpu.reset(seed=1)), "reset")
            for t, a in enumerate(actions):
                check_whole(snapshot(gpu.step(torch.as_tensor(a, device="cuda"))), snapshot(cpu.step(a)), f"step {t + 1}")


def test_a_saved_gpu_mixture_continues_exactly_on_either_device():
    n = 64
    rng = np.random.default_rng(4)
    before, after = rng.integers(0, 8, size=(40, n)), rng.integers(0, 8, size=(40, n))
    with kage.make_vec(MIX, n, device="cuda", weights=WEIGHTS) as a, \
            kage.make_vec(MIX, n, device="cuda", weights=WEIGHTS) as b, \
            kage.make_vec(MIX, n, device="cpu", weights=WEIGHTS) as c:
        a.reset(seed=11)
        for x in before:
            a.step(torch.as_tensor(x, device="cuda"))
        state = a.save_state()
        b.load_state(state)
        c.load_state(state)
        # load_state renders every part's frames again: the observations at once, before any step.
        assert torch.equal(torch.from_dlpack(b._handle.output("obs")), torch.from_dlpack(a._handle.output("obs")))
        assert np.array_equal(c._handle.output("obs"), a._handle.output("obs").numpy())
        for t, x in enumerate(after):
            sa = snapshot(a.step(torch.as_tensor(x, device="cuda")))
            sb = snapshot(b.step(torch.as_tensor(x, device="cuda")))
            sc = snapshot(c.step(x))
            check_whole(sb, sa, f"step {t + 1} after load_state")
            check_whole(sa, sc, f"step {t + 1} after load_state on the CPU")
        assert b.save_state() == a.save_state()
        with kage.make_vec(MIX, n, device="cuda", weights=[1, 1, 1, 1]) as other:
            with pytest.raises(ValueError, match="spec hash"):
                other.load_state(state)


def test_an_out_of_range_action_names_the_batchs_environment():
    with kage.make_vec(MIX, 10, device="cuda", weights=[3, 2, 4, 1]) as env:
        assert env.counts == (3, 2, 4, 1)
        env.reset(seed=0)
        bad = torch.zeros(10, dtype=torch.int64, device="cuda")
        bad[6] = 9  # part 2 (environments 5..8), its environment 1
        env.step(bad)
        with pytest.raises(ValueError, match=r"step 1 held 9 for environment 6"):
            env.synchronize()
        env.step(torch.zeros(10, dtype=torch.int64, device="cuda"))
        env.synchronize()  # reported once
        # Two parts in one step: the first part's report, with its own offset.
        bad = torch.zeros(10, dtype=torch.int32, device="cuda")
        bad[4], bad[9] = -1, 8  # part 1's environment 1, part 3's environment 0
        env.step(bad)
        with pytest.raises(ValueError, match=r"step 3 held -1 for environment 4"):
            env.synchronize()
        env.step(torch.zeros(10, dtype=torch.int64, device="cuda"))
        env.synchronize()
