"""Outputs are the runtime's memory: numpy and torch (DLPack) views share it, no copy."""
import numpy as np
import torch

import kage
from support import SIMPLEST


def test_numpy_and_torch_share_the_runtime_memory():
    with kage.make_vec(SIMPLEST, 2) as env:
        obs, info = env.reset(seed=0)
        handle = env._handle
        runtime = handle.data_ptr("obs")
        assert runtime != 0
        assert obs.ctypes.data == runtime
        assert np.from_dlpack(obs).ctypes.data == runtime
        tensor = torch.from_dlpack(obs)
        assert tensor.data_ptr() == runtime and tensor.dtype == torch.uint8 and tuple(tensor.shape) == obs.shape
        for name in ("reward", "terminated", "truncated", "final_obs", "final_mask"):
            assert handle.output(name).ctypes.data == handle.data_ptr(name), name
        for name, _, _ in kage.INFO_FIELDS:
            assert torch.from_dlpack(info[name]).data_ptr() == handle.data_ptr(f"info/{name}"), name
            assert info["final_info"][name].ctypes.data == handle.data_ptr(f"final_info/{name}"), name

        # The views see the next step's values: the same memory, overwritten in place.
        before = tensor.clone()
        x_view = torch.from_dlpack(info["x"])
        env.step(np.array([2, 2]))
        assert not torch.equal(tensor, before)
        assert torch.equal(x_view, torch.from_dlpack(env._handle.output("info/x")))


def test_flags_have_a_documented_bool_view():
    with kage.make_vec(SIMPLEST, 2) as env:
        env.reset(seed=0)
        _, _, terminated, truncated, _ = env.step(np.array([0, 0]))
        assert truncated.astype(bool).dtype == np.bool_
        assert torch.from_dlpack(terminated).bool().dtype == torch.bool
