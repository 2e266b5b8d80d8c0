"""--augment-mode: the update's loss in each mode worked by hand on a tiny network, and which frames each term
sees; which frames the policy acts on in a short training run of each mode (never augmented in an evaluation);
a pack of two equal to two lone runs and an exact resume with an augmentation in each mode; a run started before
the modes existed resumes in the mode it had; bad flags refused before anything is written."""
import dataclasses
import json
import math
import pathlib
import signal

import pytest
import torch

import recording_plugins
from kage.ppo import checkpoint, train
from kage.ppo.losses import drac_regularisers
from kage.util.stop import StopRequest
from support import NEAR_GOAL_RUNS as RUNS, NOISY_SKELETON


# ---- the loss on one minibatch, by hand ----

def sigmoid(x):
    return 1 / (1 + math.exp(-x))


class Means(torch.nn.Module):
    """One run: logits [m, 0] and value 2 m for a frame whose bytes average 255 m; records each call's means."""

    def __init__(self):
        super().__init__()
        self.a = torch.nn.Parameter(torch.ones(()))
        self.seen = []

    def forward(self, obs):
        m = obs.float().mean((-3, -2, -1)) / 255
        self.seen.append([round(v, 6) for v in m.flatten().tolist()])
        return torch.stack([self.a * m, torch.zeros_like(m)], -1), 2 * m


PLAIN = torch.stack([torch.full((4, 4, 3), 51), torch.full((4, 4, 3), 102)]).to(torch.uint8)[None]  # m 0.2, 0.4
AUGMENTED = 255 - PLAIN  # m 0.8, 0.6
ACTIONS = torch.tensor([[0, 1]])
ADVANTAGES, RETURNS = torch.tensor([[1.0, -0.5]]), torch.tensor([[1.0, 0.0]])
# The rollout's log-probabilities and values: the policy on the plain frames.
OLD_LOGPROB = torch.tensor([[math.log(sigmoid(0.2)), math.log(1 - sigmoid(0.4))]])
OLD_VALUE = torch.tensor([[0.4, 0.8]])
VAR_RETURNS = torch.tensor([0.25])  # the run's returns' variance over its batch: G_V in units of 0.5


def loss_of(mode, augmented):
    args = train.Args(train_config_path="x", augment="m:f", augment_mode=mode, drac_coef=0.1, norm_adv=False,
                      clip_vloss=False, ent_coef=0.0, vf_coef=0.5, clip_coef=0.2)
    agent = Means()
    loss, terms = train.minibatch_loss(agent, (PLAIN,), augmented, ACTIONS, OLD_LOGPROB, OLD_VALUE, ADVANTAGES,
                                       RETURNS, VAR_RETURNS, args, 0.0)
    return loss.item(), {k: v.item() for k, v in terms.items()}, agent.seen


def kl(m_p, m_q):
    """KL(softmax([m_p, 0]) || softmax([m_q, 0]))."""
    p, q = sigmoid(m_p), sigmoid(m_q)
    return p * math.log(p / q) + (1 - p) * math.log((1 - p) / (1 - q))


def test_drac_trains_ppo_on_the_plain_frames_and_pulls_the_augmented_outputs_to_them():
    loss, terms, seen = loss_of("drac", AUGMENTED)
    assert seen == [[0.2, 0.4], [0.8, 0.6]]  # PPO's forward on the plain frames, then the regularisers'
    # ratio 1 on the plain frames: pg = mean(-A) = -0.25; v = 0.5 mean((0.4 - 1)^2, (0.8 - 0)^2) = 0.25
    assert terms["policy_loss"] == pytest.approx(-0.25) and terms["value_loss"] == pytest.approx(0.25)
    assert terms["approx_kl"] == pytest.approx(0.0, abs=1e-7) and terms["clipfrac"] == 0.0
    g_pi = (kl(0.2, 0.8) + kl(0.4, 0.6)) / 2
    g_v = ((0.4 - 1.6) ** 2 + (0.8 - 1.2) ** 2) / 2 / 0.25  # (V(s) - V(aug s))^2 = 1.44 and 0.16, over 0.25
    assert terms["drac_policy"] == pytest.approx(g_pi, rel=1e-5) and terms["drac_value"] == pytest.approx(g_v)
    assert loss == pytest.approx(-0.25 + 0.5 * 0.25 + 0.1 * (g_pi + g_v), rel=1e-5)


