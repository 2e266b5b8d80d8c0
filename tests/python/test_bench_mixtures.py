"""kage.bench over pairs that train on a mixture or a schedule (suite.json's train "stages"): the trainer
arguments each run gets (flags, pack files), --share-training over identical trainings, the records' checks,
and the report naming the training. suite.json is written by hand here, as kagec suite writes it."""
import dataclasses
import json

from kage.bench import records, report, run
from kage.bench.units import units_of
from kage.ppo import train
from test_report import write_run

MIX = {"name": "mixture of 2", "spec_sha256": "m" * 64, "schedule": None,
       "stages": [{"start": 1, "configs": [{"name": "/c/base.yaml", "spec_sha256": "a" * 64, "weight": 1.0},
                                          {"name": "/c/f2.yaml", "spec_sha256": "b" * 64, "weight": 2.0}]}]}
SCHEDULE = {"name": "/c/curriculum.yaml", "spec_sha256": "s" * 64, "schedule": "/c/curriculum.yaml",
            "stages": [{"start": 1, "configs": [{"name": "/c/base.yaml", "spec_sha256": "a" * 64, "weight": 1.0}]},
                       {"start": 200, "configs": [{"name": "/c/f2.yaml", "spec_sha256": "b" * 64, "weight": 3.0},
                                                  {"name": "/c/base.yaml", "spec_sha256": "a" * 64, "weight": 1.0}]}]}


def pair(name, train_side, eval_name):
    return {"pair": name, "sweep": None, "sweep_eval": None, "declared_axis": "filters", "certified": True,
            "train": train_side, "eval": {"name": eval_name, "spec_sha256": "e" * 64}, "problems": [], "lint_ok": True}


SUITE = {"kagec_suite_report": 1, "suite": "mix", "manifest": "/s/mix.yaml", "passed": 4, "total": 4,
         "pairs": [pair("filters/1", MIX, "/c/f1.yaml"), pair("filters/3", MIX, "/c/f3.yaml"),
                   pair("filters/4", SCHEDULE, "/c/f4.yaml"),
                   pair("filters/5", {"name": "/c/base.yaml", "spec_sha256": "a" * 64}, "/c/f5.yaml")]}


def unit(name):
    return next(u for u in units_of(SUITE) if u.name == name)


def test_each_training_becomes_the_trainers_flags():
    assert unit("filters/1").train_configs == ["/c/base.yaml", "/c/f2.yaml"]
    assert unit("filters/4").train_configs == ["/c/base.yaml", "/c/f2.yaml"]
    flags = run.train_flags(unit("filters/1"), 7, "/out/r", ["--num-envs", "4"])
    assert flags[:6] == ["--train-config-paths", "/c/base.yaml", "/c/f2.yaml", "--train-weights", "1.0", "2.0"]
    assert flags[6:] == ["--eval-config-path", "/c/f1.yaml", "--eval-config-labels", "eval", "--seed", "7", "--out",
                         "/out/r", "--exp-name", "filters_1", "--num-envs", "4"]
    assert run.train_flags(unit("filters/4"), 7, "/out/r", [])[:2] == ["--train-schedule", "/c/curriculum.yaml"]
    assert run.train_flags(unit("filters/5"), 7, "/out/r", [])[:2] == ["--train-config-path", "/c/base.yaml"]
    for flag in ("--train-config-paths", "--train-weights", "--train-schedule"):
        assert flag in run.PER_RUN_FLAGS


def test_pack_files_carry_each_runs_training(tmp_path):
    trainer_args = ["--num-envs", "4", "--device", "cpu"]
    pack = [(unit("filters/1"), 1, "/out/a"), (unit("filters/4"), 2, "/out/b"), (unit("filters/5"), 3, "/out/c")]
    path = run.write_pack_file(str(tmp_path / "packs" / "pack_0.json"), pack, trainer_args)
    runs = json.loads(open(path).read())["runs"]
    assert runs[0]["train_config_path"] == "" and runs[0]["train_config_paths"] == ["/c/base.yaml", "/c/f2.yaml"]
    assert runs[0]["train_weights"] == [1.0, 2.0] and runs[0]["num_envs"] == 4 and runs[0]["seed"] == 1
    assert runs[1]["train_config_path"] == "" and runs[1]["train_schedule"] == "/c/curriculum.yaml"
    assert "train_config_paths" not in runs[1] or not runs[1]["train_config_paths"]
    # A plain pair's run is exactly the trainer's parse of its flags, as before.
    assert runs[2] == dataclasses.asdict(train.parse_args(run.train_flags(*pack[2], trainer_args)))


