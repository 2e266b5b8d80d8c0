"""One tiny training run (CPU, 40-step episodes) with a counting augmentation, videos and a recording
TensorBoard writer, then `python3 -m kage.ppo.evaluate` on its checkpoint: the augmentation is applied to the
update's minibatches only, never in an evaluation or a video; the scalars carry the original's tags;
kage.ppo.evaluate reproduces the run's last evaluation, writes the report's tables, refuses a config of
another observation size, and records GIFs of the episode's length in frames (or one per stride)."""
import csv
import json
import os
import subprocess
import sys

import pytest
from PIL import Image

import counting_augment
from kage.ppo import checkpoint, tensorboard_log, train, video
from support import NOISY_SKELETON, ROOT

EPISODE_LENGTH = 40  # noisy_short.yaml's episode_length
LABEL = "noisy_short.yaml"  # the eval config's label: its file name (§3.5)
FLAGS = ["--train-config-path", NOISY_SKELETON, "--eval-config-path", NOISY_SKELETON, "--seed", "5",
         "--device", "cpu", "--threads", "1", "--total-timesteps", "128", "--num-envs", "2", "--num-steps", "32",
         "--num-minibatches", "2", "--update-epochs", "1", "--run-eval-every", "1", "--eval-episodes", "2",
         "--eval-num-envs", "2", "--augment", "counting_augment:count", "--video-every", "2"]


class RecordingWriter:
    """Stands in for torch's SummaryWriter (no tensorboard package in CI): keeps what it is given."""
    scalars, texts = [], []

    def __init__(self, log_dir, purge_step=None):
        self.log_dir = log_dir

    def add_scalar(self, tag, value, step):
        RecordingWriter.scalars.append((tag, value, step))

    def add_text(self, tag, text):
        RecordingWriter.texts.append((tag, text))

    def flush(self):
        pass

    def close(self):
        pass


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The run directory; the augmentation's call count around each evaluation and video."""
    out = tmp_path_factory.mktemp("run") / "run"
    around = []

    def counted(function):
        def wrapper(*args, **kwargs):
            before = len(counting_augment.calls)
            result = function(*args, **kwargs)
            around.append((function.__name__, before, len(counting_augment.calls)))
            return result
        return wrapper

    saved = train.evaluation_rows, video.record_frames, tensorboard_log.summary_writer_class
    train.evaluation_rows, video.record_frames = counted(train.evaluation_rows), counted(video.record_frames)
    tensorboard_log.summary_writer_class = lambda: RecordingWriter
    try:
        assert train.main(FLAGS + ["--out", str(out)]) == 0
    finally:
        train.evaluation_rows, video.record_frames, tensorboard_log.summary_writer_class = saved
    return out, around


def evaluations(out):
    return [json.loads(line) for line in open(out / "metrics.jsonl") if '"kind": "eval"' in line]


def evaluate(*args, module="kage.ppo.evaluate"):
    return subprocess.run([sys.executable, "-m", module, *args, "--episodes", "2", "--num-envs", "2",
                           "--device", "cpu", "--threads", "1"], cwd=ROOT, capture_output=True, text=True, timeout=600)


def score(*args):
    return evaluate("score", *args, module="kage.bench")


def test_augmentation_only_on_update_minibatches(run):
    out, around = run
    # The check on blank frames before anything is written (2 frames, then 3 read at indices: one more than it
    # stores, so that a function that ignores the indices returns the wrong shape); then 2 iterations x 1 epoch x
    # 2 minibatches of 32 frames (drac, the default mode); 3 evaluations (iterations 0, 1, 2), and videos of both
    # configs at iterations 0 and 2, none of which calls it.
    assert counting_augment.calls == [2, 3] + [32] * 4
    assert [name for name, _, _ in around].count("evaluation_rows") == 3
    assert [name for name, _, _ in around].count("record_frames") == 4
    assert all(before == after for _, before, after in around), around


