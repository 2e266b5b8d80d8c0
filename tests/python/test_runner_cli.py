"""The runner's command line and the Slurm script it writes: the flags kage.bench sets per run are refused in
every spelling (--flag=value, abbreviations), --seed is not taken for --seeds, #SBATCH values with spaces
stay one value, a newline in any value written into the script is refused rather than becoming a line of
its own, and a pair whose name would put its runs outside the benchmark directory is refused."""
import os
import subprocess
import sys

import pytest

from kage.bench import run, slurm
from support import NOISY_SKELETON, TINY_TRAINING

SUITE = """suite: names
pairs:
  - name: {name}
    axis: background
    train: {config}
    eval: {config}
"""


def write_suite(directory, name="alone"):
    directory.mkdir(parents=True, exist_ok=True)
    suite = directory / "suite.yaml"
    suite.write_text(SUITE.format(name=name, config=NOISY_SKELETON))
    return suite


@pytest.mark.parametrize("flags, match", [
    (["--eval-config-path=/elsewhere.yaml"], "--eval-config-path"),
    (["--eval-config-paths=/a.yaml"], "--eval-config-paths"),
    (["--train-config-path=/x.yaml"], "--train-config-path"),
    (["--seed", "4"], "--seed"),
    (["--seed=4"], "--seed"),
    (["--exp-name=x"], "--exp-name"),
    (["--eval-config-p", "/elsewhere.yaml"], "eval-config-p"),
    (["--see", "4"], "see"),
])
@pytest.mark.parametrize("command", ["run", "slurm"])
def test_per_run_flags_are_refused_in_every_spelling(tmp_path, flags, match, command):
    suite = write_suite(tmp_path)
    main = run.main if command == "run" else slurm.main
    with pytest.raises(SystemExit) as caught:
        main([str(suite), "--seeds", "1", "--out", str(tmp_path / "bench"), *TINY_TRAINING, *flags])
    assert caught.value.code != 0
    assert not (tmp_path / "bench" / "bench.json").exists()


def test_a_misspelt_trainer_flag_is_named_in_one_line(tmp_path):
    suite = write_suite(tmp_path)
    with pytest.raises(SystemExit) as caught:
        run.main([str(suite), "--seeds", "1", "--out", str(tmp_path / "bench"), *TINY_TRAINING, "--num-env", "2"])
    assert caught.value.code == "kage.bench: unknown flag --num-env; did you mean --num-envs?"
    assert not (tmp_path / "bench").exists()


@pytest.mark.parametrize("flags, message", [
    (["--augment", "kage.ppo.augment:colour_jitter"], "did you mean 'color_jitter'"),
    (["--agent", "kage.ppo.agent:nature_cn"], "--agent kage.ppo.agent:nature_cn"),
    (["--augment", "tests_plugin_that_is_not_there:fn"], "cannot import 'tests_plugin_that_is_not_there'"),
])
def test_a_plug_in_every_run_would_refuse_is_refused_before_any_run(tmp_path, flags, message):
    suite = write_suite(tmp_path)
    with pytest.raises(SystemExit) as caught:
        run.main([str(suite), "--seeds", "1", "--out", str(tmp_path / "bench"), *TINY_TRAINING, *flags])
    assert caught.value.code.startswith("kage.bench: ") and message in caught.value.code
    assert caught.value.code.endswith("kage.bench: no run started; fix the flag and run again")
    assert not (tmp_path / "bench").exists()  # nothing recorded: the corrected flag starts afresh


def test_a_schedule_stage_after_the_runs_end_is_refused_before_any_run(tmp_path):
    schedule = tmp_path / "late.yaml"
    schedule.write_text(f"- start: 1\n  configs: [{NOISY_SKELETON}]\n- start: 50\n  configs: [{NOISY_SKELETON}]\n")
    suite = tmp_path / "suite.yaml"
    suite.write_text(f"suite: late\npairs:\n  - name: late\n    axis: background\n    train: {{schedule: {schedule}}}\n"
                     f"    eval: {NOISY_SKELETON}\n")
    with pytest.raises(SystemExit) as caught:
        run.main([str(suite), "--seeds", "1", "--out", str(tmp_path / "bench"), *TINY_TRAINING])
    assert caught.value.code == (f"kage.bench: late: {schedule}:3: stages[1].start 50, but the run has 1 iterations: "
                                 "start it earlier, or raise --total-timesteps")
    assert not (tmp_path / "bench").exists()


def sbatch_lines(script: str):
    return [line for line in script.splitlines() if line.startswith("#SBATCH ")]


def write_script(tmp_path, *args, cwd=None):
    return subprocess.run([sys.executable, "-m", "kage.bench", "slurm", *args, *TINY_TRAINING], cwd=cwd or tmp_path,
                          capture_output=True, text=True, timeout=600,
                          env=dict(os.environ, PYTHONPATH=os.environ.get("PYTHONPATH", "")))


