"""The trainer on a mixture (--train-config-paths, --train-weights) and on a schedule (--train-schedule): what the
runs record, that a pack of mixture runs equals them alone, that a resume is exact across a stage boundary, and
that every refusal is one located line with nothing written (CPU, float32)."""
import dataclasses
import json
import os

import pytest

from kage.ppo import checkpoint, train
from support import CONFIGS, LONG_EPISODE, NEAR_GOAL
from test_packing import compare_values, rows

RED, NOISY = str(CONFIGS / "near_goal_red.yaml"), str(CONFIGS / "near_goal_noisy.yaml")
FLAGS = dict(device="cpu", threads=1, total_timesteps=256, num_envs=4, num_steps=16, num_minibatches=2,
             update_epochs=1, run_eval_every=2, eval_episodes=4, eval_num_envs=4, save_checkpoint_every=1)


def write_schedule(path, stages):
    lines = []
    for start, configs, weights in stages:
        lines += [f"- start: {start}", f"  configs: [{', '.join(configs)}]"]
        if weights:
            lines.append(f"  weights: [{', '.join(str(w) for w in weights)}]")
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_a_mixture_run_records_its_configs_and_evaluates_its_mixture(tmp_path):
    args = train.Args(**FLAGS, train_config_paths=[NEAR_GOAL, RED, NOISY], train_weights=[1, 1, 2],
                      eval_config_path=NEAR_GOAL, seed=5, out=str(tmp_path / "run"))
    runs = train.train([args])
    run_json = json.loads((tmp_path / "run" / "run.json").read_text())
    assert {label: c["path"] for label, c in run_json["configs"].items()} == {
        "train": NEAR_GOAL, "train.1": RED, "train.2": NOISY, "near_goal.yaml": NEAR_GOAL}
    assert run_json["stages"] == [{"start": 1, "configs": ["train", "train.1", "train.2"], "weights": [1.0, 1.0, 2.0]}]
    assert sorted(os.listdir(tmp_path / "run" / "configs")) == ["near_goal.yaml.json", "train.1.json", "train.2.json",
                                                                "train.json"]
    assert os.listdir(tmp_path / "run" / "certificates") == ["near_goal.yaml.json"]
    assert runs[0].env.counts == (1, 1, 2), "the training batch is split 1:1:2"
    assert runs[0].eval_envs["train"].counts == (1, 1, 2), "the train evaluation runs the same mixture"
    evaluations = [r for r in rows(tmp_path / "run") if r["kind"] == "eval"]
    assert [r["iteration"] for r in evaluations] == [0, 2, 4]
    assert all(set(r["evals"]) == {"near_goal.yaml"} for r in evaluations)


def test_a_mixture_of_one_config_twice_trains_as_that_config(tmp_path):
    """Halves of one batch running one config get the seeds a batch of that config gives them, so the run's
    rollouts, updates and evaluations are those of the config alone: the log is the same, row for row."""
    alone = train.Args(**FLAGS, train_config_path=NEAR_GOAL, eval_config_path=RED, seed=4, out=str(tmp_path / "a"))
    twice = dataclasses.replace(alone, train_config_path="", train_config_paths=[NEAR_GOAL, NEAR_GOAL],
                                out=str(tmp_path / "b"))
    train.train([alone])
    train.train([twice])
    ra, rb = rows(tmp_path / "a"), rows(tmp_path / "b")
    assert [(r["kind"], r["iteration"]) for r in ra] == [(r["kind"], r["iteration"]) for r in rb]
    for x, y in zip(ra, rb):
        compare_values(x, y, f"{x['kind']}:{x['iteration']}")


def test_a_pack_of_two_mixture_runs_equals_them_alone(tmp_path):
    runs = [dict(train_config_paths=[NEAR_GOAL, RED], train_weights=[3, 1], eval_config_path=RED, seed=3),
            dict(train_config_paths=[RED, NOISY], eval_config_path=NEAR_GOAL, seed=8)]
    lone = [train.Args(**FLAGS, **run, out=str(tmp_path / f"lone{i}")) for i, run in enumerate(runs)]
    packed = [dataclasses.replace(a, out=str(tmp_path / f"packed{i}")) for i, a in enumerate(lone)]
    for args in lone:
        train.train([args])
    train.train(packed)
    for a, b in zip(lone, packed):
        ra, rb = rows(tmp_path / os.path.basename(a.out)), rows(tmp_path / os.path.basename(b.out))
        assert [(r["kind"], r["iteration"]) for r in ra] == [(r["kind"], r["iteration"]) for r in rb]
        for x, y in zip(ra, rb):
            compare_values(x, y, f"{a.out}:{x['kind']}:{x['iteration']}")
        assert checkpoint.load(f"{a.out}/checkpoints/latest.pt")["env_state"] == \
            checkpoint.load(f"{b.out}/checkpoints/latest.pt")["env_state"], "the environments saw the same actions"


