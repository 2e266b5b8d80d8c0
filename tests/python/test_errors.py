"""Every documented bad input raises its documented exception, with a message that names the fix."""
import numpy as np
import pytest
import torch

import kage
from support import CONFIGS, SIMPLEST


@pytest.fixture
def env():
    with kage.make_vec(SIMPLEST, 4) as e:
        e.reset(seed=0)
        yield e


def test_config_error_carries_located_diagnostics():
    with pytest.raises(kage.ConfigError) as info:
        kage.make_vec(str(CONFIGS / "bad_value.yaml"), 2)
    (diag,) = info.value.errors
    assert diag.file.endswith("bad_value.yaml") and (diag.line, diag.col) == (5, 12)
    assert "physics.gravity" in diag.message and "[schema-type]" in diag.message
    assert "bad_value.yaml:5:12: error:" in str(info.value)


def test_missing_config():
    with pytest.raises(FileNotFoundError, match="no/such.yaml"):
        kage.make_vec("no/such.yaml", 2)


@pytest.mark.parametrize("kwargs, match", [
    ({"num_envs": 0}, "num_envs"),
    ({"num_envs": 2, "device": "tpu"}, "device"),
    ({"num_envs": 2, "threads": 0}, "threads"),
])
def test_bad_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        kage.make_vec(SIMPLEST, **kwargs)


def test_cuda_without_a_gpu_says_use_cpu():
    if kage.gpu_backend_built():
        try:
            import ctypes
            ctypes.CDLL("libcuda.so.1")
            pytest.skip("reported skip: this machine has a CUDA driver, so device='cuda' may work here")
        except OSError:
            pass
    with pytest.raises(RuntimeError, match="device='cpu'"):
        kage.make_vec(SIMPLEST, 2, device="cuda")


@pytest.mark.parametrize("actions, match", [
    (np.zeros(3, dtype=np.int64), r"shape \(3,\), expected \(4,\)"),
    (np.zeros((4, 1), dtype=np.int64), r"shape \(4, 1\), expected \(4,\)"),
    (np.zeros(4, dtype=np.float32), "dtype float32, expected an integer dtype"),
    (np.array([0, 1, 8, 2]), "action 8 for environment 2"),
    (np.array([0, -1, 2, 2]), "action -1 for environment 1"),
    (torch.tensor([0, 1, 2, 9]), "action 9 for environment 3"),
    (np.array([0, 2**63, 2, 1], dtype=np.uint64), "action 9223372036854775808 for environment 1"),  # was negative
    ([0, 1, 2], r"expected \(4,\)"),
])
def test_bad_actions(env, actions, match):
    with pytest.raises(ValueError, match=match):
        env.step(actions)


class FakeCudaArray:
    """Looks like a GPU array to the protocols."""

    shape = (4,)

    def __dlpack_device__(self):
        return (2, 0)

    def __dlpack__(self, stream=None):
        raise AssertionError("a CPU environment must not take the capsule")


class FakeCudaInterface:
    __cuda_array_interface__ = {"shape": (4,), "typestr": "<i8", "data": (1 << 40, False), "version": 3}


@pytest.mark.parametrize("actions", [FakeCudaArray(), FakeCudaInterface()])
def test_gpu_actions_for_a_cpu_env(env, actions):
    with pytest.raises(ValueError, match="GPU memory .* runs on the CPU"):
        env.step(actions)


def test_valid_inputs_of_every_host_kind(env):
    """Each host kind of actions steps the batch exactly as the same values as an int32 numpy array do, on a twin
    batch of the same config and seed."""
    with kage.make_vec(SIMPLEST, 4) as twin:
        twin.reset(seed=0)
        for actions, values in ((np.array([1, 2, 3, 4], dtype=np.uint8), [1, 2, 3, 4]), ([7, 6, 5, 4], [7, 6, 5, 4]),
                                (torch.tensor([0, 2, 4, 6], dtype=torch.int32), [0, 2, 4, 6]),
                                (np.array([2, 2, 2, 2, 9, 9, 9, 9], dtype=np.int64)[:4], [2, 2, 2, 2])):
            obs, reward, _, _, info = env.step(actions)
            want_obs, want_reward, _, _, want_info = twin.step(np.array(values, dtype=np.int32))
            assert np.array_equal(obs, want_obs) and np.array_equal(reward, want_reward), type(actions)
            assert np.array_equal(info["x"], want_info["x"]) and np.array_equal(info["vx"], want_info["vx"])
        # Right (2) and left (1) moved the environments apart: the comparison saw actions that mattered.
        assert len(set(info["x"].tolist())) > 1


def test_bad_reset_arguments(env):
    with pytest.raises(ValueError, match="4 non-negative ints"):
        env.reset(seed=[1, 2])
    with pytest.raises(ValueError, match="reset_mask"):
        env.reset(seed=1, options={"reset_mask": [True]})
    with pytest.raises(ValueError, match="unknown options"):
        env.reset(seed=1, options={"bogus": 1})
