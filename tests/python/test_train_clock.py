"""charts/SPS's clock counts what the original's does (§4.3): the training loop's wall time, its logging and
checkpoints included, less its evaluation points. The checkpoints and evaluations are slowed down here by known
amounts, so that each shows up (or not) in the logged training time whatever the machine's speed."""
import json
import time

from kage.ppo import train
from support import NEAR_GOAL

CHECKPOINT_S = 1.0  # several times an iteration of this run on a CPU
EVALUATION_S = 0.5


def test_checkpoints_count_and_evaluations_do_not(tmp_path, monkeypatch):
    save, evaluate = train.save_checkpoints, train.evaluation_rows

    def slow_save(*a, **kw):
        time.sleep(CHECKPOINT_S)
        return save(*a, **kw)

    def slow_evaluate(*a, **kw):
        time.sleep(EVALUATION_S)
        return evaluate(*a, **kw)

    monkeypatch.setattr(train, "save_checkpoints", slow_save)
    monkeypatch.setattr(train, "evaluation_rows", slow_evaluate)
    out = tmp_path / "run"
    args = train.parse_args([
        "--train-config-path", NEAR_GOAL, "--eval-config-path", NEAR_GOAL, "--device", "cpu", "--threads", "1",
        "--total-timesteps", "192", "--num-envs", "2", "--num-steps", "16", "--num-minibatches", "2",
        "--update-epochs", "1", "--run-eval-every", "3", "--eval-episodes", "2", "--eval-num-envs", "2",
        "--save-checkpoint-every", "1", "--out", str(out)])
    start = time.perf_counter()
    train.train([args])
    wall = time.perf_counter() - start

    rows = [json.loads(line) for line in open(out / "metrics.jsonl")]
    trained = [r for r in rows if r["kind"] == "train"]
    assert [r["iteration"] for r in trained] == [1, 2, 3, 4, 5, 6]
    laps = [args.batch_size / r["charts/SPS_update"] for r in trained]
    # Iteration i's checkpoint is written after its lap, so it falls in the lap of iteration i + 1.
    assert all(lap >= CHECKPOINT_S for lap in laps[1:]), laps
    train_seconds = trained[-1]["global_step"] / trained[-1]["charts/SPS"]
    assert abs(train_seconds - sum(laps)) < 1e-6 * train_seconds
    # The evaluation points (at iterations 0, 3 and 6) are outside the clock, as is the pack's start.
    assert [r["iteration"] for r in rows if r["kind"] == "eval"] == [0, 3, 6]
    assert train_seconds <= wall - 3 * EVALUATION_S
