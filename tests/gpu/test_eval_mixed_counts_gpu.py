"""The padded evaluation (a pack's runs evaluating different numbers of configs) on the GPU with the table's speed
flags, its evaluation step a CUDA graph: each run logs what it logs in a pack whose runs evaluate equally many,
as tests/python/test_eval_mixed_counts.py checks on the CPU. cuDNN's deterministic algorithms make equality the
test: the padded pack's batches have the equal pack's shapes."""
import pytest
import torch

from kage.ppo import train
from test_eval_mixed_counts import NEAR_GOAL, NOISY, RED, only, rows

FLAGS = ["--device", "cuda", "--bf16", "--fused-input", "--cuda-graph", "--triton-conv", "--total-timesteps", "2048",
         "--num-envs", "8", "--num-steps", "64", "--num-minibatches", "2", "--update-epochs", "2",
         "--run-eval-every", "1", "--eval-episodes", "4", "--eval-num-envs", "4"]


@pytest.fixture
def deterministic(monkeypatch):
    monkeypatch.setattr(torch.backends.cudnn, "deterministic", True)
    before = torch.are_deterministic_algorithms_enabled(), torch.is_deterministic_algorithms_warn_only_enabled()
    torch.use_deterministic_algorithms(True, warn_only=True)
    yield
    torch.use_deterministic_algorithms(before[0], warn_only=before[1])


def run_args(out, seed, train_config, evals):
    return train.parse_args(FLAGS + ["--train-config-path", train_config, "--eval-config-paths", *evals,
                                     "--seed", str(seed), "--out", str(out)])


def test_a_padded_pack_evaluates_on_the_gpu_as_an_equal_one(tmp_path, deterministic):
    train.train([run_args(tmp_path / "mixed/a", 3, NEAR_GOAL, [RED, NOISY]),
                 run_args(tmp_path / "mixed/b", 8, RED, [NEAR_GOAL])])
    train.train([run_args(tmp_path / "equal/a", 3, NEAR_GOAL, [RED, NOISY]),
                 run_args(tmp_path / "equal/b", 8, RED, [NEAR_GOAL, NOISY])])

    assert rows(tmp_path / "mixed/a") == rows(tmp_path / "equal/a")
    mixed_b, equal_b = rows(tmp_path / "mixed/b"), rows(tmp_path / "equal/b")
    assert [r["kind"] for r in mixed_b] == [r["kind"] for r in equal_b] and "eval" in {r["kind"] for r in mixed_b}
    for mixed, equal in zip(mixed_b, equal_b):
        if mixed["kind"] == "eval":
            assert list(mixed["evals"]) == ["near_goal.yaml"]  # no row for the padding
            assert mixed == only(equal, {"near_goal.yaml"})
        else:
            assert mixed == equal
