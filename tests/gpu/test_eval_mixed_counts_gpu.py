"""The padded evaluation (a pack's runs evaluating different numbers of configs) on the GPU with the table's speed
flags, its evaluation step a CUDA graph: each run logs what it logs in a pack whose runs evaluate equally many,
as tests/python/test_eval_mixed_counts.py checks on the CPU. cuDNN's deterministic algorithms make equality the
test: the padded pack's batches have the equal pack's shapes."""
from kage.ppo import train
from test_eval_mixed_counts import assert_padded_pack_logs_as_an_equal_one

FLAGS = ["--device", "cuda", "--bf16", "--fused-input", "--cuda-graph", "--triton-conv", "--total-timesteps", "2048",
         "--num-envs", "8", "--num-steps", "64", "--num-minibatches", "2", "--update-epochs", "2",
         "--run-eval-every", "1", "--eval-episodes", "4", "--eval-num-envs", "4"]


def run_args(out, seed, train_config, evals):
    return train.parse_args(FLAGS + ["--train-config-path", train_config, "--eval-config-paths", *evals,
                                     "--seed", str(seed), "--out", str(out)])


def test_a_padded_pack_evaluates_on_the_gpu_as_an_equal_one(tmp_path, deterministic):
    mixed_b = assert_padded_pack_logs_as_an_equal_one(tmp_path, run_args)
    assert [r["kind"] for r in mixed_b].count("eval") == 5  # iterations 0 to 4