@pytest.mark.parametrize("stop_after", [2, 3])
def test_a_resume_is_exact_across_a_stage_boundary(tmp_path, capsys, stop_after):
    """Stage 2 starts at iteration 3 of 4: stopped after iteration 2 the resume enters it; stopped after 3 the
    resume loads environments of stage 2 from the checkpoint. Either way the run ends as one never stopped."""
    schedule = write_schedule(tmp_path / "curriculum.yaml", [(1, [NEAR_GOAL], None), (3, [NEAR_GOAL, RED], [1, 3])])
    # Evaluated at every iteration: a run stopped early (stop_after) evaluates at its last one, as a whole run does.
    whole = train.Args(**dict(FLAGS, run_eval_every=1), train_schedule=schedule, eval_config_path=RED, seed=11,
                       out=str(tmp_path / "whole"))
    train.train([whole])
    assert f"kage.ppo.train: {whole.out}: iteration 3: stage 2 of 2 starts (train, train.1)" in capsys.readouterr().err
    stopped = dataclasses.replace(whole, out=str(tmp_path / "stopped"))
    train.train([stopped], stop_after=stop_after)
    assert checkpoint.load(f"{stopped.out}/checkpoints/latest.pt")["iteration"] == stop_after
    train.train([stopped])
    assert [(r["kind"], r["iteration"]) for r in rows(tmp_path / "whole")] == \
        [(r["kind"], r["iteration"]) for r in rows(tmp_path / "stopped")]
    for x, y in zip(rows(tmp_path / "whole"), rows(tmp_path / "stopped")):
        compare_values(x, y, f"{x['kind']}:{x['iteration']}")
    a, b = checkpoint.load(f"{whole.out}/checkpoints/latest.pt"), checkpoint.load(f"{stopped.out}/checkpoints/latest.pt")
    assert a["env_state"] == b["env_state"]
    for name in a["agent"]:
        assert (a["agent"][name] == b["agent"][name]).all(), name
    run_json = json.loads((tmp_path / "whole" / "run.json").read_text())
    assert run_json["stages"] == [{"start": 1, "configs": ["train"], "weights": None},
                                  {"start": 3, "configs": ["train", "train.1"], "weights": [1.0, 3.0]}]


def test_the_same_schedule_by_another_path_resumes(tmp_path, monkeypatch):
    """A run started with --train-schedule s.yaml from its folder resumes when the same file is named by its full
    path: its configs and stages are what hold the run to it."""
    schedule = write_schedule(tmp_path / "s.yaml", [(1, [NEAR_GOAL], None), (3, [NEAR_GOAL, RED], [1, 3])])
    monkeypatch.chdir(tmp_path)
    first = train.Args(**FLAGS, train_schedule="s.yaml", eval_config_path=RED, seed=2, out=str(tmp_path / "run"))
    train.train([first], stop_after=1)
    train.train([dataclasses.replace(first, train_schedule=str(schedule))])
    assert (tmp_path / "run" / "summary.json").exists()


def test_a_changed_schedule_is_refused_on_resume(tmp_path):
    schedule = write_schedule(tmp_path / "s.yaml", [(1, [NEAR_GOAL], None), (3, [NEAR_GOAL, RED], [1, 3])])
    args = train.Args(**FLAGS, train_schedule=schedule, eval_config_path=RED, seed=2, out=str(tmp_path / "run"))
    train.train([args], stop_after=1)
    write_schedule(tmp_path / "s.yaml", [(1, [NEAR_GOAL], None), (2, [NEAR_GOAL, RED], [1, 3])])
    with pytest.raises(SystemExit, match="other training stages"):
        train.train([args])
    write_schedule(tmp_path / "s.yaml", [(1, [NEAR_GOAL], None), (3, [NEAR_GOAL, NOISY], [1, 3])])
    with pytest.raises(SystemExit, match=f"other configs \\(train.1: {RED} then, {NOISY} now\\)"):
        train.train([args])


def refusal(tmp_path, capsys, *flags):
    """The trainer's message lines when it refuses `flags` (in this process), and whether it wrote its --out."""
    out = tmp_path / "refused"
    argv = ["--device", "cpu", "--threads", "1", "--total-timesteps", "256", "--num-envs", "4", "--num-steps", "16",
            "--num-minibatches", "2", "--eval-config-path", RED, "--out", str(out), *flags]
    with pytest.raises(SystemExit) as refused:
        train.main(argv)
    message = refused.value.code if isinstance(refused.value.code, str) else ""
    assert refused.value.code != 0
    return (capsys.readouterr().err + message).strip().splitlines(), out.exists()