def test_packs_keep_a_training_kind_together(tmp_path):
    jobs = [(unit(name), 1, str(tmp_path / name)) for name in ("filters/1", "filters/5", "filters/3", "filters/4")]
    packs = run.packs_of(jobs, 4)
    assert sorted([u.name for u, _, _ in p] for p in packs) == [["filters/1", "filters/3"], ["filters/4"],
                                                                 ["filters/5"]]


def test_share_training_joins_pairs_of_one_mixture_only():
    units = run.share_training(units_of(SUITE), SUITE)
    names = [u.name for u in units]
    assert names == [f"shared/mixture-of-2-{'m' * 8}", "filters/4", "filters/5"]
    shared = units[0]
    assert [p["pair"] for p in shared.pairs] == ["filters/1", "filters/3"]
    assert shared.eval_labels == ["filters_1", "filters_3"]
    assert run.train_flags(shared, 1, "/o", [])[:3] == ["--train-config-paths", "/c/base.yaml", "/c/f2.yaml"]


def test_records_check_a_mixtures_stages():
    assert records.suite_problem(SUITE) is None
    damaged = json.loads(json.dumps(SUITE))
    damaged["pairs"][0]["train"]["stages"][0]["configs"][1].pop("weight")
    assert "lacks its name, spec_sha256 or weight" in records.suite_problem(damaged)
    damaged = json.loads(json.dumps(SUITE))
    damaged["pairs"][2]["train"]["stages"] = []
    assert "without a list of stages" in records.suite_problem(damaged)


def test_report_reads_a_mixture_units_runs(tmp_path):
    (tmp_path / "suite.json").write_text(json.dumps(SUITE))
    (tmp_path / "bench.json").write_text(json.dumps({"kage_bench": 1, "suite": "/s/mix.yaml", "seeds": [1],
                                                     "units": ["filters/1"], "trainer_args": []}))
    write_run(tmp_path, "filters/1", 1, ["eval"], {"train/success_once": 0.8, "eval/eval/success_once": 0.2})
    result = report.report(str(tmp_path))
    row = next(p for p in result["levels"]["pairs"] if p["pair"] == "filters/1")
    assert row["train_spec"] == "m" * 64  # the mixture's identity: its configs' Specs and weights
    assert row["trains_on"] == "mixture of 2"  # as the suite names it
    assert "Pairs that train on several configs: filters/1 (mixture of 2)." in \
        (tmp_path / "report" / "pairs.md").read_text()
    assert row["metrics"]["success_once"]["train"]["mean"] == 0.8
    assert row["metrics"]["success_once"]["eval"]["mean"] == 0.2


def test_a_mixture_split_that_leaves_configs_untrained_is_warned_of_before_any_run(tmp_path, capsys):
    # filters/1 of the leave-one-out suite trains on 9 configs at equal weights: 2 environments go to the first two.
    assert run.main(["kage_bench_loo", "--pairs", "filters/1", "--seeds", "1", "--out", str(tmp_path / "b"),
                     "--dry-run", "--device", "cpu", "--num-envs", "2", "--num-steps", "128",
                     "--total-timesteps", "256"]) == 0
    err = capsys.readouterr().err
    assert "kage.bench: warning: filters/1: --num-envs 2 split over stages[0]'s 9 configs as [1, 1, 0, 0, 0, 0, 0, " \
           "0, 0] leaves " in err
    assert "configs/kage_bench/filters/9-eval.yaml without environments: they do not train; raise --num-envs" in err
