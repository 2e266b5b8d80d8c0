"""The trainer's optional behaviours run end to end on the CPU: frame stacking, reward normalisation,
bootstrapping at truncation, the annealings, channels-last convolutions, greedy evaluation, several eval
configs; and flags it cannot honour are refused with the fix."""
import json

import pytest

from kage.ppo import args as trainer_args, train
from support import CONFIGS, LONG_EPISODE, NEAR_GOAL

OPTIONS = ["--use-frame-stack", "--normalize-reward", "--bootstrap-truncation", "--anneal-lr", "--ent-coef-anneal",
           "--channels-last", "--eval-greedy"]


def test_every_option_at_once(tmp_path):
    out = tmp_path / "run"
    args = train.parse_args([
        "--train-config-path", NEAR_GOAL, "--eval-config-paths", str(CONFIGS / "near_goal_red.yaml"),
        str(CONFIGS / "noisy_short.yaml"), "--eval-config-labels", "red", "noisy", "--seed", "2", "--device", "cpu",
        "--threads", "1", "--total-timesteps", "192", "--num-envs", "2", "--num-steps", "16", "--num-minibatches", "2",
        "--update-epochs", "1", "--run-eval-every", "3", "--eval-episodes", "2", "--eval-num-envs", "2",
        "--out", str(out), *OPTIONS])
    train.train([args])
    rows = [json.loads(line) for line in open(out / "metrics.jsonl")]
    train_rows = [r for r in rows if r["kind"] == "train"]
    assert [r["iteration"] for r in train_rows] == list(range(1, 7))
    lrs = [r["charts/learning_rate"] for r in train_rows]
    assert lrs[0] == 5e-4 and lrs == sorted(lrs, reverse=True) and lrs[-1] > 0
    assert train_rows[-1]["charts/entropy_coef"] < 0.01
    evals = [r for r in rows if r["kind"] == "eval"]
    assert [e["iteration"] for e in evals] == [0, 3, 6] and set(evals[-1]["evals"]) == {"red", "noisy"}
    summary = json.loads((out / "summary.json").read_text())
    assert summary["evaluations"] == 3 and "diff/noisy/success_once" in summary["stats"]


def test_triton_conv_without_triton(monkeypatch, capsys):
    """Where triton is not installed (as on the CPU machines), --triton-conv is refused before training."""
    real_find_spec = trainer_args.importlib.util.find_spec
    monkeypatch.setattr(trainer_args.importlib.util, "find_spec",
                        lambda name, *rest: None if name == "triton" else real_find_spec(name, *rest))
    with pytest.raises(SystemExit):
        train.parse_args(["--train-config-path", NEAR_GOAL, "--device", "cuda", "--fused-input", "--triton-conv"])
    assert "--triton-conv needs the triton package" in capsys.readouterr().err


@pytest.mark.parametrize("flags, message", [
    (["--device", "cpu", "--bf16"], "--bf16 and --cuda-graph are for --device cuda"),
    (["--device", "cpu", "--triton-conv", "--fused-input"], "--triton-conv is for --device cuda"),
    (["--triton-conv"], "--triton-conv runs conv1 on --fused-input's 4x4 blocks: add --fused-input"),
    (["--num-minibatches", "3"], "must divide the batch"),
    (["--eval-config-paths", "a", "b", "--eval-config-labels", "x"], "gives 1 labels for 2 eval configs"),
    (["--total-timesteps", "10"], "less than one batch"),
    (["--eval-num-envs", "0"], "--eval-num-envs 0 must be positive while evaluation is on"),
    (["--eval-episodes", "0"], "to train without evaluations, pass --run-eval-every 0"),
    (["--run-eval-every", "-1"], "--run-eval-every -1 must not be negative (0: no evaluation)"),
])
def test_flags_it_cannot_honour(flags, message, capsys):
    with pytest.raises(SystemExit):
        train.parse_args(["--train-config-path", NEAR_GOAL, *flags])
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("flags, message", [
    (["--total-timestep", "5"], "unknown flag --total-timestep; did you mean --total-timesteps?"),
    (["--num-envs=4", "--xyz=1"], "unknown flag --xyz: python3 -m kage.ppo.train --help lists the flags"),
    (["--device", "cpu", "7"], "unexpected argument '7': every argument is a --flag or a flag's value"),
])
def test_an_unknown_argument_is_named_in_one_line(flags, message):
    with pytest.raises(SystemExit) as caught:
        train.parse_args(["--train-config-path", NEAR_GOAL, *flags])
    assert caught.value.code == f"python3 -m kage.ppo.train: {message}"


def test_episodes_shorter_than_a_rollout_are_all_counted(tmp_path):
    # 40-step episodes, 64-step rollouts: an environment can end two episodes in one rollout, so the
    # trainer reads the episode metrics after every step (the benchmark's 500-step episodes are read once).
    out = tmp_path / "run"
    train.train([train.parse_args([
        "--train-config-path", NEAR_GOAL, "--seed", "4", "--device", "cpu", "--threads", "1", "--total-timesteps", "128",
        "--num-envs", "1", "--num-steps", "64", "--num-minibatches", "2", "--update-epochs", "1",
        "--run-eval-every", "0", "--out", str(out)])])
    rows = [json.loads(line) for line in open(out / "metrics.jsonl")]
    assert [r["iteration"] for r in rows] == [1, 2]
    # Episodes end at steps 40, 80 and 120: one in the first rollout, two in the second.
    assert all(r["train/avg_completed_episodic_length"] == 40 for r in rows)
    assert all("train/avg_passed_distance" in r for r in rows)
    assert (out / "summary.json").exists()


def test_an_eval_config_that_changes_the_hidden_game_is_warned_of(tmp_path, capsys):
    out = tmp_path / "run"
    train.train([train.parse_args([
        "--train-config-path", NEAR_GOAL, "--eval-config-path", LONG_EPISODE, "--device", "cpu", "--threads", "1",
        "--total-timesteps", "64", "--num-envs", "1", "--num-steps", "64", "--num-minibatches", "2",
        "--update-epochs", "1", "--run-eval-every", "0", "--out", str(out)])])
    err = capsys.readouterr().err
    assert f"kage.ppo.train: warning: eval config long_episode.yaml ({LONG_EPISODE})" in err
    assert "is not certified against the train config: latent keys change (the hidden game differs)" in err
    assert "(certificates/long_episode.yaml.json)" in err
    assert json.loads((out / "certificates" / "long_episode.yaml.json").read_text())["certified"] is False


def test_help_shows_each_default_once(capsys):
    with pytest.raises(SystemExit):
        train.parse_args(["--help"])
    text = " ".join(capsys.readouterr().out.split())  # argparse wraps lines
    assert "environment steps of the run (default: 25000000)" in text
    assert "(alpha_r; 0.1 in Raileanu et al. 2021) (default: 0.1)" in text
    assert "(default: None)" not in text and "(default: [])" not in text
    assert "CPU threads (default: all cores) (default" not in text  # a help that names its default keeps its own
