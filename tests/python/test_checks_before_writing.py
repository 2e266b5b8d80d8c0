"""kage.ppo.train checks every argument against its meaning (kage-ppo-baseline.md §2.1) and everything the
run needs (the device, the agent and augmentation modules, the batches' size) before it writes anything, so
that a corrected rerun is never refused as "started with other arguments"; nonsense values are refused
instead of training to "done"."""
import json

import pytest
import torch

from kage.ppo import train
from support import NOISY_SKELETON

BASE = ["--train-config-path", NOISY_SKELETON, "--seed", "3", "--threads", "1", "--total-timesteps", "32",
        "--num-envs", "2", "--num-steps", "16", "--num-minibatches", "2", "--update-epochs", "1",
        "--run-eval-every", "0"]


@pytest.mark.parametrize("flags", [
    ["--max-grad-norm", "-1"], ["--max-grad-norm", "0"], ["--max-grad-norm", "nan"],
    ["--gamma", "2"], ["--gamma", "-0.1"], ["--gamma", "nan"],
    ["--gae-lambda", "1.5"], ["--learning-rate", "inf"], ["--learning-rate", "0"], ["--learning-rate", "-1e-3"],
    ["--learning-rate", "nan"], ["--clip-coef", "0"], ["--clip-coef", "-0.2"], ["--ent-coef", "nan"],
    ["--ent-coef", "-0.01"], ["--vf-coef", "-1"], ["--vf-coef", "inf"], ["--update-epochs", "0"],
    ["--num-minibatches", "0"], ["--num-minibatches", "-2"], ["--total-timesteps", "-5"],
    ["--reward-clip-min", "1", "--reward-clip-max", "0"], ["--reward-clip-min", "nan"], ["--seed", "-1"],
    ["--seed", str(2**64)], ["--save-checkpoint-every", "-1"], ["--threads", "0"], ["--threads", "-2"],
    ["--num-envs", str(2**31)], ["--eval-num-envs", str(2**31)], ["--num-steps", str(2**40)],
    ["--asset-root", "/nonexistent-asset-root"], ["--augment", ""], ["--augment", " "],
], ids=lambda flags: " ".join(flags))
def test_nonsense_values_are_refused_before_anything_is_written(tmp_path, flags):
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as caught:
        train.main(BASE + ["--device", "cpu", "--out", str(out), *flags])
    assert caught.value.code != 0
    assert not out.exists()


def test_a_flag_error_is_one_line(capsys):
    """Not after argparse's usage block of every flag."""
    with pytest.raises(SystemExit) as caught:
        train.main(BASE + ["--device", "cpu", "--drac-coef", "abc"])
    err = capsys.readouterr().err
    assert caught.value.code == 2
    assert err.strip().splitlines() == ["python3 -m kage.ppo.train: error: argument --drac-coef: invalid float value: "
                                        "'abc' (python3 -m kage.ppo.train --help lists every flag)"]


@pytest.mark.parametrize("first, fix", [
    (["--agent", "no_such_module:make"], []),
    (["--agent", "kage.ppo.agent:no_such_factory"], []),
    (["--augment", "kage.ppo.augment:no_such_fn"], []),
    (["--num-envs", "100000000", "--num-minibatches", "1", "--total-timesteps", "1600000000"], []),
    (["--augment", "bad_plugins:float_frames"], []),
    (["--augment", "bad_plugins:nothing"], []),
    (["--augment", "bad_plugins:wrong_shape"], []),
    (["--augment", "bad_plugins:fewer_rows"], []),
    (["--augment", "bad_plugins:other_device"], []),
    (["--augment", "bad_plugins:raises"], []),
    (["--augment", "bad_plugins:exits"], []),
    (["--augment", "bad_plugins:ignores_images"], []),
    (["--augment", "bad_plugins:float_frames", "--augment-mode", "rollout"], []),
    (["--agent", "os:system"], []),
    (["--agent", "bad_plugins:no_parameters"], []),
    (["--agent", "bad_plugins:integer_logits"], []),
    (["--num-envs", "20000", "--num-minibatches", "1", "--total-timesteps", "2560000"], []),
], ids=["agent-module", "agent-factory", "augment", "memory", "augment-float", "augment-none", "augment-shape",
        "augment-rows", "augment-device", "augment-raises", "augment-exits", "augment-ignores-images",
        "augment-float-rollout", "agent-not-a-factory",
        "agent-no-parameters", "agent-integer-outputs", "rollout-buffer"])