def test_tensorboard_scalars_under_the_original_tags(run):
    out, _ = run
    final = evaluations(out)[-1]
    logged = {(tag, step): value for tag, value, step in RecordingWriter.scalars}
    assert logged[("eval/avg_eval_config_passed_distance", 128)] == final["evals"][LABEL]["passed_distance"]
    assert logged[("eval/avg_train_eval_jump_count_diff", 128)] == final["diffs"][LABEL]["jump_count"]
    assert {step for tag, step in logged if tag == "eval/avg_train_config_success_once"} == {0, 64, 128}
    assert {step for tag, step in logged if tag == "losses/value_loss"} == {64, 128}
    assert logged[("charts/global_step", 64)] == 64.0
    assert [tag for tag, _ in RecordingWriter.texts] == ["hyperparameters"]
    assert "|augment|counting_augment:count|" in RecordingWriter.texts[0][1]


def test_trainer_videos_at_the_chosen_evaluation_points(run):
    out, _ = run
    assert sorted(os.listdir(out / "videos")) == [f"{LABEL}_iter_0.gif", f"{LABEL}_iter_2.gif", "train_iter_0.gif",
                                                  "train_iter_2.gif"]
    with Image.open(out / "videos" / "train_iter_2.gif") as gif:
        assert gif.format == "GIF" and gif.n_frames == EPISODE_LENGTH


def test_evaluate_configs_reproduces_the_last_evaluation(run, tmp_path):
    out, _ = run
    done = evaluate(str(out), "--config", NOISY_SKELETON, "--out", str(tmp_path / "eval"))
    assert done.returncode == 0, done.stderr
    with open(tmp_path / "eval" / "configs.csv") as f:
        (row,) = list(csv.DictReader(f))
    # The same seed (run seed + 10,000 + iteration), parameters and sampling stream as the run's last evaluation
    # of its eval config.
    final = evaluations(out)[-1]["evals"][LABEL]
    for metric in ("return", "passed_distance", "success_once", "jump_count"):
        assert float(row[metric]) == pytest.approx(final[metric], rel=1e-6), metric
    assert int(row["episodes"]) >= 2 and float(row["length"]) == EPISODE_LENGTH
    assert "| noisy_short.yaml |" not in (tmp_path / "eval" / "configs.md").read_text()  # the path is shown
    assert NOISY_SKELETON in (tmp_path / "eval" / "configs.md").read_text()


def test_checkpoint_without_agent_spec_is_rebuilt_from_its_run_directory(run, tmp_path):
    out, _ = run
    older = tmp_path / "older"
    for name in ("run.json", "configs/train.json"):
        (older / name).parent.mkdir(parents=True, exist_ok=True)
        (older / name).write_bytes((out / name).read_bytes())
    state = checkpoint.load(out / "checkpoints" / "latest.pt")
    del state["agent_spec"]  # as kage.ppo.train wrote checkpoints before --agent
    (older / "checkpoints").mkdir()
    (older / "checkpoints" / "latest.pt").write_bytes(checkpoint.encode(state))
    done = evaluate(str(older), "--config", NOISY_SKELETON, "--out", str(tmp_path / "eval"))
    assert done.returncode == 0, done.stderr
    with open(tmp_path / "eval" / "configs.csv") as f:
        (row,) = list(csv.DictReader(f))
    assert float(row["return"]) == pytest.approx(evaluations(out)[-1]["evals"][LABEL]["return"], rel=1e-6)


