"""kage.step_batches on the GPU: batches on streams of their own (as a pack's runs are), stepped by rows of one
device actions tensor that the default stream writes, equal each batch stepped alone with its row, byte for
byte, across autoresets; a mixture among them. Device rows step with one launch pair per config over all the
batches (kage::step_together); a refusal names its batch and steps none."""
import numpy as np
import pytest
import torch

import kage
from support import ROOT

BENCH = ROOT / "configs/kage_bench"
SKELETON, FILTERS_5 = str(BENCH / "bases/image_skeleton.yaml"), str(BENCH / "filters/5-eval.yaml")
N = 64


def batches(streams):
    configs = [SKELETON, FILTERS_5, [SKELETON, FILTERS_5], SKELETON]
    return [kage.make_vec(c, N, device="cuda", seed=10 + i, stream=s) for i, (c, s) in enumerate(zip(configs, streams))]


def outputs(env) -> dict:
    obs, reward, terminated, truncated, info = env.outputs()
    arrays = {"obs": obs, "reward": reward, "terminated": terminated, "truncated": truncated,
              "final_obs": info["final_obs"], "_final": info["_final"]}
    arrays.update({f"final_info/{k}": v for k, v in info["final_info"].items()})
    return {k: torch.from_dlpack(v).clone() for k, v in arrays.items()}


def assert_same_outputs(envs_a, envs_b, step) -> None:
    """Each batch of `envs_a` left every output byte for byte as its twin in `envs_b`."""
    for a, b in zip(envs_a, envs_b):
        oa, ob = outputs(a), outputs(b)
        for key in oa:
            assert torch.equal(oa[key], ob[key]), (step, key)


def step_side_by_side(together, alone, steps: int, seed: int, dtype=torch.int64) -> int:
    """Resets both lists, then steps `together` by kage.step_batches and each batch of `alone` by its own step with
    the same random rows (made on the default stream), comparing their outputs every 50 steps and past the 500-step
    truncation; the number of episodes that ended in `together`."""
    for env in together + alone:
        env.reset()
    generator = torch.Generator(device="cuda").manual_seed(seed)
    finished = 0
    for step in range(steps):
        actions = torch.randint(0, 8, (len(together), together[0].num_envs), device="cuda", generator=generator,
                                dtype=dtype)
        kage.step_batches(together, actions)
        for env, row in zip(alone, actions):
            env.step(row)
        torch.cuda.synchronize()
        if step % 50 == 0 or step >= 495:
            assert_same_outputs(together, alone, step)
        finished += sum(int(torch.from_dlpack(env.outputs()[4]["_final"]).sum()) for env in together)
    return finished


def test_rows_on_several_streams_equal_each_batch_stepped_alone():
    streams = [torch.cuda.Stream() for _ in range(4)]
    together, alone = batches([s.cuda_stream for s in streams]), batches([0] * 4)
    finished = step_side_by_side(together, alone, 600, seed=3)  # past the 500-step truncation of every episode
    assert finished >= 4 * N  # every environment's episode ended at least once


def test_int32_rows_with_a_row_stride_step_as_int64_rows():
    a, b = batches([0] * 4), batches([0] * 4)
    for env in a + b:
        env.reset()
    rows = torch.randint(0, 8, (4, N), device="cuda", generator=torch.Generator(device="cuda").manual_seed(5))
    wide = torch.zeros((4, 2 * N), dtype=torch.int32, device="cuda")
    wide[:, :N] = rows.to(torch.int32)
    kage.step_batches(a, rows)
    kage.step_batches(b, wide[:, :N])  # rows 2N apart
    torch.cuda.synchronize()
    for x, y in zip(a, b):
        assert np.array_equal(x.outputs()[0].numpy(), y.outputs()[0].numpy())


def test_a_pack_of_mixtures_steps_together_as_each_alone():
    """Eight runs of one mixture (a pack's runs on streams of their own, 40 environments: parts that do not fill
    a warp) step with one launch pair per config over all eight: each batch equals its twin stepped alone."""
    mixture = [SKELETON, FILTERS_5, str(BENCH / "filters/4-eval.yaml")]
    streams = [torch.cuda.Stream().cuda_stream for _ in range(8)]
    together = [kage.make_vec(mixture, 40, device="cuda", seed=i, stream=s) for i, s in enumerate(streams)]
    alone = [kage.make_vec(mixture, 40, device="cuda", seed=i) for i in range(8)]
    finished = step_side_by_side(together, alone, 520, seed=7, dtype=torch.int32)
    assert finished >= 8 * 40  # every environment's episode ended at least once


def test_a_bad_action_names_its_batch_and_nothing_steps():
    envs = batches([0] * 4)
    for env in envs:
        env.reset()
    actions = torch.zeros((4, N), dtype=torch.int64, device="cuda")
    actions[2, 7] = 9  # batch 2 is the mixture: its first part's environment 7
    kage.step_batches(envs, actions)  # step 1 runs with the value masked; the kernel reports it
    torch.cuda.synchronize()
    before = [outputs(env)["obs"] for env in envs]
    with pytest.raises(ValueError, match=r"batch 2 of 4 \(none stepped\): .*step 1 held 9 for environment 7"):
        kage.step_batches(envs, torch.zeros((4, N), dtype=torch.int64, device="cuda"))
    torch.cuda.synchronize()
    assert all(torch.equal(b, outputs(env)["obs"]) for b, env in zip(before, envs))