def test_sbatch_values_with_spaces_stay_one_value(tmp_path):
    suite = write_suite(tmp_path / "my suites")
    out = tmp_path / "my runs"
    done = write_script(tmp_path, str(suite), "--seeds", "1", "--out", str(out), "--job-name", "my job",
                        "--partition", "gpu", "--time", "4:00:00")
    assert done.returncode == 0, done.stderr
    lines = sbatch_lines((out / "slurm" / "kage_bench.sbatch").read_text())
    assert f'#SBATCH --output="{out}/slurm/task_%a.log"' in lines
    assert '#SBATCH --job-name="my job"' in lines
    assert "#SBATCH --partition=gpu" in lines and "#SBATCH --time=4:00:00" in lines


@pytest.mark.parametrize("flag", ["--job-name", "--partition", "--time"])
def test_a_newline_in_a_slurm_value_is_refused(tmp_path, flag):
    suite = write_suite(tmp_path)
    done = write_script(tmp_path, str(suite), "--seeds", "1", "--out", str(tmp_path / "bench"), flag,
                        "x\ntouch /tmp/injected")
    assert done.returncode != 0 and flag in done.stderr and "Traceback" not in done.stderr, done.stderr
    assert not (tmp_path / "bench" / "slurm" / "kage_bench.sbatch").exists()


def test_a_newline_in_out_the_suite_path_or_the_working_directory_is_refused(tmp_path):
    suite = write_suite(tmp_path)
    odd = write_suite(tmp_path / "odd\necho injected")
    cases = [([str(suite), "--out", str(tmp_path / "b\nrm -rf x")], tmp_path, "--out"),
             ([str(odd), "--out", str(tmp_path / "b2")], tmp_path, "suite"),
             ([str(suite), "--out", str(tmp_path / "b3")], tmp_path / "odd\necho injected", "working directory")]
    for args, cwd, what in cases:
        done = write_script(tmp_path, *args, "--seeds", "1", cwd=cwd)
        assert done.returncode != 0 and what in done.stderr and "Traceback" not in done.stderr, done.stderr
        assert "newline" in done.stderr


@pytest.mark.parametrize("name", ["/tmp/escaped", "../escaped", "a/../../escaped", "a//b", "./a", "a\\b"])
def test_a_pair_named_outside_the_benchmark_directory_is_refused(tmp_path, name):
    suite = write_suite(tmp_path, f'"{name}"')
    with pytest.raises(SystemExit, match="name"):
        run.main([str(suite), "--seeds", "1", "--out", str(tmp_path / "bench"), *TINY_TRAINING])
    assert not (tmp_path / "bench").exists()
    assert not (tmp_path / "escaped").exists() and not os.path.exists("/tmp/escaped/seed_1")


def test_a_misspelt_plug_in_of_gpu_runs_is_refused_without_a_gpu_here(tmp_path):
    # GPU runs' plug-ins are imported and named by the runner, not called (no CUDA context in the runner).
    suite = write_suite(tmp_path)
    flags = [f for f in TINY_TRAINING if f not in ("--device", "cpu")]
    with pytest.raises(SystemExit) as caught:
        run.main([str(suite), "--seeds", "1", "--out", str(tmp_path / "bench"), *flags, "--device", "cuda",
                  "--augment", "kage.ppo.augment:colour_jitter", "--dry-run"])
    assert "did you mean 'color_jitter'" in caught.value.code
    assert not (tmp_path / "bench").exists()


def test_a_plug_in_drawing_from_a_global_generator_is_warned_of_before_any_run(tmp_path, capsys):
    suite = write_suite(tmp_path)
    run.main([str(suite), "--seeds", "1", "--out", str(tmp_path / "bench"), *TINY_TRAINING,
              "--augment", "bad_plugins:global_numpy_flip"])
    err = capsys.readouterr().err
    warning = "kage.bench: warning: --augment bad_plugins:global_numpy_flip draws from numpy's global random generator"
    assert warning in err and err.index(warning) < err.index("[1/")  # before the first run starts


def test_a_run_that_fails_in_training_is_named_with_its_cause(tmp_path, capsys, monkeypatch):
    """An augmentation that passes the check on blank frames and fails on real ones: the run's line gives the log's
    last line (the trainer's one-line reason), and the summary says to fix it before rerunning."""
    here = os.path.dirname(os.path.abspath(__file__))  # where the trainer's process imports bad_plugins from
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [here, os.environ.get("PYTHONPATH")])))
    suite = write_suite(tmp_path)
    status = run.main([str(suite), "--seeds", "1", "--out", str(tmp_path / "bench"), *TINY_TRAINING,
                       "--augment", "bad_plugins:raises_on_real_frames"])
    err = capsys.readouterr().err
    assert status == 1
    assert "FAILED (exit 1): kage.ppo.train: --augment bad_plugins:raises_on_real_frames: on uint8 frames " in err
    assert "it raised ValueError: not on real frames; see " in err
    assert "kage.bench run: 1 run(s) failed: alone seed 1; fix what each log's last line says" in err
