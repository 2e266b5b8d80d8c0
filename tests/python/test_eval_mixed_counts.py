"""A pack's runs may evaluate different numbers of configs (kage.ppo.evaluation pads the fewer with blank slots
that no environment steps): each run logs what it logs in a pack whose runs evaluate equally many, where the
other run's extra config is a real one. CPU, one thread."""
import json

import pytest

from kage.ppo import train
from support import CONFIGS

TIMING = {"charts/SPS", "charts/SPS_update", "seconds"}
FLAGS = ["--device", "cpu", "--threads", "1", "--total-timesteps", "64", "--num-envs", "2", "--num-steps", "32",
         "--num-minibatches", "2", "--update-epochs", "1", "--run-eval-every", "1", "--eval-episodes", "3",
         "--eval-num-envs", "2"]
NEAR_GOAL, RED, NOISY = (str(CONFIGS / f"{name}.yaml") for name in ("near_goal", "near_goal_red", "near_goal_noisy"))


def run_args(out, seed, train_config, evals, extra):
    return train.parse_args(FLAGS + list(extra) + ["--train-config-path", train_config, "--eval-config-paths", *evals,
                                                   "--seed", str(seed), "--out", str(out)])


def rows(out):
    with open(out / "metrics.jsonl") as f:
        return [{k: v for k, v in json.loads(line).items() if k not in TIMING} for line in f]


def only(row, labels):
    """An eval row with only the eval configs `labels` (and the train config's values)."""
    return dict(row, evals={k: v for k, v in row["evals"].items() if k in labels},
                diffs={k: v for k, v in row["diffs"].items() if k in labels})


def assert_padded_pack_logs_as_an_equal_one(tmp_path, run_args) -> list:
    """Trains a pack whose run b evaluates one config beside run a's two, and one whose run b evaluates two (the
    second real); each run logs the same in both, b without a row for the padding. `run_args(out, seed,
    train_config, evals)` makes a run's arguments. Returns b's rows in the padded pack."""
    train.train([run_args(tmp_path / "mixed/a", 3, NEAR_GOAL, [RED, NOISY]),
                 run_args(tmp_path / "mixed/b", 8, RED, [NEAR_GOAL])])
    train.train([run_args(tmp_path / "equal/a", 3, NEAR_GOAL, [RED, NOISY]),
                 run_args(tmp_path / "equal/b", 8, RED, [NEAR_GOAL, NOISY])])

    assert rows(tmp_path / "mixed/a") == rows(tmp_path / "equal/a")
    mixed_b, equal_b = rows(tmp_path / "mixed/b"), rows(tmp_path / "equal/b")
    assert [r["kind"] for r in mixed_b] == [r["kind"] for r in equal_b]
    for mixed, equal in zip(mixed_b, equal_b):
        if mixed["kind"] == "eval":
            assert list(mixed["evals"]) == ["near_goal.yaml"]  # no row for the padding
            assert mixed == only(equal, {"near_goal.yaml"})
        else:
            assert mixed == equal
    return mixed_b


@pytest.mark.parametrize("extra", [[], ["--use-frame-stack"]], ids=["frames", "frame_stack"])
def test_runs_evaluating_different_numbers_of_configs_log_what_they_log_otherwise(tmp_path, extra):
    mixed_b = assert_padded_pack_logs_as_an_equal_one(
        tmp_path, lambda out, seed, train_config, evals: run_args(out, seed, train_config, evals, extra))
    assert [r["kind"] for r in mixed_b] == ["eval", "train", "eval"]
