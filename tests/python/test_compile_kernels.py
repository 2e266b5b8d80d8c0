"""kage.compile_kernels: what it refuses, and in what order, on a machine without a GPU (tests/gpu/
test_compile_kernels_gpu.py compiles on one). Every config is read before the device is asked for, so a config
with errors is named even where no kernel could compile."""
import ctypes

import pytest

import kage
from support import CONFIGS, SIMPLEST


def has_cuda_driver() -> bool:
    try:
        ctypes.CDLL("libcuda.so.1")
        return True
    except OSError:
        return False


def test_a_config_with_errors_is_named_before_the_device():
    with pytest.raises(kage.ConfigError) as info:
        kage.compile_kernels([SIMPLEST, str(CONFIGS / "bad_value.yaml")])
    (diag,) = info.value.errors
    assert diag.file.endswith("bad_value.yaml") and (diag.line, diag.col) == (5, 12)
    assert "physics.gravity" in diag.message


def test_missing_config():
    with pytest.raises(FileNotFoundError, match="no/such.yaml"):
        kage.compile_kernels([SIMPLEST, "no/such.yaml"])


@pytest.mark.parametrize("configs", [SIMPLEST, str(SIMPLEST).encode()])
def test_one_path_instead_of_a_list(configs):
    with pytest.raises(TypeError, match=r"a list of configs, e.g. \[path\]"):
        kage.compile_kernels(configs)


@pytest.mark.skipif(has_cuda_driver(), reason="reported skip: this machine has a CUDA driver (tests/gpu compiles)")
def test_without_a_gpu_says_so():
    with pytest.raises(kage.DeviceUnavailableError, match="no usable"):
        kage.compile_kernels([SIMPLEST])


def test_no_configs_compile_nothing_and_need_no_gpu():
    assert kage.compile_kernels([]) == {"compiled": 0, "cached": 0}


# ---- the trainer compiles its pack's configs ahead (kage.ppo.runs.compile_kernels) ----

def pack_of(*eval_configs):
    from kage.ppo import args as train_args
    return [train_args.parse_args(["--train-config-path", SIMPLEST, "--eval-config-paths", *eval_configs,
                                   "--seed", str(seed)]) for seed in (1, 2)]


def test_the_trainer_names_a_config_with_errors_and_the_fix():
    from kage.ppo import runs
    with pytest.raises(SystemExit) as info:
        runs.compile_kernels(pack_of(str(CONFIGS / "bad_value.yaml")))
    assert "bad_value.yaml:5:12: error:" in str(info.value)
    assert "fix the config first" in str(info.value)


@pytest.mark.skipif(has_cuda_driver(), reason="reported skip: this machine has a CUDA driver (tests/gpu compiles)")
def test_the_trainer_counts_each_config_of_its_pack_once():
    from kage.ppo import runs
    with pytest.raises(SystemExit, match=r"(?s)compiling the kernels of 2 configs: .*no usable"):
        runs.compile_kernels(pack_of(str(CONFIGS / "near_goal.yaml")))
