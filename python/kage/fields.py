"""The per-environment fields of a batch and the episode metrics, written once: FIELDS is the one table of
their names, their order in each output and their descriptions. The log and the evaluation
(kage.ppo.evaluation, kage.ppo.train), the benchmark report (kage.bench.tables, kage.bench.report), the
TensorBoard scalars (kage.ppo.tensorboard_log), the videos (kage.ppo.video), the checkpoint scorer
(kage.ppo.evaluate) and the interval estimates (kage.bench.intervals) take their names from the views below;
none of them lists a metric itself.

A row's columns:

- ``source``: who fills the field. RUNTIME: the runtime, each reset and step (``runtime/info_fields.def``,
  whose line gives its type and meaning; kage.vector refuses to import when that file and this table name
  different fields). BATCH: the batch, once, at its creation (``kage::Env::config_index``), with its
  ``dtype`` and ``doc`` here.
- ``record``: whether the evaluation records it for each finished episode (kage-ppo-baseline.md §4.1), and
  how it is summarised (§3.2): LISTED (the return and length: the mean over the first `episodes` listed
  episodes whose return is not exactly 0) or ALL (every other metric: its sum over every finished
  episode, over their number). The record's columns are ``RECORD_COLUMNS``, in table order.
- ``diff``: the evaluation logs |train - eval| of it (§3.3).
- ``report``: its rank in the report's CSV and JSON tables; ``markdown``: (rank, heading) in its Markdown
  tables.
- ``scorer``: (rank, shown in Markdown) in the checkpoint scorer's configs table.
- ``video``: its rank on a video's panel.
- ``interval``: its rank among the metrics the interval estimates take (shares of episodes or of the
  distance, whose performance profile over 0..1 fits).
- ``board``: the TensorBoard main_metrics/ copies the original makes of it: "side" (its train value at an
  evaluation) and "diff" (its train - eval difference).

Read a record by name: ``RECORD_COLUMNS.index(name)``. A new metric is a row with a ``record`` (and the
columns that place it in each output); a new field of the batch is a row of source BATCH and its values in
the batch (``kage::Env``), which kage.make_vec and kage.jax return under its name.
"""
from typing import NamedTuple, Optional, Sequence, Tuple

RUNTIME, BATCH = "runtime", "batch"
LISTED, ALL = "listed", "all"


class Field(NamedTuple):
    name: str
    source: str
    record: Optional[str] = None
    diff: bool = False
    report: Optional[int] = None
    markdown: Optional[Tuple[int, str]] = None
    scorer: Optional[Tuple[int, bool]] = None
    video: Optional[int] = None
    interval: Optional[int] = None
    board: str = ""
    dtype: Optional[str] = None  # BATCH fields only: the runtime's are in runtime/info_fields.def
    doc: Optional[str] = None


FIELDS: Tuple[Field, ...] = (
    #     name               source   record  diff   report markdown          scorer      video interval board
    Field("return",          RUNTIME, LISTED, True,  5,     (4, "return"),    (1, True),  1,    None,    "side diff"),
    Field("length",          RUNTIME, LISTED, False, 6,     None,             (2, True),  None, None,    ""),
    Field("x",               RUNTIME, ALL,    False, None,  None,             (8, False), 2,    None,    ""),
    Field("y",               RUNTIME, ALL,    False, None,  None,             (9, False), None, None,    ""),
    Field("vx_mean",         RUNTIME, ALL,    False, None,  None,             (10, False), None, None,   ""),
    Field("vy_mean",         RUNTIME, ALL,    False, None,  None,             (11, False), None, None,   ""),
    Field("passed_distance", RUNTIME, ALL,    True,  1,     (2, "distance"),  (5, True),  3,    None,    "side diff"),
    Field("progress",        RUNTIME, ALL,    True,  2,     (3, "progress"),  (6, True),  4,    3,       "diff"),
    Field("jump_count",      RUNTIME, ALL,    True,  7,     None,             (7, True),  6,    None,    "side diff"),
    Field("success",         RUNTIME, ALL,    True,  3,     None,             (4, True),  None, 2,       ""),
    Field("success_once",    RUNTIME, ALL,    True,  4,     (1, "success"),   (3, True),  5,    1,       "diff"),
    Field("vx",              RUNTIME),
    Field("vy",              RUNTIME),
    Field("timestep",        RUNTIME),
    Field("config",          BATCH, dtype="int32",
          doc="the index of the config the environment runs, in the list given to make_vec (0 for one config)"),
)

