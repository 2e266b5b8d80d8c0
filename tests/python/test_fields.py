"""kage.fields, the one table of the batch's fields and the episode metrics: its views are the names and orders
that the log, the report, TensorBoard, the videos and the scorer have always written (existing runs and reports
stay byte for byte the same), the runtime's info fields are its RUNTIME rows, and every batch returns exactly
its fields, the batch's `config` too."""
import numpy as np
import pytest
import torch

import kage
from kage import fields
from kage.ppo import evaluation
from support import NEAR_GOAL, SIMPLEST

NINE = ("x", "y", "vx_mean", "vy_mean", "passed_distance", "progress", "jump_count", "success", "success_once")


def test_views_keep_the_published_names_and_orders():
    assert fields.EPISODE_METRICS == NINE  # §4.1: the nine metrics of the training log's train/avg_<m>
    assert fields.RECORD_COLUMNS == ("finished", "return", "length") + NINE
    assert set(fields.DIFF_METRICS) == {"return", "success", "progress", "success_once", "passed_distance",
                                         "jump_count"}  # §3.3
    assert fields.REPORT_METRICS == ("passed_distance", "progress", "success", "success_once", "return", "length",
                                     "jump_count")
    assert fields.MARKDOWN_METRICS == (("success", "success_once"), ("distance", "passed_distance"),
                                       ("progress", "progress"), ("return", "return"))
    assert fields.SCORER_METRICS == ("return", "length", "success_once", "success", "passed_distance", "progress",
                                     "jump_count", "x", "y", "vx_mean", "vy_mean")
    assert fields.SCORER_MARKDOWN == fields.SCORER_METRICS[:7]
    assert fields.VIDEO_METRICS == ("return", "x", "passed_distance", "progress", "success_once", "jump_count")
    assert fields.INTERVAL_METRICS == ("success_once", "success", "progress")
    assert fields.BOARD_SIDE == ("return", "passed_distance", "jump_count")
    assert set(fields.BOARD_DIFF) == set(fields.DIFF_METRICS) - {"success"}
    assert fields.SUCCESS_SHOWN == "success_once"


def test_the_record_is_read_by_name():
    # kage.ppo.train's tally still reads the return, the length and then the metrics at these positions.
    assert [evaluation.COLUMN[n] for n in ("finished", "return", "length")] == [0, 1, 2]
    assert [evaluation.COLUMN[m] for m in fields.EPISODE_METRICS] == list(range(3, 3 + len(NINE)))


def test_the_runtime_fields_are_the_tables_runtime_rows():
    runtime = [name for name, _, _ in kage.INFO_FIELDS]
    assert fields.runtime_problem(runtime) is None
    assert set(runtime) == set(fields.RUNTIME_FIELDS) and "config" not in runtime
    missing = fields.runtime_problem(runtime + ["speed"])
    assert "the runtime has speed without a row in kage.fields.FIELDS" in missing
    extra = fields.runtime_problem([n for n in runtime if n != "jump_count"])
    assert "kage.fields.FIELDS has runtime rows jump_count that the runtime lacks" in extra


def test_every_field_has_one_row_and_the_ranks_count_from_one():
    names = [f.name for f in fields.FIELDS]
    assert len(names) == len(set(names))
    for view in (fields.REPORT_METRICS, fields.SCORER_METRICS, fields.VIDEO_METRICS, fields.INTERVAL_METRICS):
        assert set(view) <= set(fields.RECORD), view
    assert fields.BATCH_FIELDS == ("config",) and fields.BY_NAME["config"].dtype == "int32"


def test_a_batch_returns_every_field_of_the_table():
    with kage.make_vec(SIMPLEST, 3) as env:
        _, info = env.reset(seed=0)
        names = set(fields.RUNTIME_FIELDS) | set(fields.BATCH_FIELDS)
        assert set(kage.vector.INFO_NAMES) == names
        assert {k for k in info if k not in ("final_obs", "final_info", "_final", "_final_obs", "_final_info")} == names
        assert set(info["final_info"]) == names
        config = info["config"]
        assert config.dtype == np.int32 and config.tolist() == [0, 0, 0]
        # A view of the batch's memory, as every output; the final info's is the same array.
        assert config.ctypes.data == env._handle.data_ptr("info/config") != 0
        assert info["final_info"]["config"].ctypes.data == config.ctypes.data
        assert torch.from_dlpack(config).tolist() == [0, 0, 0]


def test_the_single_environment_reports_the_config_too():
    from kage.single_env import SingleEnv  # needs Gymnasium

    env = SingleEnv(NEAR_GOAL)
    _, info = env.reset(seed=1)
    assert info["config"] == 0 and set(info) == set(kage.vector.INFO_NAMES)
    env.close()


@pytest.mark.parametrize("column", ["return", "success_once"])
def test_an_evaluation_summarises_each_recorded_field_by_its_rule(column):
    # Two environments, finished episodes at steps 0 and 1: LISTED fields average the listed episodes whose
    # return is not 0, ALL fields sum over every finished episode.
    records = torch.zeros((2, len(fields.RECORD_COLUMNS), 2))
    c = evaluation.COLUMN
    records[0, c["finished"]] = torch.tensor([1.0, 1.0])
    records[0, c["return"]] = torch.tensor([2.0, 0.0])
    records[0, c["success_once"]] = torch.tensor([1.0, 0.0])
    records[1, c["finished"]] = torch.tensor([1.0, 0.0])
    records[1, c["return"]] = torch.tensor([4.0, 9.0])
    records[1, c["success_once"]] = torch.tensor([1.0, 1.0])
    result = evaluation.summarize_evaluation(records, 3)
    assert result["episodes"] == 3
    assert result[column] == {"return": 3.0, "success_once": float(np.float32(2) / np.float32(3))}[column]
