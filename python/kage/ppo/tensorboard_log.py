"""TensorBoard scalars of a training run under the original's tag names (kage-ppo-baseline.md §4.3), so
that its curves overlay runs of the original. Written to <run dir>/tensorboard/ where tensorboard is
importable (torch.utils.tensorboard needs it); metrics.jsonl holds every value either way."""
import dataclasses
import math
import os
import sys
from typing import Dict, Optional

from kage.fields import BOARD_DIFF, BOARD_SIDE, BY_NAME, DIFF_METRICS, LISTED, RECORD
from kage.ppo.args import first_train_config

# The original's copies of two training-row tags, under its own names.
TRAIN_COPIES = {"train/avg_progress": "main_metrics/avg_train_progress",
                "train/avg_success_once": "main_metrics/avg_success_once"}


def value_tag(metric: str) -> str:
    """The original's name of a recorded field at an evaluation: episodic_return and episodic_length for the
    LISTED ones, config_<metric> for the others."""
    return f"episodic_{metric}" if BY_NAME[metric].record == LISTED else f"config_{metric}"


def number(value: Optional[float]) -> float:
    """A logged value; a missing one (every listed return exactly 0, or a loss that was not finite) is NaN,
    as the original logs it."""
    return math.nan if value is None else float(value)


def train_scalars(row: dict) -> Dict[str, float]:
    """A training row's tags: its keys are already the original's (charts/, losses/, train/), plus
    charts/global_step and the main_metrics/ copies."""
    tags = {k: number(v) for k, v in row.items() if "/" in k}
    tags["charts/global_step"] = float(row["global_step"])
    tags.update({copy: tags[tag] for tag, copy in TRAIN_COPIES.items() if tag in tags})
    return tags


def eval_scalars(row: dict, train_label: str) -> Dict[str, float]:
    """An evaluation row's tags: ppo_jax.py's with one eval config, ppo_jax_multi_conf.py's (labelled by
    file name; `train_label` is the train config's) with several."""
    evals = row["evals"]
    if len(evals) == 1:
        (label, evaluated), = evals.items()
        diff = row["diffs"][label]
        tags = {}
        for side, result in (("train", row["train"]), ("eval", evaluated)):
            tags.update({f"eval/avg_{side}_{value_tag(m)}": number(result[m]) for m in RECORD})
        # QUIRK: the return's difference is train_eval_return_diff, every other one's avg_train_eval_<m>_diff.
        diff_tag = {d: "train_eval_return_diff" if d == "return" else f"avg_train_eval_{d}_diff" for d in DIFF_METRICS}
        tags.update({f"eval/{diff_tag[d]}": number(diff[d]) for d in DIFF_METRICS})
        for tag in [f"avg_train_{value_tag(m)}" for m in BOARD_SIDE] + [diff_tag[d] for d in BOARD_DIFF]:
            tags[f"main_metrics/{tag}"] = tags[f"eval/{tag}"]
        return tags
    tags = {}
    for label, result in ((train_label, row["train"]), *evals.items()):
        tags.update({f"{label}/avg_{value_tag(m)}": number(result[m]) for m in RECORD})
        for m in BOARD_SIDE:
            tags[f"main_metrics/{label}/avg_{value_tag(m)}"] = tags[f"{label}/avg_{value_tag(m)}"]
    for label, diff in row["diffs"].items():
        for d in DIFF_METRICS:
            tags[f"{label}/train_eval_{d}_diff"] = number(diff[d])
            if d in BOARD_DIFF:
                tags[f"main_metrics/{label}/train_eval_{d}_diff"] = tags[f"{label}/train_eval_{d}_diff"]
    return tags


def summary_writer_class():
    """torch's SummaryWriter, or None where tensorboard is not importable."""
    try:
        from torch.utils.tensorboard import SummaryWriter
    except ImportError:
        return None
    return SummaryWriter


class Board:
    """A run's TensorBoard log, opened at its first write; after a resume, the events past the checkpoint's
    step are dropped (purge), as the run's log rows are."""

    def __init__(self, log_dir: str, writer_class, train_label: str, hyperparameters: dict):
        self.log_dir, self.writer_class, self.train_label = log_dir, writer_class, train_label
        self.hyperparameters = hyperparameters
        self.purge_step: Optional[int] = None
        self.writer = None

    def purge(self, global_step: int) -> None:
        self.purge_step = global_step + 1

    def write(self, *rows: dict) -> None:
        if self.writer is None:
            self.writer = self.writer_class(self.log_dir, purge_step=self.purge_step)
            if self.purge_step is None:  # a fresh run: its arguments as the original's text entry
                table = "\n".join(f"|{k}|{v}|" for k, v in self.hyperparameters.items())
                self.writer.add_text("hyperparameters", f"|param|value|\n|-|-|\n{table}")
        for row in rows:
            tags = train_scalars(row) if row["kind"] == "train" else eval_scalars(row, self.train_label)
            for tag, value in tags.items():
                self.writer.add_scalar(tag, value, row["global_step"])
        self.writer.flush()

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()


class NoBoard:
    """Where tensorboard is not importable: nothing is written."""

    def purge(self, global_step: int) -> None:
        pass

    def write(self, *rows: dict) -> None:
        pass

    def close(self) -> None:
        pass


_told = False


def open_writer(run_dir: str, args):
    """The run's Board, or a NoBoard (with a note on stderr, once) where tensorboard is not importable."""
    global _told
    writer_class = summary_writer_class()
    if writer_class is None:
        if not _told:
            print("kage.ppo.train: tensorboard is not importable: no TensorBoard scalars (metrics.jsonl has every value)",
                  file=sys.stderr)
            _told = True
        return NoBoard()
    train_label = os.path.basename(first_train_config(args).rstrip("/")).replace(" ", "_")  # §3.5's labels
    return Board(os.path.join(run_dir, "tensorboard"), writer_class, train_label, dataclasses.asdict(args))
