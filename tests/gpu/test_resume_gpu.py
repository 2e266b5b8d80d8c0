"""A CUDA run (fused Adam, whose step count lives on the device) stopped after its checkpoint resumes from it:
the resumed run loads the Adam state onto the device, continues the step count, and ends with the uninterrupted
run's log rows and parameters, bit for bit. The runs use cuDNN's deterministic algorithms: under the trainer's
default autotuned ones, two uninterrupted runs already differ by up to 8e-5 in fc_weight after 16 Adam steps
(H100, 2026-11-26), as much as a resumed run does, so no tolerance could tell a faulty resume from rounding."""
import torch

from kage.ppo import checkpoint, train
from support import CONFIGS
from test_train_resume import rows

FLAGS = ["--train-config-path", str(CONFIGS / "near_goal.yaml"), "--seed", "3", "--device", "cuda",
         "--total-timesteps", "2048", "--num-envs", "8", "--num-steps", "64", "--num-minibatches", "2",
         "--update-epochs", "2", "--run-eval-every", "0", "--save-checkpoint-every", "2"]


def run(out, stop_after=None):
    train.train([train.parse_args(FLAGS + ["--out", str(out)])], stop_after=stop_after)


def test_cuda_run_resumes_its_fused_adam_state(tmp_path, deterministic):
    whole, resumed = tmp_path / "whole", tmp_path / "resumed"
    run(whole)
    run(resumed, stop_after=2)
    stopped = checkpoint.load(resumed / "checkpoints/latest.pt")
    assert stopped["iteration"] == 2 and stopped["optimizer_steps"] == 2 * 2 * 2
    run(resumed)
    a, b = (checkpoint.load(d / "checkpoints/latest.pt") for d in (whole, resumed))
    assert a["iteration"] == b["iteration"] == 4 and a["optimizer_steps"] == b["optimizer_steps"] == 16
    for name, p in a["agent"].items():
        assert torch.equal(b["agent"][name], p), f"{name}: max |resumed - whole| {(b['agent'][name] - p).abs().max()}"
    assert rows(resumed) == rows(whole)
    for name, state in a["optimizer"].items():
        assert b["optimizer"][name]["step"].item() == state["step"].item() == 16, name
