"""The trainer's plug-in points without environments: loading `module:attribute` references and their
errors, the agent contract's checks, the random-shift augmentation on hand-made frames, and the
TensorBoard tags of hand-made log rows (kage-ppo-baseline.md §4.3)."""
import math

import pytest
import torch

from kage.ppo import plugins, tensorboard_log
from kage.ppo.augment import PAD, random_shift
from kage.fields import EPISODE_METRICS

SHAPE = (16, 16, 3)


def test_references_are_checked_with_their_fix():
    with pytest.raises(SystemExit, match="write it as module:attribute"):
        plugins.load("kage.ppo.agent.nature_cnn", "--agent")
    with pytest.raises(SystemExit, match="cannot import 'no_such_module'.*PYTHONPATH"):
        plugins.load("no_such_module:make", "--agent")
    with pytest.raises(SystemExit, match="has no 'nature_cnnn'; did you mean 'nature_cnn'"):
        plugins.load("kage.ppo.agent:nature_cnnn", "--agent")
    with pytest.raises(SystemExit, match="has no 'xyz'; it defines TinyNet, make, wrong_shape"):
        plugins.load("lone_agent:xyz", "--agent")
    # A module's __all__ is what it offers: the shipped set's helpers are not named as augmentations.
    with pytest.raises(SystemExit, match="has no 'xyz'; it defines random_shift, random_crop, color_jitter, grayscale, "
                                         "random_conv, cutout_color, gaussian_noise, overlay$"):
        plugins.load_augment("kage.ppo.augment:xyz")
    with pytest.raises(SystemExit, match=r"must take \(obs, uniform\)"):
        plugins.load_augment("math:sqrt")
    with pytest.raises(SystemExit, match=r"write it as module:attribute \(e.g. kage.ppo.augment:random_shift\)"):
        plugins.load_augment("random_shift")


def test_a_module_that_fails_to_import_is_named_with_its_fix(tmp_path, monkeypatch):
    """The module is found but its import fails: its own error and where, or the import it lacks; a file path
    instead of a module's name is named as such."""
    (tmp_path / "syntax_error_aug.py").write_text("def aug(obs, uniform) return obs\n")
    (tmp_path / "raising_aug.py").write_text("raise RuntimeError('module-level failure')\n")
    (tmp_path / "lacking_aug.py").write_text("import no_such_dependency_xyz\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(SystemExit, match=r"importing 'syntax_error_aug' raised SyntaxError: .*syntax_error_aug.py, "
                                         r"line 1\); fix the module$"):
        plugins.load_augment("syntax_error_aug:aug")
    with pytest.raises(SystemExit, match=r"importing 'raising_aug' raised RuntimeError: module-level failure; fix"):
        plugins.load_augment("raising_aug:aug")
    with pytest.raises(SystemExit, match=r"importing 'lacking_aug' failed: No module named 'no_such_dependency_xyz'; "
                                         r"install what it imports"):
        plugins.load_augment("lacking_aug:aug")
    with pytest.raises(SystemExit, match=r"name a module, not a file: raising_aug:aug, with the directory"):
        plugins.load_augment(f"{tmp_path}/raising_aug.py:aug")


@pytest.mark.parametrize("reference, generators", [
    ("bad_plugins:global_torch_noise", "torch's global"), ("bad_plugins:global_numpy_flip", "numpy's global")])
def test_an_augmentation_drawing_from_a_global_generator_is_warned_of(reference, generators):
    warning = plugins.check_augment(plugins.load_augment(reference), reference, (2, 2, *SHAPE), "cpu")
    assert warning.startswith(f"--augment {reference} draws from {generators} random generator")
    assert "will not reproduce when resumed" in warning and "`uniform(shape)`" in warning


def test_the_shipped_augmentations_draw_from_their_own_streams():
    import kage.ppo.augment as shipped
    for name in shipped.__all__:
        reference = f"kage.ppo.augment:{name}"
        assert plugins.check_augment(plugins.load_augment(reference), reference, (2, 2, 44, 44, 3), "cpu") is None


def test_agents_are_built_in_the_pack_interface():
    packed = plugins.build_agent("kage.ppo.agent:nature_cnn", (44, 44, 3), 5, [1, 2], "cpu")
    logits, value = packed(torch.zeros((2, 7, 44, 44, 3), dtype=torch.uint8))
    assert logits.shape == (2, 7, 5) and value.shape == (2, 7)

    lone = plugins.build_agent("lone_agent:make", SHAPE, 8, [3], "cpu")
    logits, value = lone(torch.zeros((1, 4, *SHAPE), dtype=torch.uint8))
    assert logits.shape == (1, 4, 8) and value.shape == (1, 4)
    weight = lone.net.actor.weight
    assert lone.run_view(weight)[0].data_ptr() == weight.data_ptr()
    again = plugins.build_agent("lone_agent:make", SHAPE, 8, [3], "cpu")
    assert torch.equal(again.net.actor.weight, weight), "the factory runs under the run's seed"

    with pytest.raises(SystemExit, match="not packable"):
        plugins.build_agent("lone_agent:make", SHAPE, 8, [1, 2], "cpu")
    with pytest.raises(SystemExit, match=r"must map \[B, H, W, C\] -> \[B, A\], \[B\].*logits \[8\]"):
        plugins.build_agent("lone_agent:wrong_shape", SHAPE, 8, [1], "cpu")