def test_drac_regularisers_move_only_the_augmented_outputs():
    agent = Means()
    plain_logits, augmented_logits = (agent(frames)[0].detach().clone().requires_grad_() for frames in (PLAIN, AUGMENTED))
    plain_value, augmented_value = (torch.tensor([[0.4, 0.8]], requires_grad=True),
                                    torch.tensor([[1.6, 1.2]], requires_grad=True))
    policy, value = drac_regularisers(plain_logits, plain_value, augmented_logits, augmented_value,
                                      torch.tensor([4.0]))
    (policy + value).sum().backward()
    assert plain_logits.grad is None and plain_value.grad is None  # held fixed
    # d KL / d q's logits = q - p (softmax logits [m, 0]), over 2 frames: frame 0's first logit
    assert augmented_logits.grad[0, 0, 0].item() == pytest.approx((sigmoid(0.8) - sigmoid(0.2)) / 2, rel=1e-5)
    # d (V - V')^2 / 4 / d V' = 2 (V' - V) / 4, over 2 frames
    assert augmented_value.grad[0].tolist() == pytest.approx([(1.6 - 0.4) / 4, (1.2 - 0.8) / 4])


def test_update_compares_the_augmented_policy_with_the_rollouts_plain_one():
    loss, terms, seen = loss_of("update", AUGMENTED)
    assert seen == [[0.8, 0.6]]  # the augmented frames only
    ratio = [sigmoid(0.8) / sigmoid(0.2), (1 - sigmoid(0.6)) / (1 - sigmoid(0.4))]  # 1.30 and 0.90: not 1
    pg = sum(max(-a * r, -a * min(max(r, 0.8), 1.2)) for a, r in zip([1.0, -0.5], ratio)) / 2
    v = 0.5 * ((1.6 - 1.0) ** 2 + (1.2 - 0.0) ** 2) / 2
    assert terms["policy_loss"] == pytest.approx(pg, rel=1e-5) and terms["value_loss"] == pytest.approx(v, rel=1e-5)
    assert terms["clipfrac"] == 0.5  # the first ratio, 1.30, lies outside [0.8, 1.2]
    assert loss == pytest.approx(pg + 0.5 * v, rel=1e-5)
    assert "drac_policy" not in terms


def test_rollout_trains_on_the_frames_the_policy_acted_on():
    # Under rollout the buffer holds the augmented frames, so the update's frames are those: no second draw.
    loss, terms, seen = loss_of("rollout", None)
    assert seen == [[0.2, 0.4]]
    assert terms["policy_loss"] == pytest.approx(-0.25) and terms["value_loss"] == pytest.approx(0.25)
    assert loss == pytest.approx(-0.25 + 0.5 * 0.25)


# ---- which frames each call sees in a short run ----

FLAGS = ["--train-config-path", NOISY_SKELETON, "--eval-config-path", NOISY_SKELETON, "--seed", "2", "--device", "cpu",
         "--threads", "1", "--total-timesteps", "64", "--num-envs", "2", "--num-steps", "32", "--num-minibatches", "2",
         "--update-epochs", "1", "--run-eval-every", "1", "--eval-episodes", "3", "--eval-num-envs", "3",
         "--agent", "recording_plugins:make", "--augment", "recording_plugins:mark"]


@pytest.mark.parametrize("mode", ["drac", "rollout", "update"])
def test_evaluations_see_plain_frames_and_each_mode_its_own(tmp_path, mode):
    recording_plugins.calls.clear()
    assert train.main(FLAGS + ["--augment-mode", mode, "--out", str(tmp_path / "run")]) == 0
    assert recording_plugins.calls[0] == (2, 0, False)  # the agent's check on two blank frames
    calls = recording_plugins.calls[1:]
    evaluations = [c for c in calls if c[0] == 6]  # 3 environments on each of 2 configs
    rollout = [c for c in calls if c[0] == 2 and not c[2]]  # the rollout's steps and its bootstrap value
    update = [c for c in calls if c[2]]
    assert evaluations and all(marked == 0 for _, marked, _ in evaluations)
    assert len(rollout) == 33
    assert all(marked == (2 if mode == "rollout" else 0) for _, marked, _ in rollout)
    sizes = [(frames, marked) for frames, marked, _ in update]
    if mode == "drac":  # per minibatch: the plain frames for PPO, then the augmented ones for the regularisers
        assert sizes == [(32, 0), (32, 32)] * 2
    else:  # rollout: the buffer's augmented frames; update: augmented minibatches
        assert sizes == [(32, 32)] * 2
    logged = json.loads((tmp_path / "run" / "run.json").read_text())["args"]
    assert logged["augment_mode"] == mode and logged["drac_coef"] == 0.1


