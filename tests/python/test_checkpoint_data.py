"""Checkpoints hold data only: torch.load(weights_only=True) reads them, a pickle payload planted in one never
runs (not when scoring it, not when resuming from it), and kage.ppo.evaluate imports an agent module only
when the command line names it, not because the checkpoint does."""
import os
import subprocess
import sys

import pytest
import torch

from kage.ppo import checkpoint, train
from support import NOISY_SKELETON, ROOT

HERE = os.path.dirname(os.path.abspath(__file__))
FLAGS = ["--train-config-path", NOISY_SKELETON, "--eval-config-path", NOISY_SKELETON, "--seed", "4",
         "--device", "cpu", "--threads", "1", "--total-timesteps", "64", "--num-envs", "2", "--num-steps", "16",
         "--num-minibatches", "2", "--update-epochs", "1", "--run-eval-every", "1", "--eval-episodes", "1",
         "--eval-num-envs", "2"]
PLANTED = '''import os
from lone_agent import make
if os.environ.get("KAGE_TEST_MARKER"):
    open(os.environ["KAGE_TEST_MARKER"], "w").close()
'''


class Payload:
    """Unpickling it runs a shell command that leaves a file behind."""

    def __init__(self, marker):
        self.marker = str(marker)

    def __reduce__(self):
        return os.system, (f"touch '{self.marker}'",)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """A baseline run and a run of a plug-in agent (planted_agent, which notes each import in a file)."""
    root = tmp_path_factory.mktemp("runs")
    (root / "planted_agent.py").write_text(PLANTED)
    sys.path.insert(0, str(root))
    try:
        assert train.main(FLAGS + ["--out", str(root / "baseline")]) == 0
        assert train.main(FLAGS + ["--out", str(root / "planted"), "--agent", "planted_agent:make"]) == 0
    finally:
        sys.path.remove(str(root))
    return root


def command(module, *args, marker=None, path=()):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([*path, HERE, os.environ.get("PYTHONPATH", "")]))
    if marker:
        env["KAGE_TEST_MARKER"] = str(marker)
    return subprocess.run([sys.executable, "-m", module, *args], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=600)


def evaluate(run_dir, out, *extra, **kwargs):
    return command("kage.ppo.evaluate", str(run_dir), "--config", NOISY_SKELETON, "--out", str(out), "--episodes", "1",
                   "--num-envs", "2", "--device", "cpu", "--threads", "1", *extra, **kwargs)


def plant_payload(run_dir, marker):
    """Adds a pickled object to the checkpoint's top-level dict, as a hostile sharer could."""
    path = run_dir / "checkpoints" / "latest.pt"
    raw = torch.load(path, weights_only=False)
    raw["payload"] = Payload(marker)
    torch.save(raw, path)


def copy_run(source, target):
    for path in source.rglob("*"):
        if path.is_file():
            (target / path.relative_to(source)).parent.mkdir(parents=True, exist_ok=True)
            (target / path.relative_to(source)).write_bytes(path.read_bytes())


def test_a_checkpoint_is_read_by_the_data_only_loader(runs):
    torch.load(runs / "baseline" / "checkpoints" / "latest.pt", map_location="cpu", weights_only=True)


def test_scoring_never_runs_a_planted_payload(runs, tmp_path):
    shared = tmp_path / "shared"
    copy_run(runs / "baseline", shared)
    marker = tmp_path / "payload_ran"
    plant_payload(shared, marker)
    done = evaluate(shared, tmp_path / "eval")
    assert not marker.exists(), "the checkpoint's payload ran"
    assert done.returncode != 0
    assert "latest.pt" in done.stderr and "data only" in done.stderr and "Traceback" not in done.stderr, done.stderr


def test_resuming_never_runs_a_planted_payload(runs, tmp_path):
    shared = tmp_path / "shared"
    copy_run(runs / "baseline", shared)
    (shared / "summary.json").unlink()  # unfinished: a rerun resumes from the checkpoint
    marker = tmp_path / "payload_ran"
    plant_payload(shared, marker)
    done = command("kage.ppo.train", *FLAGS, "--out", str(shared))
    assert not marker.exists(), "the checkpoint's payload ran"
    assert done.returncode != 0
    assert "latest.pt" in done.stderr and "Traceback" not in done.stderr, done.stderr


def test_the_agent_a_checkpoint_names_is_imported_only_when_the_user_names_it(runs, tmp_path):
    marker = tmp_path / "imported"
    refused = evaluate(runs / "planted", tmp_path / "a", marker=marker, path=[str(runs)])
    assert not marker.exists(), "kage.ppo.evaluate imported the module the checkpoint named"
    assert refused.returncode != 0 and "--agent planted_agent:make" in refused.stderr, refused.stderr
    consented = evaluate(runs / "planted", tmp_path / "b", "--agent", "planted_agent:make", marker=marker,
                         path=[str(runs)])
    assert consented.returncode == 0, consented.stderr
    assert marker.exists()


def test_the_baseline_agent_needs_no_consent(runs, tmp_path):
    done = evaluate(runs / "baseline", tmp_path / "eval")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "eval" / "configs.csv").exists()


def test_a_checkpoint_of_the_earlier_pickled_format_is_read_as_data_or_refused_by_name(runs, tmp_path):
    older = tmp_path / "older"
    copy_run(runs / "baseline", older)
    torch.save(checkpoint.load(older / "checkpoints" / "latest.pt"), older / "checkpoints" / "latest.pt")
    done = evaluate(older, tmp_path / "eval")
    if int(torch.__version__.split(".")[0]) >= 2:  # its data-only loader reads pickled floats and bytes
        assert done.returncode == 0, done.stderr
    else:
        assert done.returncode != 0 and "torch 2.x" in done.stderr and "Traceback" not in done.stderr, done.stderr


def test_numpy_numbers_are_kept_as_their_values_and_other_objects_refused(tmp_path):
    import numpy as np

    path = tmp_path / "state.pt"
    state = {"agent": {}, "iteration": np.int64(7), "mean": np.float32(0.5), "flag": np.bool_(True)}
    path.write_bytes(checkpoint.encode(state))
    loaded = checkpoint.load(str(path))
    assert (loaded["iteration"], loaded["mean"], loaded["flag"]) == (7, 0.5, True)
    assert type(loaded["iteration"]) is int and type(loaded["flag"]) is bool
    with pytest.raises(TypeError, match="data only, not ndarray"):
        checkpoint.encode({"array": np.zeros(2)})