BAD = [
    (["--train-config-paths", NEAR_GOAL, LONG_EPISODE], "certify-mixture-latent"),
    (["--train-config-paths", NEAR_GOAL, str(CONFIGS / "small_frame.yaml")], "certify-mixture-shape"),
    (["--train-config-paths", NEAR_GOAL, RED, "--train-weights", "1", "-1"], "weights[1]=-1.0: a finite number >= 0"),
    (["--train-config-paths", NEAR_GOAL, RED, "--train-weights", "1", "nan"], "weights[1]=nan: a finite number >= 0"),
    (["--train-config-paths", NEAR_GOAL, RED, "--train-weights", "0", "0"], "all zero"),
    (["--train-config-paths", NEAR_GOAL, RED, "--train-weights", "1"], "1 given for 2 configs"),
    (["--train-config-paths", NEAR_GOAL, "no/such.yaml"], "no/such.yaml"),
    (["--train-weights", "1", "--train-config-path", NEAR_GOAL], "--train-weights splits --train-config-paths"),
    (["--train-config-path", NEAR_GOAL, "--train-config-paths", NEAR_GOAL, RED], "give one of"),
]


@pytest.mark.parametrize("flags,text", BAD, ids=[t for _, t in BAD])
def test_a_bad_mixture_is_refused_in_one_line_and_nothing_is_written(tmp_path, capsys, flags, text):
    lines, wrote = refusal(tmp_path, capsys, *flags)
    assert any(text in line for line in lines), lines
    assert not wrote


SCHEDULES = [
    ("- start: 1\n  configs: [{a}]\n- start: 5\n  configs: [{b}]\n- start: 3\n  configs: [{a}]\n",
     ":5: stages[2].start 3 is not after stages[1].start 5"),
    ("- start: 2\n  configs: [{a}]\n", ":1: stages[0].start is 2: the first stage starts at iteration 1"),
    ("- start: 1\n  configs: [{a}, nowhere.yaml]\n", ":2: stages[0].configs[1] 'nowhere.yaml': not found"),
    ("- start: 1\n  configs: [{a}, {b}]\n  weights: [1, -2]\n", ":3: stages[0].weights[1]=-2: a finite number >= 0"),
    ("- start: 1\n  configs: [{a}, {b}]\n  weights:\n    - 1\n    - -2\n",
     ":5: stages[0].weights[1]=-2: a finite number >= 0"),  # the item's own line
    ("- start: 1\n  configs: [{a}, {b}]\n  weights:\n", ":3: stages[0].weights: no value: a list of 2 non-negative"),
    ("- start: 1\n  configs: [{a}, {b}]\n  weights: [1, 1" + "0" * 400 + "]\n",
     ":3: stages[0].weights[1]=1000000000000000000000000000000000000...: a finite number >= 0"),
    ("- start: 1\n  configs: [{a}]\n  weight: [1]\n", ":3: stages[0]: unknown key 'weight'"),
    ("start: 1\n", ":1: a schedule is a YAML list of stages"),
    ("", ":1: a schedule is a YAML list of stages"),
    ("- start: 1\n  configs: [{a}]\n  configs: [{b}]\n", ":3: key 'configs' appears twice in one mapping"),
    ("- start: 1\n  configs: [{a}]\n- start: 9\n  configs: [{b}]\n", ":3: stages[1].start 9, but the run has 4 iterations"),
    ("- start: 1\n  configs: [{a}]\n- start: 2\n  configs: [{long}]\n", "certify-mixture-latent"),
    ("- start: 1\n  configs: [{a}]\n- start: 2\n  configs: [{long}]\n",
     "kage.ppo.train: the stages of {path}: train on configs of one hidden game"),
]


@pytest.mark.parametrize("text,message", SCHEDULES, ids=[m for _, m in SCHEDULES])
def test_a_bad_schedule_is_refused_in_one_located_line_and_nothing_is_written(tmp_path, capsys, text, message):
    path = tmp_path / "schedule.yaml"
    path.write_text(text.format(a=NEAR_GOAL, b=RED, long=LONG_EPISODE))
    lines, wrote = refusal(tmp_path, capsys, "--train-schedule", str(path))
    message = message.format(path=path)
    assert any(message in line for line in lines), lines
    if message.startswith(":"):  # the schedule's own line (kagec locates a certificate's in the config)
        assert any(line.startswith(f"kage.ppo.train: {path}:") for line in lines), lines
    assert not wrote