def test_evaluate_suite_writes_the_report_tables(run, tmp_path):
    out, _ = run
    (tmp_path / "black.yaml").write_text(f"extends: {NOISY_SKELETON}\nbackground:\n  mode: black\n")
    (tmp_path / "suite.yaml").write_text(
        "suite: tiny\ndescription: one pair\npairs:\n  - name: look/1\n    axis: background\n"
        f"    description: noise to black\n    train: {NOISY_SKELETON}\n    eval: black.yaml\n")
    done = score(str(out / "checkpoints" / "latest.pt"), "--suite", str(tmp_path / "suite.yaml"),
                 "--out", str(tmp_path / "eval"))
    assert done.returncode == 0, done.stderr
    for name in ("axes.md", "axes.csv", "pairs.md", "pairs.csv", "runs.csv", "report.md", "evaluation.json"):
        assert (tmp_path / "eval" / name).stat().st_size > 100, name
    with open(tmp_path / "eval" / "pairs.csv") as f:
        distance = next(r for r in csv.DictReader(f) if r["metric"] == "passed_distance")
    result = json.loads((tmp_path / "eval" / "evaluation.json").read_text())
    (pair,) = result["levels"]["pairs"]
    assert distance["pair"] == "look/1" and distance["n_seeds"] == "1"
    assert float(distance["train_mean"]) == pair["metrics"]["passed_distance"]["train"]["mean"]
    # The train side is evaluated as in training (seed + 20,000 + iteration): the run's last value.
    assert pair["metrics"]["passed_distance"]["train"]["mean"] == evaluations(out)[-1]["train"]["passed_distance"]


def test_evaluate_refuses_a_config_of_another_size(run, tmp_path):
    out, _ = run
    small = tmp_path / "small.yaml"
    small.write_text(f"extends: {NOISY_SKELETON}\nH: 64\nW: 64\n")
    done = evaluate(str(out), "--config", str(small), "--out", str(tmp_path / "eval"))
    assert done.returncode != 0
    assert f"{small}: its observations are 64x64x3 with 8 actions" in done.stderr
    assert "a policy for 128x128x3 with 8 actions" in done.stderr and "keys H and W" in done.stderr
    assert not (tmp_path / "eval" / "configs.csv").exists()


@pytest.mark.parametrize("stride, frames", [(1, EPISODE_LENGTH), (7, 6)])  # steps 7, 14, ..., 35 and the last, 40
def test_video_has_a_frame_per_step_or_per_stride(run, tmp_path, stride, frames):
    out, _ = run
    gif = tmp_path / "episode.gif"
    done = evaluate(str(out), "--config", NOISY_SKELETON, "--video", str(gif), "--video-stride", str(stride))
    assert done.returncode == 0, done.stderr
    assert gif.read_bytes()[:6] == b"GIF89a"
    assert f"({EPISODE_LENGTH} steps, {gif.stat().st_size / 1e6:.1f} MB)" in done.stderr
    with Image.open(gif) as image:
        assert image.n_frames == frames
        width, height = image.size
        assert height == 256 and width > 256  # the 128-pixel frame doubled, the metrics beside it
        image.seek(frames - 1)
        assert len(set(image.convert("RGB").getdata())) > 20  # a rendered frame and text, not a blank


def test_video_needs_one_config_and_a_known_format(run, tmp_path):
    out, _ = run
    two = evaluate(str(out), "--config", NOISY_SKELETON, NOISY_SKELETON, "--video", str(tmp_path / "a.gif"))
    assert two.returncode == 2 and "exactly one --config" in two.stderr
    other = evaluate(str(out), "--config", NOISY_SKELETON, "--video", str(tmp_path / "a.avi"))
    assert other.returncode != 0 and "write a .gif" in other.stderr


def test_a_large_video_says_how_to_make_it_smaller(tmp_path):
    from kage.ppo import video
    small, large = tmp_path / "small.gif", tmp_path / "large.gif"
    small.write_bytes(b"x" * 1000)
    large.write_bytes(b"x" * (video.LARGE_VIDEO + 1))
    assert video.size_note(str(small)) == "0.0 MB"
    assert video.size_note(str(large)) == ("10.5 MB; --video-stride K keeps every K-th step, and an .mp4 (ffmpeg) is "
                                           "many times smaller")
    mp4 = tmp_path / "large.mp4"
    large.rename(mp4)
    assert video.size_note(str(mp4)) == "10.5 MB; --video-stride K keeps every K-th step"
