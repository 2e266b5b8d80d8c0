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


def test_shared_training_reaches_array_tasks(tmp_path):
    """kage.bench slurm passes --share-training on to every task; the 340 runs of 10 seeds become 90."""
    out = tmp_path / "array"
    bench("slurm", "suites/kage_bench.yaml", "--seeds", "1-10", "--pack", "8", "--out", str(out),
                 "--share-training")
    script = (out / "slurm" / "kage_bench.sbatch").read_text()
    assert "--share-training --task" in script
    table = json.loads((out / "tasks.json").read_text())["tasks"]
    runs = [(r["unit"], r["seed"]) for task in table for r in task]
    assert len(runs) == len(set(runs)) == 90
    shared = json.loads((out / "bench.json").read_text())["shared"]
    assert len(shared) == 30  # the 34 pairs but the 4 with a train config of their own