def test_a_refused_run_writes_nothing_and_its_corrected_rerun_trains(tmp_path, capsys, first, fix):
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as refused:
        train.main(BASE + ["--device", "cpu", "--out", str(out), *first])
    message = str(refused.value.code)
    assert message.startswith("kage.ppo.train:") and "\n" not in message.strip(), message  # one line
    assert any(flag in message for flag in ("--agent", "--augment", "--num-envs", "memory")), message
    assert not out.exists()
    assert train.main(BASE + ["--device", "cpu", "--out", str(out), *fix]) == 0
    assert json.loads((out / "run.json").read_text())["args"]["device"] == "cpu"


def test_the_default_cuda_device_without_a_gpu_writes_nothing(tmp_path):
    if torch.cuda.is_available():
        pytest.skip("reported skip: this machine has a GPU, so --device cuda is not refused here")
    out = tmp_path / "run"
    with pytest.raises(SystemExit, match="--device cpu"):
        train.main(BASE + ["--out", str(out)])
    assert not out.exists()
    assert train.main(BASE + ["--device", "cpu", "--out", str(out)]) == 0


def test_the_benchmark_runner_refuses_the_default_cuda_device_without_a_gpu_before_writing(tmp_path):
    if torch.cuda.is_available():
        pytest.skip("reported skip: this machine has a GPU, so --device cuda is not refused here")
    from kage.bench import run
    out = tmp_path / "bench"
    with pytest.raises(SystemExit, match="torch sees no GPU here: add --device cpu"):
        run.main(["kage_bench", "--pairs", "background/1", "--seeds", "1", "--out", str(out), *BASE[4:]])
    assert not out.exists()


def test_a_pack_file_is_checked_as_the_command_line_is(tmp_path):
    runs = [vars(train.parse_args(BASE + ["--device", "cpu", "--out", str(tmp_path / f"run{i}")])) for i in (1, 2)]
    for run in runs:
        run["gamma"] = 2.0  # both: packed runs that differ in it are refused for that reason
    pack = tmp_path / "pack.json"
    pack.write_text(json.dumps({"runs": runs}))
    with pytest.raises(SystemExit):
        train.main(["--pack", str(pack)])
    assert not (tmp_path / "run1").exists() and not (tmp_path / "run2").exists()


def test_a_misspelt_shipped_config_is_named_with_the_nearest_names(tmp_path):
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as refused:
        train.main(BASE + ["--device", "cpu", "--out", str(out), "--eval-config-path", "kage_bench/background/1-evl"])
    message = str(refused.value.code)
    assert message.startswith("kage.ppo.train: (1-evl) config 'kage_bench/background/1-evl' is neither a path nor "
                              "a shipped config name"), message
    assert "near names: kage_bench/background/1-eval" in message
    assert not out.exists()


def test_an_augmentation_drawing_from_a_global_generator_trains_with_a_warning(tmp_path, capsys):
    out = tmp_path / "run"
    train.main(BASE + ["--device", "cpu", "--out", str(out), "--augment", "bad_plugins:global_torch_noise"])
    assert "kage.ppo.train: warning: --augment bad_plugins:global_torch_noise draws from torch's global random " \
           "generator" in capsys.readouterr().err
    assert (out / "summary.json").exists()


def test_a_run_that_fails_before_its_first_checkpoint_starts_over_with_the_fix(tmp_path, capsys):
    """An augmentation that passes the check on blank frames and fails in the first update stops its run in one
    line, before any checkpoint: nothing is lost, so a rerun with another augmentation starts the run over."""
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as failed:
        train.main(BASE + ["--device", "cpu", "--out", str(out), "--augment", "bad_plugins:raises_on_real_frames"])
    message = str(failed.value.code)
    assert message.startswith("kage.ppo.train: --augment bad_plugins:raises_on_real_frames: on uint8 frames ") and \
        message.endswith("it raised ValueError: not on real frames"), message
    assert not (out / "checkpoints" / "latest.pt").exists()
    capsys.readouterr()
    assert train.main(BASE + ["--device", "cpu", "--out", str(out), "--augment", "kage.ppo.augment:random_shift"]) == 0
    assert f"kage.ppo.train: {out} stopped before its first checkpoint" in capsys.readouterr().err
    recorded = json.loads((out / "run.json").read_text())["args"]
    assert recorded["augment"] == "kage.ppo.augment:random_shift"
    with pytest.raises(SystemExit, match="was started with other arguments"):  # a checkpoint now: a resume's rules
        train.main(BASE + ["--device", "cpu", "--out", str(out), "--augment", "kage.ppo.augment:grayscale"])