def test_an_augmentation_that_returns_a_view_of_its_frames_trains_in_each_mode(tmp_path):
    flags = [f for f in FLAGS if f != "recording_plugins:mark"]
    at = flags.index("--augment")
    flags[at + 1:at + 1] = ["recording_plugins:transposed"]
    for mode in ("drac", "rollout", "update"):
        assert train.main(flags + ["--augment-mode", mode, "--out", str(tmp_path / mode)]) == 0


def test_augment_mode_defaults_to_drac(tmp_path):
    assert train.main(FLAGS + ["--out", str(tmp_path / "run")]) == 0
    assert json.loads((tmp_path / "run" / "run.json").read_text())["args"]["augment_mode"] == "drac"
    rows = [json.loads(line) for line in open(tmp_path / "run" / "metrics.jsonl")]
    assert all("losses/drac_policy" in r and "losses/drac_value" in r for r in rows if r["kind"] == "train")


# ---- packs, resume and runs started before the modes ----

SMALL = dict(device="cpu", threads=1, total_timesteps=96, num_envs=2, num_steps=16, num_minibatches=2, update_epochs=2,
             run_eval_every=3, eval_episodes=2, eval_num_envs=2, save_checkpoint_every=1)
MODES = [("kage.ppo.augment:color_jitter", "drac"), ("kage.ppo.augment:random_conv", "rollout"),
         ("kage.ppo.augment:overlay", "update")]


def rows(path):
    timing = ("charts/SPS", "charts/SPS_update", "seconds")
    return [{k: v for k, v in json.loads(line).items() if k not in timing} for line in open(path / "metrics.jsonl")]


@pytest.mark.parametrize("augment, mode", MODES, ids=[m for _, m in MODES])
def test_a_pack_of_two_equals_two_lone_runs(tmp_path, augment, mode):
    lone = [train.Args(**SMALL, **run, augment=augment, augment_mode=mode, out=str(tmp_path / f"lone{i}"))
            for i, run in enumerate(RUNS)]
    packed = [dataclasses.replace(a, out=str(tmp_path / f"packed{i}")) for i, a in enumerate(lone)]
    for args in lone:
        train.train([args])
    train.train(packed)
    for i in range(2):
        a, b = rows(tmp_path / f"lone{i}"), rows(tmp_path / f"packed{i}")
        assert [(r["kind"], r["iteration"]) for r in a] == [(r["kind"], r["iteration"]) for r in b]
        for x, y in zip(a, b):  # episodes and evaluations exactly, losses to float32 rounding (test_packing.py)
            for key in x:
                if key.startswith("losses/") or key == "train/explained_variance":
                    assert y[key] == pytest.approx(x[key], rel=1e-4, abs=1e-6), key
                else:
                    assert x[key] == y[key], key
        ca = checkpoint.load(tmp_path / f"lone{i}" / "checkpoints/latest.pt")
        cb = checkpoint.load(tmp_path / f"packed{i}" / "checkpoints/latest.pt")
        assert ca["env_state"] == cb["env_state"]


class TermAfter(StopRequest):
    """A SIGTERM noted once the run has logged `iterations` training rows: the trainer checkpoints after that
    iteration and exits, as under kage.bench run's stop."""

    def __init__(self, log, iterations: int):
        super().__init__("test", "stopping")
        self.log, self.iterations = log, iterations

    @property
    def requested(self) -> bool:
        if self.signum is None and self.log.exists() and \
                sum('"kind": "train"' in line for line in open(self.log)) >= self.iterations:
            self.signum = signal.SIGTERM
        return self.signum is not None


def stop_after(args, iterations: int):
    with pytest.raises(SystemExit) as stopped:
        train.train([args], stop=TermAfter(pathlib.Path(args.out) / "metrics.jsonl", iterations))
    assert stopped.value.code == 128 + signal.SIGTERM


