"""A resume proves that the checkpoint, the log and the arguments belong together, or refuses naming what
disagrees: another seed's checkpoint copied in, a weight or the environments' state altered inside the
checkpoint, run.json deleted and the run started again under other flags, a damaged row before the
checkpoint. Rows written after the checkpoint are dropped and written again, and the resume says so."""
import json
import shutil
import struct

import pytest

from kage.ppo import checkpoint, train
from support import NOISY_SKELETON

FLAGS = ["--train-config-path", NOISY_SKELETON, "--device", "cpu", "--threads", "1", "--total-timesteps", "192",
         "--num-envs", "2", "--num-steps", "16", "--num-minibatches", "2", "--update-epochs", "1",
         "--run-eval-every", "0", "--save-checkpoint-every", "2"]


def partial(out, seed, iterations):
    """A run of 6 iterations stopped after `iterations` of them (a checkpoint at each even one)."""
    train.train([train.parse_args(FLAGS + ["--seed", str(seed), "--out", str(out)])], stop_after=iterations)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    partial(root / "seed1", 1, 3)  # checkpoint at iteration 2, a log row of iteration 3 after it
    partial(root / "seed2", 2, 3)
    return root


def resume(out, seed=1, *extra):
    return train.main(FLAGS + ["--seed", str(seed), "--out", str(out), *extra])


def copy(runs, tmp_path, name="seed1"):
    shutil.copytree(runs / name, tmp_path / "run")
    return tmp_path / "run"


def refused(out, match, seed=1, *extra):
    with pytest.raises(SystemExit, match=match) as caught:
        resume(out, seed, *extra)
    return str(caught.value)


def test_an_untouched_run_resumes_and_says_which_rows_it_writes_again(runs, tmp_path, capsys):
    out = copy(runs, tmp_path)
    assert resume(out) == 0
    err = capsys.readouterr().err
    assert f"resuming {out} after iteration 2" in err
    assert "1 log row (iteration 3) written after the checkpoint of iteration 2 dropped; this run writes them again" in err
    rows = [json.loads(line) for line in open(out / "metrics.jsonl")]
    assert [r["iteration"] for r in rows] == [1, 2, 3, 4, 5, 6]


def test_another_seeds_checkpoint_is_refused(runs, tmp_path):
    out = copy(runs, tmp_path)
    shutil.copy(runs / "seed2" / "checkpoints" / "latest.pt", out / "checkpoints" / "latest.pt")
    message = refused(out, "seed")
    assert "latest.pt" in message and "2" in message


def flip(path, old: bytes, new: bytes):
    data = path.read_bytes()
    assert data.count(old) == 1, "the bytes to alter are found once in the file"
    path.write_bytes(data.replace(old, new))


def test_a_weight_altered_inside_the_checkpoint_is_refused(runs, tmp_path):
    out = copy(runs, tmp_path)
    state = checkpoint.load(out / "checkpoints" / "latest.pt")
    weight = state["agent"]["fc_weight"].reshape(-1)
    flip(out / "checkpoints" / "latest.pt", weight[:4].numpy().tobytes(),
         struct.pack("<f", -2.6e37) + weight[1:4].numpy().tobytes())
    refused(out, "latest.pt.*(damaged|content)")


def test_an_altered_environment_state_is_refused(runs, tmp_path):
    out = copy(runs, tmp_path)
    state, data = checkpoint.load(out / "checkpoints" / "latest.pt"), (out / "checkpoints" / "latest.pt").read_bytes()
    env_state = state["env_state"]
    body = next(env_state[i:i + 12] for i in range(len(env_state) // 2, len(env_state) - 12)
                if data.count(env_state[i:i + 12]) == 1 and len(set(env_state[i:i + 12])) > 4)  # past the header
    flip(out / "checkpoints" / "latest.pt", body, bytes(b ^ 0x5A for b in body))
    refused(out, "latest.pt.*(damaged|content)")


def test_a_deleted_run_json_with_other_flags_is_refused(runs, tmp_path):
    out = copy(runs, tmp_path)
    (out / "run.json").unlink()
    refused(out, "run.json", 1, "--learning-rate", "0.001")


def test_a_deleted_run_json_is_refused_even_with_the_same_flags(runs, tmp_path):
    out = copy(runs, tmp_path)
    (out / "run.json").unlink()
    refused(out, "run.json")


def test_a_damaged_row_before_the_checkpoint_is_refused_naming_its_line(runs, tmp_path):
    out = copy(runs, tmp_path)
    lines = (out / "metrics.jsonl").read_text().splitlines(keepends=True)
    lines[0] = lines[0][:20] + "#" + lines[0][21:]
    (out / "metrics.jsonl").write_text("".join(lines))
    refused(out, "metrics.jsonl.*line 1")


def test_a_log_cut_short_before_the_checkpoint_is_refused(runs, tmp_path):
    out = copy(runs, tmp_path)
    lines = (out / "metrics.jsonl").read_text().splitlines(keepends=True)
    (out / "metrics.jsonl").write_text(lines[0])
    refused(out, "metrics.jsonl")


def test_a_torn_last_row_after_the_checkpoint_is_dropped(runs, tmp_path):
    out = copy(runs, tmp_path)
    text = (out / "metrics.jsonl").read_text()
    (out / "metrics.jsonl").write_text(text[:-30])  # a write cut short by a kill: row 3 half written
    assert resume(out) == 0
    assert [json.loads(line)["iteration"] for line in open(out / "metrics.jsonl")] == [1, 2, 3, 4, 5, 6]
