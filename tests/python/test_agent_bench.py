"""Your own agent through `python3 -m kage.bench run` (CPU, tiny flags, a one-pair suite of 40-step
episodes): the example agent (the baseline with kage.ppo.augment:random_shift) trains packed and reports; a
plug-in network that cannot be packed trains its runs one at a time under --pack, saying so."""
import json
import os
import subprocess
import sys

from support import NOISY_SKELETON, ROOT

TINY = ["--total-timesteps", "128", "--num-envs", "2", "--num-steps", "32", "--num-minibatches", "2",
        "--update-epochs", "1", "--run-eval-every", "2", "--eval-episodes", "2", "--eval-num-envs", "2",
        "--device", "cpu", "--threads", "1"]


def bench(*args):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.environ["PYTHONPATH"], os.path.dirname(__file__)]))
    return subprocess.run([sys.executable, "-m", "kage.bench", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=900, env=env)


def one_pair_suite(folder):
    (folder / "black.yaml").write_text(f"extends: {NOISY_SKELETON}\nbackground:\n  mode: black\n")
    (folder / "suite.yaml").write_text(
        "suite: tiny\ndescription: one pair\npairs:\n  - name: look/1\n    axis: background\n"
        f"    description: noise to black\n    train: {NOISY_SKELETON}\n    eval: black.yaml\n")
    return str(folder / "suite.yaml")


def test_example_agent_trains_packed_and_reports(tmp_path):
    out = tmp_path / "shift"
    done = bench("run", one_pair_suite(tmp_path), "--seeds", "1-2", "--pack", "2", "--out", str(out), *TINY,
                 "--augment", "kage.ppo.augment:random_shift")
    assert done.returncode == 0, done.stderr
    assert len(json.loads((out / "packs" / "pack_0.json").read_text())["runs"]) == 2
    for seed in (1, 2):
        run_dir = out / "runs" / "look/1" / f"seed_{seed}"
        assert (run_dir / "summary.json").exists(), (out / "packs" / "pack_0.log").read_text()
        args = json.loads((run_dir / "run.json").read_text())["args"]
        assert args["augment"] == "kage.ppo.augment:random_shift" and args["agent"] == "kage.ppo.agent:nature_cnn"
        evals = [json.loads(line) for line in open(run_dir / "metrics.jsonl") if '"kind": "eval"' in line]
        assert [e["iteration"] for e in evals] == [0, 2] and evals[-1]["evals"]["eval"]["episodes"] >= 2
    reported = bench("report", str(out))
    assert reported.returncode == 0, reported.stderr
    pairs = (out / "report" / "pairs.md").read_text()
    assert "| look/1 | background | 2 |" in pairs


def test_unpackable_agent_runs_alone_under_pack(tmp_path):
    out = tmp_path / "lone"
    done = bench("run", one_pair_suite(tmp_path), "--seeds", "1-2", "--pack", "2", "--out", str(out), *TINY,
                 "--agent", "lone_agent:make")
    assert done.returncode == 0, done.stderr
    assert "--agent lone_agent:make cannot be packed" in done.stderr and "one at a time" in done.stderr
    assert not (out / "packs").exists()
    for seed in (1, 2):
        run_dir = out / "runs" / "look/1" / f"seed_{seed}"
        assert (run_dir / "summary.json").exists(), (run_dir / "train.log").read_text()
        assert json.loads((run_dir / "run.json").read_text())["args"]["agent"] == "lone_agent:make"


def test_bad_agent_reference_is_reported(tmp_path):
    done = bench("run", one_pair_suite(tmp_path), "--seeds", "1", "--pack", "2", "--out", str(tmp_path / "bad"),
                 *TINY, "--agent", "lone_agent:mak")
    assert done.returncode != 0
    assert "--agent lone_agent:mak" in done.stderr and "has no 'mak'; did you mean 'make'?" in done.stderr
