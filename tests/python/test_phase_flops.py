"""lab/tools/phase_flops.py: the network's FLOPs a frame and each phase's TFLOP/s from a `kage.bench speed` row,
and what a target rate with evaluations asks of the network's passes. Expected values are worked out by hand
from the spec's NatureCNN on 128 x 128 x 3 frames."""
import json
import sys

import pytest

from support import ROOT

sys.path.insert(0, str(ROOT / "lab/tools"))
import phase_flops  # noqa: E402 (lab/tools is no package)
from kage.ppo.args import Args  # noqa: E402

# Multiply-adds x 2 per layer: conv1 31x31 outputs x 32 channels x (3 x 8 x 8), conv2 14x14 x 64 x (32 x 4 x 4),
# conv3 12x12 x 64 x (64 x 3 x 3), the 9,216 -> 512 layer, the 8 action logits and the value.
CONV1 = 2 * 31 * 31 * 32 * 3 * 8 * 8  # 11,808,768
FORWARD = CONV1 + 2 * 14 * 14 * 64 * 32 * 4 * 4 + 2 * 12 * 12 * 64 * 64 * 3 * 3 + 2 * 9216 * 512 + 2 * 512 * 8 \
    + 2 * 512 * 1
BACKWARD = 2 * FORWARD - CONV1  # weight and input gradients, but none for the frames


def test_the_networks_flops_a_frame():
    assert FORWARD == 44_717_056
    assert phase_flops.network_flops() == (FORWARD, BACKWARD)


# K = 2 packed runs at 1 s an iteration; a run of 1,525 iterations and 32 evaluation points of 2 s: 1,589 s.
ROW = {"K": 2, "steps_per_s": 32768.0, "steps_per_s_with_evals": 32768 * 1525 / 1589, "iteration_s": 1.0,
       "eval_point_s": 2.0, "full_run_hours": 1589 / 3600,
       "shares": {"env": 0.05, "forward": 0.1, "augment": 0.0, "update_forward": 0.2, "backward": 0.5,
                  "optimizer": 0.05, "other": 0.1}}


def test_each_network_phase_gets_its_frames_flops_over_its_seconds():
    work = phase_flops.phase_work(ROW, Args(), 100_000, FORWARD, BACKWARD)
    steps = 2 * 16384  # K runs of 128 environments x 128 steps
    assert work["phases"]["forward"]["tflop"] == pytest.approx(steps * FORWARD / 1e12)
    assert work["phases"]["forward"]["tflops"] == pytest.approx(steps * FORWARD / 1e12 / 0.1)
    assert work["phases"]["update_forward"]["tflops"] == pytest.approx(3 * steps * FORWARD / 1e12 / 0.2)
    assert work["phases"]["backward"]["tflops"] == pytest.approx(3 * steps * BACKWARD / 1e12 / 0.5)


def test_the_target_bounds_the_iteration_and_the_networks_rate():
    work = phase_flops.phase_work(ROW, Args(), 100_000, FORWARD, BACKWARD)
    # 1,525 iterations of 32,768 steps at 100 k steps/s, less 32 evaluation points of 2 s, over 1,525 iterations.
    bound = (1525 * 32768 / 100_000 - 32 * 2.0) / 1525
    assert work["iteration_bound_s"] == pytest.approx(bound)
    assert work["rest_s"] == pytest.approx(0.2)  # environment, optimizer and other: 20 % of 1 s
    network = 2 * 16384 * (FORWARD + 3 * FORWARD + 3 * BACKWARD) / 1e12
    assert work["needed_tflops"] == pytest.approx(network / (bound - 0.2))


def test_a_line_that_is_no_speed_row_is_named(tmp_path, capsys):
    path = tmp_path / "speed.jsonl"
    path.write_text(json.dumps(ROW) + "\n" + json.dumps({"K": 2}) + "\n")
    with pytest.raises(SystemExit) as stop:
        phase_flops.main([str(path)])
    assert f"{path}:2: not a `kage.bench speed --json` row" in str(stop.value)
    assert "K = 2: 32,768 steps/s" in capsys.readouterr().out  # the first row was reported before it
