"""kage.bench run --share-training: pairs with one train config train once per seed, in one run that
evaluates every eval config of them; the training is the separate runs' training (its train side logs the
same values), and the report gives each pair its own row from its label."""
import csv
import json
import subprocess
import sys

from support import ROOT

TINY = ["--total-timesteps", "128", "--num-envs", "2", "--num-steps", "32", "--num-minibatches", "2",
        "--update-epochs", "1", "--run-eval-every", "2", "--eval-episodes", "2", "--eval-num-envs", "2",
        "--device", "cpu", "--threads", "1"]
PAIRS = ["background/1", "agent_appearance/1", "background/4"]  # the first two share shape_black.yaml


def bench(*args):
    done = subprocess.run([sys.executable, "-m", "kage.bench", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=900)
    assert done.returncode == 0, done.stderr
    return done


def train_rows(run_dir):
    """The training rows without timings, and the evaluations' train side."""
    rows = [json.loads(line) for line in open(run_dir / "metrics.jsonl")]
    timing = {"charts/SPS", "charts/SPS_update", "seconds"}
    return [{k: v for k, v in r.items() if k not in timing} if r["kind"] == "train" else
            (r["iteration"], r["train"]) for r in rows]


def test_shared_training_trains_once_and_reports_each_pair(tmp_path):
    shared, separate = tmp_path / "shared", tmp_path / "separate"
    bench("run", "suites/kage_bench.yaml", "--pairs", *PAIRS, "--seeds", "1", "--out", str(shared),
          "--share-training", *TINY)
    bench("run", "suites/kage_bench.yaml", "--pairs", "background/1", "--seeds", "1", "--out", str(separate), *TINY)

    recorded = json.loads((shared / "bench.json").read_text())
    unit = recorded["shared"]["background/1"][0]
    assert unit.startswith("shared/shape_black-")
    assert recorded["shared"] == {"background/1": [unit, "background_1"],
                                  "agent_appearance/1": [unit, "agent_appearance_1"]}
    assert recorded["units"] == [unit, "background/4"]
    run_dir = shared / "runs" / unit / "seed_1"
    run = json.loads((run_dir / "run.json").read_text())
    assert set(run["configs"]) == {"train", "background_1", "agent_appearance_1"}
    assert (shared / "runs" / "background" / "4" / "seed_1" / "summary.json").exists()
    assert not (shared / "runs" / "background" / "1").exists()

    # The shared run trained what background/1's own run trained: the same training rows, the same
    # evaluations of the train config.
    alone = separate / "runs" / "background" / "1" / "seed_1"
    assert train_rows(run_dir) == train_rows(alone)

    bench("report", str(shared))
    with open(shared / "report" / "pairs.csv") as f:
        rows = [r for r in csv.DictReader(f) if r["metric"] == "passed_distance"]
    assert sorted(r["pair"] for r in rows) == sorted(PAIRS)
    stats = json.loads((run_dir / "summary.json").read_text())["stats"]
    for r in rows:
        if r["pair"] == "background/4":
            continue
        label = r["pair"].replace("/", "_")
        assert float(r["train_mean"]) == stats["train/passed_distance"]["max"]
        assert float(r["eval_mean"]) == stats[f"eval/{label}/passed_distance"]["max"]
    refused = subprocess.run([sys.executable, "-m", "kage.bench", "run", "suites/kage_bench.yaml", "--pairs", *PAIRS,
                              "--seeds", "1", "--out", str(shared), *TINY], cwd=ROOT, capture_output=True, text=True,
                             timeout=300)
    assert refused.returncode != 0 and "--share-training" in refused.stderr

    # A folder whose pairs ran in parts of at most 10 eval configs (the published table's -part1 and -part2) is
    # not mixed with this layout: its pairs' seeds would train again under the new name.
    recorded["shared"]["background/1"][0] = unit + "-part1"
    (shared / "bench.json").write_text(json.dumps(recorded))
    mixed = subprocess.run([sys.executable, "-m", "kage.bench", "run", "suites/kage_bench.yaml", "--pairs", *PAIRS,
                            "--seeds", "1", "--out", str(shared), "--share-training", *TINY], cwd=ROOT,
                           capture_output=True, text=True, timeout=300)
    assert mixed.returncode != 0
    assert f"runs pair background/1 in {unit}-part1, this version in {unit}" in mixed.stderr, mixed.stderr
    assert "into another --out" in mixed.stderr


IMAGE_SKELETON_PAIRS = ["background/9", *(f"filters/{i}" for i in range(1, 10)), "effects/1", "effects/2", "effects/3"]


def eval_rows(run_dir, labels):
    """Per evaluation point, the named eval configs' results and differences to the train config."""
    rows = [json.loads(line) for line in open(run_dir / "metrics.jsonl")]
    return [(r["iteration"], {k: (r["evals"][k], r["diffs"][k]) for k in labels}) for r in rows if r["kind"] == "eval"]


def test_a_run_of_more_than_10_eval_configs_evaluates_as_two_runs(tmp_path):
    """IMAGE_SKELETON's 13 pairs share one run: its 11th to 13th eval configs (effects/1-3) take the 1st to 3rd's
    evaluation seeds, so they log what a run of the same training evaluating effects/1-3 alone logs, and the
    training is that run's."""
    many, few = tmp_path / "many", tmp_path / "few"
    bench("run", "suites/kage_bench.yaml", "--pairs", *IMAGE_SKELETON_PAIRS, "--seeds", "1", "--out", str(many),
          "--share-training", *TINY)
    bench("run", "suites/kage_bench.yaml", "--pairs", "effects/1", "effects/2", "effects/3", "--seeds", "1", "--out",
          str(few), "--share-training", *TINY)
    [unit] = json.loads((many / "bench.json").read_text())["units"]
    assert json.loads((few / "bench.json").read_text())["units"] == [unit]  # one training, one run directory name
    run_many, run_few = many / "runs" / unit / "seed_1", few / "runs" / unit / "seed_1"
    labels = json.loads((run_many / "run.json").read_text())["args"]["eval_config_labels"]
    assert labels == [p.replace("/", "_") for p in IMAGE_SKELETON_PAIRS]  # in this order: effects 11th to 13th
    effects = ["effects_1", "effects_2", "effects_3"]
    assert train_rows(run_many) == train_rows(run_few)
    assert eval_rows(run_many, effects) == eval_rows(run_few, effects)
    assert len(eval_rows(run_few, effects)) >= 2  # at least two evaluation points compared


def test_shared_training_reaches_array_tasks(tmp_path):
    """kage.bench slurm passes --share-training on to every task; the 340 runs of 10 seeds become 70."""
    out = tmp_path / "array"
    bench("slurm", "suites/kage_bench.yaml", "--seeds", "1-10", "--pack", "8", "--out", str(out),
                 "--share-training")
    script = (out / "slurm" / "kage_bench.sbatch").read_text()
    assert "--share-training --task" in script
    table = json.loads((out / "tasks.json").read_text())["tasks"]
    runs = [(r["unit"], r["seed"]) for task in table for r in task]
    assert len(runs) == len(set(runs)) == 70  # 7 train configs, each trained once a seed
    shared = json.loads((out / "bench.json").read_text())["shared"]
    assert len(shared) == 30  # the 34 pairs but the 4 with a train config of their own


def test_mixed_eval_counts_train_one_pack(tmp_path):
    """--mix-eval-counts: the shared run (2 eval configs) and background/4's (1) train in one pack, each evaluating
    its own configs and no other."""
    out = tmp_path / "mixed"
    bench("run", "suites/kage_bench.yaml", "--pairs", *PAIRS, "--seeds", "1", "--out", str(out), "--share-training",
          "--pack", "2", "--mix-eval-counts", *TINY)
    pack = json.loads((out / "packs" / "pack_0.json").read_text())
    assert len(pack["runs"]) == 2 and not (out / "packs" / "pack_1.json").exists()
    unit = json.loads((out / "bench.json").read_text())["units"][0]
    expected = {unit: {"background_1", "agent_appearance_1"}, "background/4": {"eval"}}
    for name, labels in expected.items():
        rows = [json.loads(line) for line in open(out / "runs" / name / "seed_1" / "metrics.jsonl")]
        evals = [r for r in rows if r["kind"] == "eval"]
        assert [r["iteration"] for r in evals] == [0, 2]
        assert all(set(r["evals"]) == labels for r in evals)
        assert (out / "runs" / name / "seed_1" / "summary.json").exists()
