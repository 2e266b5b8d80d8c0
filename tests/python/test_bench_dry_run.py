"""kage.bench run --dry-run: the task table and each GPU's tasks, with nothing trained or written. The expected
tables are derived from the suite by hand: under --share-training KAGE-Bench's 34 pairs train 7 runs a seed, one a
train config: shape_black's evaluating 11 eval configs (its background, agent, distractors and layout pairs),
image_skeleton's 13 (filters, background/9, effects), skeleton_black's 6, and four evaluating 1 (background/4, /6,
/7 and /10). The task table groups them by eval configs, in the order the suite first names each count: 11, 1, 6,
13."""
import re

import pytest

from kage.bench import gpus, run
from kage.bench.units import Unit
from support import ROOT


def dry(capsys, *extra):
    status = run.main(["kage_bench", "--seeds", "1-5", "--share-training", "--out", "never-made", "--dry-run",
                       *extra])
    return status, capsys.readouterr().out


def test_the_table_and_the_gpus_tasks_with_nothing_written(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    status, out = dry(capsys, "--pack", "12", "--gpus", "0,1,2,3")
    assert status == 0
    assert not (tmp_path / "never-made").exists()
    lines = out.splitlines()
    assert lines[0].startswith("kage.bench run --dry-run: 5 tasks, 35 runs (--pack 12, --share-training)")
    # shape_black's 5 runs of 12 configs; the 20 runs of 2 configs in packs of 12; skeleton_black's 5 of 7;
    # image_skeleton's 5 of 14.
    assert [line.split(":")[0] + ": " + line.split(": ")[1].split(",")[0] for line in lines[1:6]] == [
        "task 0: 5 runs x 12 configs", "task 1: 12 runs x 2 configs", "task 2: 8 runs x 2 configs",
        "task 3: 5 runs x 7 configs", "task 4: 5 runs x 14 configs"]
    gpu_lines = [line for line in lines if line.startswith("  GPU ")]
    assert len(gpu_lines) == 4
    taken = [re.match(r"  GPU \d: tasks? ([\d, ]+), weight", line).group(1).split(", ") for line in gpu_lines]
    assert sorted(int(task) for tasks in taken for task in tasks) == [0, 1, 2, 3, 4]  # each task once
    # weights (per run 1 + evals + 40): 260, 504, 336, 235, 270; the heaviest, task 1, first and alone on its GPU,
    # then 2, 4 and 0 on the others, and 3 where 0 (the lightest of them) ends
    assert taken == [["1"], ["2"], ["4"], ["0", "3"]]


def test_only_the_tasks_named(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    status, out = dry(capsys, "--pack", "12", "--gpus", "0,1", "--tasks", "3,4")
    assert status == 0
    gpu_lines = [line for line in out.splitlines() if line.startswith("  GPU ")]
    assert gpu_lines[0].startswith("  GPU 0: task 4, weight 270") and gpu_lines[1].startswith("  GPU 1: task 3, ")


def test_tasks_joined_by_plus_weigh_as_one(capsys, tmp_path, monkeypatch):
    """--tasks 3+4 trains tasks 3 and 4 as one (one process, one pack): one GPU takes both, their weights summed."""
    monkeypatch.chdir(tmp_path)
    status, out = dry(capsys, "--pack", "12", "--gpus", "0,1", "--tasks", "0,3+4")
    assert status == 0
    gpu_lines = [line for line in out.splitlines() if line.startswith("  GPU ")]
    assert gpu_lines[0].startswith("  GPU 0: task 3+4, weight 505 (100 % ")  # 235 + 270
    assert gpu_lines[1].startswith("  GPU 1: task 0, weight 260 (51 % ")


def test_joined_tasks_that_cannot_share_a_pack_are_named(capsys, tmp_path, monkeypatch):
    """In kage_bench_loo at --pack 5, task 15 (distractors/4) trains on a mixture of 4 configs and task 16
    (distractors/5) on a mixture of 2 (the suite's description): joined, they train as two packs, and the dry run
    says so; tasks 12 and 13 (distractors/1 and /2, mixtures of 4) share one."""
    monkeypatch.chdir(tmp_path)
    status = run.main(["kage_bench_loo", "--seeds", "1-5", "--share-training", "--out", "never-made", "--dry-run",
                       "--pack", "5", "--gpus", "0", "--tasks", "12+13,15+16"])
    out = capsys.readouterr().out
    assert status == 0
    assert "task 12: 5 runs x 2 configs, weight 210: distractors/1" in out
    assert "tasks 15+16 train as 2 packs, one after the other, not as one" in out
    assert "tasks 12+13 train as" not in out


def test_a_task_that_cannot_be_one_pack_is_named(capsys, tmp_path, monkeypatch):
    """kage_bench_loo with one seed at --pack 5, in manifest order: filters/1-5 (mixtures of 9) are task 0, one pack;
    task 1 adds effects/1 (a mixture of 3) to filters/6-9, task 2 distractors/1-3 (of 4) to effects/2-3, task 3
    distractors/5-6 (of 2) to distractors/4: each trains as 2 packs, and the dry run says so without --gpus too."""
    monkeypatch.chdir(tmp_path)
    status = run.main(["kage_bench_loo", "--seeds", "1", "--out", "never-made", "--dry-run", "--pack", "5"])
    out = capsys.readouterr().out
    assert status == 0
    named = re.findall(r"kage.bench run: task (\d+) trains as (\d+) packs, one after the other", out)
    assert named == [("1", "2"), ("2", "2"), ("3", "2")]


def test_the_gpus_are_named_as_given(capsys, tmp_path, monkeypatch):
    """--gpus 3,1 trains on GPUs 3 and 1 (the runner's [gpu 3] and [gpu 1]): the dry run names them so, in that
    order, the first taking the heaviest task."""
    monkeypatch.chdir(tmp_path)
    status, out = dry(capsys, "--pack", "12", "--gpus", "3,1")
    assert status == 0
    assert "on 2 GPUs, longest first" in out
    gpu_lines = [line for line in out.splitlines() if line.startswith("  GPU ")]
    assert [line.split(":")[0] for line in gpu_lines] == ["  GPU 3", "  GPU 1"]
    assert gpu_lines[0].startswith("  GPU 3: tasks 1, 0, ")  # 504 and 260 against GPU 1's 336, 270 and 235


def test_hand_out_gives_each_task_to_the_first_free_worker():
    # Worker 0 takes 5 and worker 1 takes 4; worker 1 (free at 4) takes 3 (to 7); worker 0 (free at 5) takes 3
    # (to 8); worker 1 (free at 7) takes 2 (to 9).
    assert gpus.hand_out([5, 4, 3, 3, 2], [0, 0]) == ([[0, 3], [1, 2, 4]], [8, 9])
    assert gpus.hand_out([1], [0, 0, 0]) == ([[0], [], []], [1, 0, 0])
    assert gpus.hand_out([2], [3, 1]) == ([[], [0]], [3, 3])  # the worker free first takes it


@pytest.mark.parametrize("extra, message", [
    (["--task", "0"], "--dry-run shows every task: drop --task"),
    (["--gpus", "0,1", "--tasks", "99"], "--tasks 99"),
    (["--gpus", "0,1", "--tasks", "1+1"], "--tasks 1\\+1: the task table's indices are 0 to 34, each named once"),
])
def test_refusals(capsys, tmp_path, monkeypatch, extra, message):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit, match=message):
        dry(capsys, *extra)


def test_all_gpus_without_a_gpu_asks_for_a_list(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(gpus, "device_count", lambda: 0)
    with pytest.raises(SystemExit, match="give the lease's GPUs as a list, e.g. --gpus 0,1,2,3"):
        dry(capsys, "--gpus", "all")


def test_an_unknown_suite_is_named_with_the_shipped_ones(capsys, tmp_path, monkeypatch):
    """Not a file system's refusal of --out: the suite's name, where it was looked for, and the choices."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as stop:
        run.main(["suites/kage_bnch.yaml", "--seeds", "1", "--out", "never-made", "--dry-run"])
    text = str(stop.value)
    assert text.startswith("kage.bench run: suite 'suites/kage_bnch.yaml' is neither a path nor a shipped suite name")
    assert "near names: kage_bench" in text and "--out" not in text and ": ?:" not in text
    assert not (tmp_path / "never-made").exists()


def test_a_suite_configs_warnings_are_shown_once_before_any_run(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    near_goal = ROOT / "tests/python/configs/near_goal.yaml"
    (tmp_path / "inert.yaml").write_text(f"extends: {near_goal}\nbackground:\n  mode: black\n"
                                         "  parallax_factor: 0.8\n")
    (tmp_path / "suite.yaml").write_text(
        "suite: tiny\ndescription: two pairs\npairs:\n" + "".join(
            f"  - name: look/{i}\n    axis: background\n    description: a look\n    train: {near_goal}\n"
            f"    eval: inert.yaml\n" for i in (1, 2)))
    assert run.main([str(tmp_path / "suite.yaml"), "--seeds", "1", "--out", "never-made", "--dry-run"]) == 0
    err = capsys.readouterr().err
    assert err.count(f"kage.bench: warning: {tmp_path / 'inert.yaml'} has kagec's warnings") == 1  # once, two pairs
    assert f"{tmp_path / 'inert.yaml'}:4:3: warning: 'background.parallax_factor' has no effect" in err
    assert str(near_goal) + " has" not in err  # a clean config says nothing
    assert not (tmp_path / "never-made").exists()


def test_the_shipped_suite_has_no_config_warnings(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert run.main(["kage_bench", "--seeds", "1", "--out", "never-made", "--dry-run"]) == 0
    captured = capsys.readouterr()
    assert "kage.bench run --dry-run:" in captured.out and "warning" not in captured.err


def test_mixed_eval_counts_pack_runs_in_manifest_order(capsys, tmp_path, monkeypatch):
    """--mix-eval-counts: the 35 runs in the suite's order (shape_black at background/1, then background/4, /6, /7,
    skeleton_black at background/8, image_skeleton at background/9, background/10; seeds innermost) in tasks of
    12, whatever their eval counts. Weights, per run 1 + evals + 40: shape_black 52, skeleton_black 47,
    image_skeleton 54, a background pair 42."""
    monkeypatch.chdir(tmp_path)
    status, out = dry(capsys, "--pack", "12", "--mix-eval-counts")
    assert status == 0
    lines = out.splitlines()
    assert lines[0].startswith("kage.bench run --dry-run: 3 tasks, 35 runs (--pack 12, --share-training, "
                               "--mix-eval-counts)")
    assert [line.split(":")[0] + ": " + line.split(": ")[1] for line in lines[1:4]] == [
        # 5 shape_black, 5 background/4, 2 background/6: 5 x 52 + 7 x 42
        "task 0: 12 runs x 2-12 configs, weight 554",
        # 3 background/6, 5 background/7, 4 skeleton_black: 8 x 42 + 4 x 47
        "task 1: 12 runs x 2-7 configs, weight 524",
        # 1 skeleton_black, 5 image_skeleton, 5 background/10: 47 + 5 x 54 + 5 x 42
        "task 2: 11 runs x 2-14 configs, weight 527"]


def test_packs_of_mixes_eval_counts_only_when_asked():
    def job(name, evals, seed):
        pairs = [{"pair": f"{name}/{i}", "train": {"name": "t.yaml"}, "eval": {"name": f"e{i}.yaml"}}
                 for i in range(evals)]
        return Unit(name, "axis", pairs), seed, f"/none/{name}/{seed}"

    jobs = [job("a", 3, 1), job("b", 1, 1), job("a", 3, 2)]
    assert [[j[2] for j in p] for p in run.packs_of(jobs, 4)] == [["/none/a/1", "/none/a/2"], ["/none/b/1"]]
    assert [[j[2] for j in p] for p in run.packs_of(jobs, 4, mix_eval_counts=True)] == [
        ["/none/a/1", "/none/b/1", "/none/a/2"]]
