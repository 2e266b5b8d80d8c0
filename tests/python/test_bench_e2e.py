"""kage.bench end to end on the CPU: run two KAGE-Bench pairs with one seed and tiny flags, packed into one
process, then report (tables in Markdown, CSV and JSON, and PNG plots); a second run skips the finished
runs, and a changed config or other trainer flags are refused."""
import csv
import json
import subprocess
import sys

from support import ROOT

TINY = ["--total-timesteps", "128", "--num-envs", "2", "--num-steps", "32", "--num-minibatches", "2",
        "--update-epochs", "1", "--run-eval-every", "1", "--eval-episodes", "2", "--eval-num-envs", "2",
        "--device", "cpu", "--threads", "1"]
PAIRS = ["background/1", "agent_appearance/1"]


def bench(*args):
    return subprocess.run([sys.executable, "-m", "kage.bench", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=900)


def run(out, *extra):
    return bench("run", "suites/kage_bench.yaml", "--pairs", *PAIRS, "--seeds", "1", "--out", str(out), *TINY, *extra)


def test_run_then_report(tmp_path):
    out = tmp_path / "bench"
    first = run(out, "--pack", "2")
    assert first.returncode == 0, first.stderr
    pack = json.loads((out / "packs" / "pack_0.json").read_text())
    assert [r["seed"] for r in pack["runs"]] == [1, 1] and len({r["train_config_path"] for r in pack["runs"]}) == 1
    for pair in PAIRS:
        run_dir = out / "runs" / pair / "seed_1"
        assert (run_dir / "summary.json").exists(), (run_dir / "train.log").read_text()
        evals = [json.loads(line) for line in open(run_dir / "metrics.jsonl") if '"kind": "eval"' in line]
        assert [e["iteration"] for e in evals] == [0, 1, 2]
        assert all(e["train"]["episodes"] >= 2 and e["evals"]["eval"]["episodes"] >= 2 for e in evals)
        run_json = json.loads((run_dir / "run.json").read_text())
        assert set(run_json["configs"]) == {"train", "eval"}
        assert json.loads((run_dir / "certificates" / "eval.json").read_text())["certified"] is True

    reported = bench("report", str(out))
    assert reported.returncode == 0, reported.stderr
    report_dir = out / "report"
    for name in ("axes.md", "axes.csv", "pairs.md", "pairs.csv", "report.md", "report.json"):
        assert (report_dir / name).stat().st_size > 100, name
    with open(report_dir / "pairs.csv") as f:
        rows = list(csv.DictReader(f))
    assert {r["pair"] for r in rows} == set(PAIRS)
    distance = {r["pair"]: r for r in rows if r["metric"] == "passed_distance"}
    for pair in PAIRS:
        summary = json.loads((out / "runs" / pair / "seed_1" / "summary.json").read_text())["stats"]
        assert float(distance[pair]["train_mean"]) == summary["train/passed_distance"]["max"]
        assert float(distance[pair]["eval_mean"]) == summary["eval/eval/passed_distance"]["max"]
        assert distance[pair]["n_seeds"] == "1"
    report = json.loads((report_dir / "report.json").read_text())
    assert {a["axis"] for a in report["levels"]["axes"]} == {"background", "agent"}
    pngs = sorted((report_dir / "plots").glob("*.png"))
    assert len(pngs) >= 5
    for png in pngs:
        data = png.read_bytes()
        assert data.startswith(b"\x89PNG\r\n\x1a\n") and len(data) > 5000, png.name

    # Again on the same directory: nothing is retrained or overwritten.
    summaries = {p: (out / "runs" / p / "seed_1" / "summary.json").read_bytes() for p in PAIRS}
    again = run(out)
    assert again.returncode == 0 and again.stderr.count("finished earlier, skipped") == 2, again.stderr
    assert summaries == {p: (out / "runs" / p / "seed_1" / "summary.json").read_bytes() for p in PAIRS}

    other_flags = run(out, "--learning-rate", "1e-3")
    assert other_flags.returncode != 0 and "trainer flags" in other_flags.stderr

    suite = json.loads((out / "suite.json").read_text())
    suite["pairs"][0]["eval"]["spec_sha256"] = "0" * 64  # as if background/1-eval.yaml had changed since
    (out / "suite.json").write_text(json.dumps(suite))
    changed = run(out)
    assert changed.returncode != 0
    assert "configs/kage_bench/background/1-eval.yaml" in changed.stderr and "changed since" in changed.stderr


def test_unknown_pair_gets_a_suggestion(tmp_path):
    result = bench("run", "suites/kage_bench.yaml", "--pairs", "backgroud/1", "--seeds", "1", "--out",
                   str(tmp_path / "b"), *TINY)
    assert result.returncode != 0 and "did you mean background/1" in result.stderr