BY_NAME = {f.name: f for f in FIELDS}


def _ranked(column: str) -> Tuple[str, ...]:
    rows = [f for f in FIELDS if getattr(f, column) is not None]
    return tuple(f.name for f in sorted(rows, key=lambda f: getattr(f, column)))


RUNTIME_FIELDS = tuple(f.name for f in FIELDS if f.source == RUNTIME)
BATCH_FIELDS = tuple(f.name for f in FIELDS if f.source == BATCH)
#: The evaluation's record of each finished episode (§4.1): the finished mask, then the recorded fields.
RECORD = tuple(f.name for f in FIELDS if f.record)
RECORD_COLUMNS = ("finished",) + RECORD
#: The metrics averaged over every finished episode (the evaluation's and the training log's `avg_` values).
EPISODE_METRICS = tuple(f.name for f in FIELDS if f.record == ALL)
DIFF_METRICS = tuple(f.name for f in FIELDS if f.diff)
REPORT_METRICS = _ranked("report")
#: (heading, metric) of the report's Markdown tables.
MARKDOWN_METRICS = tuple((BY_NAME[m].markdown[1], m) for m in _ranked("markdown"))
SCORER_METRICS = _ranked("scorer")
SCORER_MARKDOWN = tuple(m for m in SCORER_METRICS if BY_NAME[m].scorer[1])
VIDEO_METRICS = _ranked("video")
INTERVAL_METRICS = _ranked("interval")
BOARD_SIDE = tuple(f.name for f in FIELDS if "side" in f.board.split())
BOARD_DIFF = tuple(f.name for f in FIELDS if "diff" in f.board.split())

#: The metric of the Markdown tables' "success" column, and the note that says so.
SUCCESS_SHOWN = next(m for heading, m in MARKDOWN_METRICS if heading == "success")
SUCCESS_NOTE = (f"success is `{SUCCESS_SHOWN}`: the share of episodes that reached the goal at some step, as in "
                "the paper's success-rate plots; `success` (past the goal at the episode's end) is in the CSV and "
                "JSON files.")


def runtime_problem(runtime_names: Sequence[str]) -> Optional[str]:
    """Why the runtime's info fields (in runtime/info_fields.def order) are not the RUNTIME rows of FIELDS, or
    None when they are."""
    missing = [n for n in runtime_names if n not in RUNTIME_FIELDS]
    extra = [n for n in RUNTIME_FIELDS if n not in runtime_names]
    if not missing and not extra:
        return None
    parts = [f"the runtime has {', '.join(missing)} without a row in kage.fields.FIELDS"] if missing else []
    parts += [f"kage.fields.FIELDS has runtime rows {', '.join(extra)} that the runtime lacks"] if extra else []
    return "; ".join(parts) + " (runtime/info_fields.def and kage/fields.py name the fields together)"


def _check_table() -> None:
    names = [f.name for f in FIELDS]
    assert len(set(names)) == len(names), "a field is listed twice"
    for column in ("report", "video", "interval"):
        ranks = [getattr(f, column) for f in FIELDS if getattr(f, column) is not None]
        assert sorted(ranks) == list(range(1, len(ranks) + 1)), f"the {column} ranks are not 1..n"
    for column in ("markdown", "scorer"):
        ranks = [getattr(f, column)[0] for f in FIELDS if getattr(f, column) is not None]
        assert sorted(ranks) == list(range(1, len(ranks) + 1)), f"the {column} ranks are not 1..n"
    for f in FIELDS:
        assert f.source in (RUNTIME, BATCH) and f.record in (None, LISTED, ALL), f.name
        assert (f.source == BATCH) == (f.dtype is not None and f.doc is not None), f.name
        assert f.record or not (f.diff or f.report or f.markdown or f.scorer or f.video or f.interval or f.board), \
            f"{f.name}: only a recorded field is a metric of the outputs"


_check_table()
