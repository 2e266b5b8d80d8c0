"""A run's non-finite losses are logged as null with one warning, in metrics.jsonl and TensorBoard, instead
of ending the process (and with it every run of its pack)."""
import json
import math

from kage.ppo.rundir import Progress, RunDir
from kage.ppo.tensorboard_log import Board, summary_writer_class
from kage.util.lock import DirectoryLock


def test_non_finite_values_are_logged_as_null(tmp_path, capsys):
    run = RunDir(str(tmp_path), {}, DirectoryLock(str(tmp_path), "run", "test"))
    run.log({"kind": "train", "iteration": 7, "losses/loss": math.nan, "losses/value_loss": math.inf,
             "losses/entropy": 0.5})
    run.log({"kind": "train", "iteration": 8, "losses/loss": math.nan, "losses/entropy": 0.25})
    rows = [json.loads(line) for line in open(tmp_path / "metrics.jsonl")]
    assert rows[0] == {"kind": "train", "iteration": 7, "losses/loss": None, "losses/value_loss": None,
                       "losses/entropy": 0.5}
    assert rows[1] == {"kind": "train", "iteration": 8, "losses/loss": None, "losses/entropy": 0.25}
    warnings = capsys.readouterr().err.splitlines()
    assert warnings == [f"kage.ppo.train: warning: {tmp_path}: losses/loss, losses/value_loss not finite at "
                        "iteration 7; such values are logged as null"]


def test_a_null_loss_reaches_tensorboard_as_nan(tmp_path):
    """A collapsed run logged approx_kl as null at iteration 1187 of 25 M steps, and the TensorBoard writer's
    float(None) ended its pack of six."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator
    board = Board(str(tmp_path), summary_writer_class(), "train", {})
    board.write({"kind": "train", "iteration": 1187, "global_step": 4096, "losses/approx_kl": None,
                 "losses/loss": 349.5})
    board.close()
    events = EventAccumulator(str(tmp_path))
    events.Reload()
    assert math.isnan(events.Scalars("losses/approx_kl")[0].value)
    assert events.Scalars("losses/loss")[0].value == 349.5


def test_the_eta_counts_the_evaluation_points_to_come(capsys):
    """Every 3rd of 10 iterations and the last: after iteration 0 four points remain (3, 6, 9, 10), after the
    last none; without evaluation none. Before any point is timed the line says how many remain."""
    progress = Progress(10, 1, 3)
    assert [progress.points_after(i) for i in (0, 3, 8, 9, 10)] == [4, 3, 2, 1, 0]
    assert Progress(10, 1, 0).points_after(0) == 0
    assert Progress(9, 1, 3).points_after(8) == 1 and Progress(9, 1, 3).points_after(9) == 0
    progress.update(1, 1, {"charts/SPS": 1.0}, None)
    assert "and 4 evaluation points" in capsys.readouterr().err
    progress.evaluating(3, 2, 4)
    assert capsys.readouterr().err == "iteration 3: evaluating 4 episodes on each of 2 configs\n"
    progress.evaluated()
    progress.update(10, 10, {"charts/SPS": 1.0}, None)
    assert "evaluation points" not in capsys.readouterr().err
