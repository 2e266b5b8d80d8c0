"""A diverged run's non-finite losses are logged as null with one warning, instead of ending the process
(and with it every run of its pack)."""
import json
import math

from kage.ppo.rundir import RunDir
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
                        "iteration 7: the run has diverged; such values are logged as null"]
