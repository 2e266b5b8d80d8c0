"""What a user can get wrong ends in a message, not a traceback: a config with errors inside kage.ppo.train, an
--out that is a file or on a read-only or full file system (the OSErrors injected: CI runs as root, where
permission bits stop nothing), a truncated or garbage checkpoint, a run.json that is not JSON, and a damaged
bench_state.json, which must not abort kage.bench status for the other runs. Each message names the file,
what is wrong and the fix."""
import errno
import io
import json
import os
import shutil
import socket
import subprocess
import sys
import time

import pytest

from kage.bench import status
from kage.ppo import checkpoint, train
from support import CONFIGS, NOISY_SKELETON, ROOT, TINY_TRAINING, dead_pid

FLAGS = ["--train-config-path", NOISY_SKELETON, "--device", "cpu", "--threads", "1", "--total-timesteps", "64",
         "--num-envs", "2", "--num-steps", "16", "--num-minibatches", "2", "--update-epochs", "1",
         "--run-eval-every", "0", "--save-checkpoint-every", "1", "--seed", "6"]


def command(module, *args):
    return subprocess.run([sys.executable, "-m", module, *args], cwd=ROOT, capture_output=True, text=True, timeout=600)


def one_message(done, *names):
    """The command failed with a message (no traceback) whose last line names each of `names`."""
    assert done.returncode != 0, done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    last = done.stderr.strip().splitlines()[-1]
    for name in names:
        assert name in last, done.stderr
    return last


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    out = tmp_path_factory.mktemp("runs") / "run"
    assert train.main(FLAGS + ["--out", str(out)]) == 0
    return out


def test_a_config_with_errors(tmp_path):
    done = command("kage.ppo.train", *FLAGS, "--train-config-path", str(CONFIGS / "bad_value.yaml"),
                   "--out", str(tmp_path / "run"))
    one_message(done, "fix the config")
    assert "bad_value.yaml:" in done.stderr  # kagec's located diagnostic
    assert not (tmp_path / "run").exists()


def test_an_out_that_is_a_file(tmp_path):
    (tmp_path / "taken").write_text("a file")
    one_message(command("kage.ppo.train", *FLAGS, "--out", str(tmp_path / "taken")), str(tmp_path / "taken"),
                "--out")


def test_an_evaluation_out_that_is_a_file(tmp_path, finished):
    (tmp_path / "taken").write_text("a file")
    one_message(command("kage.ppo.evaluate", str(finished), "--config", NOISY_SKELETON, "--out", str(tmp_path / "taken"),
                        "--device", "cpu", "--episodes", "1", "--num-envs", "2"), str(tmp_path / "taken"), "--out")


def failing(error, under):
    """os.open and os.mkdir raising `error` for paths under `under`, and behaving otherwise."""
    real_open, real_mkdir = os.open, os.mkdir

    def check(path):
        if os.path.abspath(os.fspath(path)).startswith(str(under)):
            raise OSError(error, os.strerror(error), os.fspath(path))

    def fake_open(path, *args, **kwargs):
        check(path)
        return real_open(path, *args, **kwargs)

    def fake_mkdir(path, *args, **kwargs):
        check(path)
        return real_mkdir(path, *args, **kwargs)
    return fake_open, fake_mkdir


@pytest.mark.parametrize("error, fix", [(errno.EROFS, "writable"), (errno.ENOSPC, "free space"),
                                        (errno.EACCES, "writable")])
@pytest.mark.parametrize("existing", [False, True], ids=["new", "resume"])
def test_a_file_system_that_refuses_writes(tmp_path, monkeypatch, finished, error, fix, existing):
    out = tmp_path / "run"
    if existing:
        shutil.copytree(finished, out)
        (out / "summary.json").unlink()
    fake_open, fake_mkdir = failing(error, out)
    monkeypatch.setattr(os, "open", fake_open)
    monkeypatch.setattr(os, "mkdir", fake_mkdir)
    with pytest.raises(SystemExit) as caught:
        train.main(FLAGS + ["--out", str(out)])
    message = str(caught.value)
    assert "\n" not in message and str(out) in message and os.strerror(error) in message and fix in message, message