def test_random_shift_moves_each_frame_by_its_own_offset():
    k, b, h, w = 2, 3, 12, 10
    frames = torch.arange(k * b * h * w * 3).remainder(251).to(torch.uint8).view(k, b, h, w, 3)
    # Uniforms 0, 0.5 and 0.999 give offsets -PAD, 0 and +PAD (floor(u * (2 PAD + 1)) - PAD).
    u = torch.tensor([[[0.0, 0.999], [0.5, 0.5], [0.999, 0.0]],
                      [[0.5, 0.0], [0.0, 0.0], [0.999, 0.999]]])
    shifted = random_shift(frames, lambda shape: u)
    assert shifted.shape == frames.shape and shifted.dtype == torch.uint8
    for run in range(k):
        for i in range(b):
            dy, dx = (int(v * (2 * PAD + 1)) - PAD for v in u[run, i])
            for r in range(h):
                for c in range(w):
                    source = frames[run, i, min(max(r + dy, 0), h - 1), min(max(c + dx, 0), w - 1)]
                    assert torch.equal(shifted[run, i, r, c], source), (run, i, r, c)
    assert torch.equal(shifted[0, 1], frames[0, 1])  # offset (0, 0)


def eval_result(base: float) -> dict:
    result = {m: base + i for i, m in enumerate(EPISODE_METRICS)}
    result.update({"return": base - 100, "length": 500.0, "episodes": 128})
    return result


DIFFS = ("return", "success", "progress", "success_once", "passed_distance", "jump_count")


def test_train_rows_keep_their_tags_and_gain_the_copies():
    row = {"kind": "train", "iteration": 3, "global_step": 3072, "charts/SPS": 100.0, "losses/value_loss": 0.5,
           "train/avg_progress": 0.25, "train/avg_success_once": 0.125}
    assert tensorboard_log.train_scalars(row) == {
        "charts/SPS": 100.0, "losses/value_loss": 0.5, "train/avg_progress": 0.25, "train/avg_success_once": 0.125,
        "charts/global_step": 3072.0, "main_metrics/avg_train_progress": 0.25, "main_metrics/avg_success_once": 0.125}


def test_one_eval_config_gets_the_tags_of_ppo_jax():
    row = {"kind": "eval", "global_step": 64, "train": eval_result(0.0), "evals": {"eval": eval_result(10.0)},
           "diffs": {"eval": {d: 1.0 + i for i, d in enumerate(DIFFS)}}}
    row["train"]["return"] = None  # every listed return exactly 0: NaN, as the original logs it
    tags = tensorboard_log.eval_scalars(row, "shape_black.yaml")
    assert math.isnan(tags.pop("eval/avg_train_episodic_return"))
    assert math.isnan(tags.pop("main_metrics/avg_train_episodic_return"))
    expected = {"eval/avg_train_episodic_length": 500.0, "eval/avg_eval_episodic_return": -90.0,
                "eval/avg_eval_episodic_length": 500.0,
                "eval/avg_train_config_x": 0.0, "eval/avg_train_config_y": 1.0, "eval/avg_train_config_vx_mean": 2.0,
                "eval/avg_train_config_vy_mean": 3.0, "eval/avg_train_config_passed_distance": 4.0,
                "eval/avg_train_config_progress": 5.0, "eval/avg_train_config_jump_count": 6.0,
                "eval/avg_train_config_success": 7.0, "eval/avg_train_config_success_once": 8.0,
                "eval/avg_eval_config_x": 10.0, "eval/avg_eval_config_y": 11.0, "eval/avg_eval_config_vx_mean": 12.0,
                "eval/avg_eval_config_vy_mean": 13.0, "eval/avg_eval_config_passed_distance": 14.0,
                "eval/avg_eval_config_progress": 15.0, "eval/avg_eval_config_jump_count": 16.0,
                "eval/avg_eval_config_success": 17.0, "eval/avg_eval_config_success_once": 18.0,
                "eval/train_eval_return_diff": 1.0, "eval/avg_train_eval_success_diff": 2.0,
                "eval/avg_train_eval_progress_diff": 3.0, "eval/avg_train_eval_success_once_diff": 4.0,
                "eval/avg_train_eval_passed_distance_diff": 5.0, "eval/avg_train_eval_jump_count_diff": 6.0,
                "main_metrics/avg_train_config_passed_distance": 4.0, "main_metrics/avg_train_config_jump_count": 6.0,
                "main_metrics/train_eval_return_diff": 1.0, "main_metrics/avg_train_eval_progress_diff": 3.0,
                "main_metrics/avg_train_eval_success_once_diff": 4.0,
                "main_metrics/avg_train_eval_passed_distance_diff": 5.0,
                "main_metrics/avg_train_eval_jump_count_diff": 6.0}
    assert tags == expected


def test_several_eval_configs_get_the_multi_config_tags():
    row = {"kind": "eval", "global_step": 64, "train": eval_result(0.0),
           "evals": {"a.yaml": eval_result(10.0), "b.yaml": eval_result(20.0)},
           "diffs": {"a.yaml": {d: 1.0 for d in DIFFS}, "b.yaml": {d: 2.0 for d in DIFFS}}}
    tags = tensorboard_log.eval_scalars(row, "train.yaml")
    assert tags["train.yaml/avg_episodic_return"] == -100.0 and tags["b.yaml/avg_config_success_once"] == 28.0
    assert tags["main_metrics/a.yaml/avg_config_jump_count"] == 16.0
    assert tags["b.yaml/train_eval_success_diff"] == 2.0 and "main_metrics/b.yaml/train_eval_success_diff" not in tags
    assert tags["main_metrics/a.yaml/train_eval_return_diff"] == 1.0
    # Per label: return, length, 9 metrics and 3 main_metrics copies; per eval label 6 diffs and 5 copies.
    assert len(tags) == 3 * (2 + 9 + 3) + 2 * (6 + 5)