@pytest.mark.parametrize("augment, mode", MODES, ids=[m for _, m in MODES])
def test_a_stopped_run_resumes_exactly(tmp_path, augment, mode):
    args = train.Args(**SMALL, **RUNS[0], augment=augment, augment_mode=mode)
    train.train([dataclasses.replace(args, out=str(tmp_path / "whole"))])
    stopped = dataclasses.replace(args, out=str(tmp_path / "stopped"))
    stop_after(stopped, 2)
    assert not (tmp_path / "stopped" / "summary.json").exists()
    train.train([stopped])
    assert rows(tmp_path / "stopped") == rows(tmp_path / "whole")
    ca = checkpoint.load(tmp_path / "whole" / "checkpoints/latest.pt")
    cb = checkpoint.load(tmp_path / "stopped" / "checkpoints/latest.pt")
    for name in ca["agent"]:
        assert torch.equal(ca["agent"][name], cb["agent"][name]), name


def test_a_run_started_before_the_modes_resumes_in_update_mode(tmp_path):
    """A run directory written before --augment-mode existed records --augment alone; the same command, which now
    means drac, resumes it as the update-mode run it was, and ends as that run uninterrupted."""
    augment = "kage.ppo.augment:random_shift"
    whole = train.Args(**SMALL, **RUNS[0], augment=augment, augment_mode="update", out=str(tmp_path / "whole"))
    train.train([whole])
    old = dataclasses.replace(whole, out=str(tmp_path / "old"))
    stop_after(old, 2)
    # Make it a run of the earlier version: no augment_mode and drac_coef in run.json or the checkpoint.
    run_json = tmp_path / "old" / "run.json"
    recorded = json.loads(run_json.read_text())
    for key in ("augment_mode", "drac_coef"):
        del recorded["args"][key]
    run_json.write_text(json.dumps(recorded))
    latest = tmp_path / "old" / "checkpoints" / "latest.pt"
    state = checkpoint.load(latest)
    for key in ("augment_mode", "drac_coef"):
        del state["identity"]["args"][key]
    latest.write_bytes(checkpoint.encode(state))

    assert train.main(["--train-config-path", RUNS[0]["train_config_path"], "--eval-config-path",
                       RUNS[0]["eval_config_path"], "--seed", "3", "--augment", augment, "--out", str(tmp_path / "old"),
                       *[f"--{k.replace('_', '-')}={v}" for k, v in SMALL.items()]]) == 0
    assert rows(tmp_path / "old") == rows(tmp_path / "whole")


# ---- bad flags ----

BASE = ["--train-config-path", NOISY_SKELETON, "--device", "cpu", "--threads", "1", "--total-timesteps", "32",
        "--num-envs", "2", "--num-steps", "16", "--run-eval-every", "0"]


@pytest.mark.parametrize("flags, says", [
    (["--augment", "kage.ppo.augment:grayscale", "--augment-mode", "sideways"], "--augment-mode: invalid choice"),
    (["--augment", "kage.ppo.augment:grayscale", "--drac-coef", "-0.1"], "--drac-coef -0.1"),
    (["--augment", "kage.ppo.augment:grayscale", "--drac-coef", "nan"], "--drac-coef nan"),
    (["--augment-mode", "rollout"], "--augment-mode rollout needs --augment"),
    (["--drac-coef", "0.5"], "--drac-coef 0.5 weighs DrAC's regularisers, which run only with --augment under "
                             "--augment-mode drac (the default): drop --drac-coef"),
    (["--augment", "kage.ppo.augment:grayscale", "--augment-mode", "rollout", "--drac-coef", "0.5"],
     "(the default), not rollout: drop --drac-coef"),
    (["--augment", "kage.ppo.augment:grayscale", "--augment=kage.ppo.augment:color_jitter"],
     "--augment given 2 times: a run takes one augmentation; to combine several, write one function that calls each"),
], ids=["unknown-mode", "negative-coef", "nan-coef", "mode-without-augment", "coef-without-augment",
        "coef-under-rollout", "two-augments"])
def test_bad_mode_flags_are_refused_in_one_line_before_anything_is_written(tmp_path, capsys, flags, says):
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as caught:
        train.main(BASE + ["--out", str(out), *flags])
    assert caught.value.code == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert says in error, error
    assert not out.exists()