def test_a_full_disk_while_checkpointing(tmp_path, monkeypatch):
    out = tmp_path / "run"

    def full(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(SystemExit) as caught:
        train.main(FLAGS + ["--out", str(out)])
    message = str(caught.value)
    assert "\n" not in message and str(out) in message and "free space" in message, message


@pytest.mark.parametrize("damage", [lambda data: data[:len(data) // 2], lambda data: b"garbage" * 100, lambda data: b""],
                         ids=["truncated", "garbage", "empty"])
def test_a_damaged_checkpoint(tmp_path, finished, damage):
    run = tmp_path / "run"
    shutil.copytree(finished, run)
    latest = run / "checkpoints" / "latest.pt"
    latest.write_bytes(damage(latest.read_bytes()))
    one_message(command("kage.ppo.evaluate", str(run), "--config", NOISY_SKELETON, "--out", str(tmp_path / "eval"),
                        "--device", "cpu", "--episodes", "1", "--num-envs", "2"), "latest.pt")
    (run / "summary.json").unlink()
    one_message(command("kage.ppo.train", *FLAGS, "--out", str(run)), "latest.pt", "another --out")


@pytest.mark.parametrize("text", ["{not json", "[]", '{"args": 3}', ""], ids=["syntax", "list", "shape", "empty"])
def test_a_run_json_that_is_not_a_run_description(tmp_path, finished, text):
    run = tmp_path / "run"
    shutil.copytree(finished, run)
    (run / "run.json").write_text(text)
    one_message(command("kage.ppo.train", *FLAGS, "--out", str(run)), "run.json")
    (run / "summary.json").unlink()
    one_message(command("kage.ppo.train", *FLAGS, "--out", str(run)), "run.json")


def status_of(bench, runs):
    """kage.bench status of a benchmark whose unit U's seed 1 has the bench_state.json runs[U] (text as it is, else
    its JSON): the runs by category, and what it printed."""
    for unit, content in runs.items():
        (bench / "runs" / unit / "seed_1").mkdir(parents=True)
        state = bench / "runs" / unit / "seed_1" / "bench_state.json"
        state.write_text(content if isinstance(content, str) else json.dumps(content))
    (bench / "bench.json").write_text(json.dumps({"units": list(runs), "seeds": [1]}))
    out = io.StringIO()
    return status.status(str(bench), out), out.getvalue()


def test_a_damaged_bench_state_does_not_abort_status(tmp_path):
    bench = tmp_path / "bench"
    runs = {"good": {"state": "failed", "time": 0, "host": "h", "exit_code": 1, "log": "x.log", "error": "boom"},
            "list": [], "syntax": "{", "no_time": {"state": "running", "host": "h"},
            "text_time": {"state": "running", "time": "yesterday", "host": "h"}, "no_host": {"state": "stopped", "time": 0}}
    found, text = status_of(bench, runs)
    assert found["failed"] == ["good seed 1"]
    for unit in ("list", "syntax", "no_time", "text_time", "no_host"):
        line = next(line for line in text.splitlines() if f"{unit} seed 1" in line)
        assert "bench_state.json" in line and "rewritten" in line, line


def test_status_trusts_no_heartbeat_from_the_future_and_names_an_unknown_state(tmp_path):
    """A heartbeat 30 days ahead (another host's clock) read as fresh for ever: "running" indefinitely."""
    bench = tmp_path / "bench"
    runs = {"ahead": {"state": "running", "time": time.time() + 30 * 86400, "host": "elsewhere"},
            "odd": {"state": "exploded", "time": time.time(), "host": "elsewhere"}}
    found, text = status_of(bench, runs)
    assert found["interrupted"] == ["ahead seed 1", "odd seed 1"] and not found.get("running")
    assert "min in the future (another host's clock?)" in text and "state 'exploded', not one kage.bench run " \
        "writes" in text, text


def test_status_calls_a_fresh_running_run_interrupted_when_its_runner_here_is_gone(tmp_path):
    bench = tmp_path / "bench"
    here = socket.gethostname()
    runs = {"alive": {"state": "running", "time": time.time(), "host": here, "pid": os.getpid()},
            "killed": {"state": "running", "time": time.time(), "host": here, "pid": dead_pid()},
            "elsewhere": {"state": "running", "time": time.time(), "host": here + "-other", "pid": dead_pid()}}
    found, text = status_of(bench, runs)
    assert found["running"] == ["alive seed 1", "elsewhere seed 1"]  # another host's process cannot be looked at
    assert found["interrupted"] == ["killed seed 1"]
    line = next(line for line in text.splitlines() if "killed seed 1" in line)
    assert f"its runner (pid {runs['killed']['pid']}, this host) is gone (killed?)" in line, line


def test_status_gives_a_running_runs_steps_and_time_left(tmp_path):
    """From its last training row and run.json's total: 3,000,000 of 25,000,000 steps at 20,000 steps/s leave
    22,000,000 / 20,000 = 1,100 s, about 18 min. A run without a training row yet, or without run.json, says
    nothing of it."""
    bench = tmp_path / "bench"
    fresh = {"state": "running", "time": time.time(), "host": socket.gethostname(), "pid": os.getpid()}
    for unit in ("training", "starting", "unknown"):
        (bench / "runs" / unit / "seed_1").mkdir(parents=True)
        (bench / "runs" / unit / "seed_1" / "bench_state.json").write_text(json.dumps(fresh))
    for unit in ("training", "starting"):
        (bench / "runs" / unit / "seed_1" / "run.json").write_text(json.dumps({"args": {"total_timesteps": 25_000_000}}))
    rows = [{"kind": "train", "global_step": 2_000_000, "charts/SPS": 19_000.0},
            {"kind": "eval", "global_step": 3_000_000}, {"kind": "train", "global_step": 3_000_000, "charts/SPS": 20_000.0}]
    (bench / "runs" / "training" / "seed_1" / "metrics.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    (bench / "runs" / "unknown" / "seed_1" / "metrics.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    (bench / "bench.json").write_text(json.dumps({"units": ["training", "starting", "unknown"], "seeds": [1]}))
    out = io.StringIO()
    assert status.status(str(bench), out)["running"] == ["training seed 1", "starting seed 1", "unknown seed 1"]
    lines = {line.split(" seed 1")[0].strip(): line for line in out.getvalue().splitlines() if " seed 1:" in line}
    assert "training seed 1: step 3,000,000 of 25,000,000, about 18 min left at its 20,000 steps/s; no checkpoint" \
        in lines["training"], lines["training"]
    assert "step" not in lines["starting"] and "step" not in lines["unknown"]


def crafted(run, change):
    """The run's checkpoint with `change` applied, written with a valid digest (a file made to pass the
    integrity check: its content is what must be checked)."""
    latest = run / "checkpoints" / "latest.pt"
    state = checkpoint.load(str(latest))
    change(state)
    latest.write_bytes(checkpoint.encode(state))


def first_parameter(state):
    return next(iter(state["agent"]))


@pytest.mark.parametrize("change, names", [
    # copy_ broadcast a [1, ...] slice over the whole weight: the run went on with garbage
    (lambda s: s["agent"].update({first_parameter(s): s["agent"][first_parameter(s)][..., :1]}), ["/agent/"]),
    (lambda s: s["agent"].pop(first_parameter(s)), ["/agent", "lacks"]),
    (lambda s: s.update(iteration=10**6), ["iteration 1000000"]),  # was "done", with no training
    (lambda s: s.update(iteration="2"), ["/iteration"]),
    (lambda s: s.update(env_state=b"garbage"), ["/env_state"]),
    (lambda s: s.update(optimizer={}), ["/optimizer"]),
    (lambda s: s.update(next_done=s["next_done"][:1]), ["/next_done"]),
    (lambda s: s.update(history={}), ["/history"]),
    (lambda s: s.update(log={}), ["does not record"]),  # was read as "no checkpoint": the log emptied
    (lambda s: s["identity"].update(configs=[]), ["does not record"]),
], ids=["parameter-shape", "parameter-missing", "iteration-beyond", "iteration-text", "env-state", "optimizer",
        "loop-state", "history", "log", "identity"])
def test_a_checkpoint_whose_content_is_not_this_runs_is_refused_by_name(tmp_path, finished, change, names):
    run = tmp_path / "run"
    shutil.copytree(finished, run)
    (run / "summary.json").unlink()
    crafted(run, change)
    with pytest.raises(SystemExit) as caught:
        train.main(FLAGS + ["--out", str(run)])
    message = str(caught.value)
    assert "\n" not in message and "latest.pt" in message and "another --out" in message, message
    for name in names:
        assert name in message, message
    assert not (run / "summary.json").exists()


@pytest.mark.parametrize("change, name", [
    (lambda s: s["agent"].update({first_parameter(s): s["agent"][first_parameter(s)][..., :1]}), "/agent/"),
    (lambda s: s["agent_spec"].update(observation_shape="128x128"), "/agent_spec/observation_shape"),
    (lambda s: s["agent_spec"].update(num_actions=-1), "-1 actions"),
    (lambda s: s.update(iteration="2"), "/iteration"),
], ids=["parameter-shape", "observation-shape", "actions", "iteration"])
def test_scoring_a_checkpoint_whose_content_is_not_a_policy_is_refused_by_name(tmp_path, finished, change, name):
    run = tmp_path / "run"
    shutil.copytree(finished, run)
    crafted(run, change)
    one_message(command("kage.ppo.evaluate", str(run), "--config", NOISY_SKELETON, "--out", str(tmp_path / "eval"),
                        "--device", "cpu", "--episodes", "1", "--num-envs", "2"), "latest.pt", name)


@pytest.mark.parametrize("configs", ['{"train": 3}', '{"train": {}}', '{"train": {"path": 1, "spec_sha256": "x"}}'])
def test_a_run_json_whose_configs_are_not_described_is_refused(tmp_path, finished, configs):
    run = tmp_path / "run"
    shutil.copytree(finished, run)
    (run / "summary.json").unlink()
    (run / "run.json").write_text('{"args": {}, "configs": %s}' % configs)
    one_message(command("kage.ppo.train", *FLAGS, "--out", str(run)), "run.json", "config 'train'")


@pytest.mark.parametrize("content, name", [
    ("{not json", "not JSON"), ("[]", "not a pack file"), ('{"runs": [3]}', "not a pack file"),
    ('{"runs": []}', "not a pack file"), ('{"runs": [{"nope": 1}]}', "'nope' is not an argument"),
    ('{"runs": [{"num_envs": "2"}]}', "'num_envs'"), ('{"runs": [{"gamma": true}]}', "'gamma'"),
], ids=["syntax", "list", "run-not-object", "no-runs", "unknown", "text-count", "bool-number"])
def test_a_damaged_pack_file_is_refused_by_name(tmp_path, content, name):
    pack = tmp_path / "pack.json"
    pack.write_text(content)
    one_message(command("kage.ppo.train", "--pack", str(pack)), str(pack), name)


@pytest.mark.parametrize("flags, name", [
    (["--threads", "0"], "--threads"), (["--threads", "-1"], "--threads"),
    (["--num-envs", str(2**40)], "--num-envs"), (["--seed", "-5"], "--seed"),
    (["--num-envs", str(2**30), "--threads", "1"], "more than half"),  # make_vec's refusal, as one line
    (["--config", "/"], "config '/'"),  # a folder without a compiled config
])
def test_scoring_flags_and_batches_that_cannot_be_made_end_in_a_message(tmp_path, finished, flags, name):
    one_message(command("kage.ppo.evaluate", str(finished), "--config", NOISY_SKELETON, "--out", str(tmp_path / "e"),
                        "--device", "cpu", "--episodes", "1", "--num-envs", "2", *flags), name)


SUITE = "suite: names\npairs:\n  - name: alone\n    axis: background\n    train: {c}\n    eval: {c}\n"


@pytest.mark.parametrize("flags, names", [
    (["--suite", "kage_bench_typo"], ["--suite", "kage_bench_typo"]),  # before anything is made
    (["--suite", "kage_bench", "--out", "/proc/no-such-dir"], ["/proc/no-such-dir", "--out"]),
])
def test_scoring_a_suite_that_is_not_there_or_an_out_that_cannot_be_written(tmp_path, finished, flags, names):
    one_message(command("kage.bench", "score", str(finished), "--device", "cpu", "--episodes", "1",
                        "--out", str(tmp_path / "scores"), *flags), *names)
    assert not (tmp_path / "scores").exists()


@pytest.mark.parametrize("command_name", ["run", "slurm"])
def test_a_benchmark_out_that_is_a_file_ends_in_a_message(tmp_path, command_name):
    (tmp_path / "suite.yaml").write_text(SUITE.format(c=NOISY_SKELETON))
    (tmp_path / "taken").write_text("a file")
    one_message(command("kage.bench", command_name, str(tmp_path / "suite.yaml"), "--seeds", "1", "--out",
                        str(tmp_path / "taken"), *TINY_TRAINING), str(tmp_path / "taken"), "--out")


@pytest.mark.parametrize("name, text, found", [
    ("bench.json", "{", "not JSON"), ("bench.json", "[]", "not an object"),
    ("bench.json", '{"units": 3, "seeds": [1], "trainer_args": []}', "'units'"),
    ("bench.json", '{"units": ["alone"], "seeds": ["x"], "trainer_args": []}', "'seeds'"),
    ("suite.json", "{", "not JSON"), ("suite.json", '{"pairs": [{"pair": "alone"}]}', "spec hashes"),
], ids=["bench-syntax", "bench-list", "bench-units", "bench-seeds", "suite-syntax", "suite-shape"])
def test_a_damaged_benchmark_record_is_refused_by_name_before_training(tmp_path, name, text, found):
    (tmp_path / "suite.yaml").write_text(SUITE.format(c=NOISY_SKELETON))
    bench = tmp_path / "bench"
    bench.mkdir()
    (bench / name).write_text(text)
    done = command("kage.bench", "run", str(tmp_path / "suite.yaml"), "--seeds", "1", "--out", str(bench),
                   *TINY_TRAINING)
    one_message(done, str(bench / name), found, "another --out")
    assert not (bench / "runs").exists()
    if name == "bench.json":
        one_message(command("kage.bench", "status", str(bench)), str(bench / name), found)


def test_status_and_packing_read_a_damaged_latest_json_as_no_checkpoint(tmp_path):
    bench = tmp_path / "bench"
    for text in ("[]", '{"iteration": "3"}'):
        (bench / "runs" / "alone" / "seed_1" / "checkpoints").mkdir(parents=True, exist_ok=True)
        (bench / "runs" / "alone" / "seed_1" / "checkpoints" / "latest.json").write_text(text)
        (bench / "bench.json").write_text(json.dumps({"units": ["alone"], "seeds": [1], "trainer_args": []}))
        out = io.StringIO()
        assert status.status(str(bench), out)["not started"] == ["alone seed 1"], out.getvalue()
