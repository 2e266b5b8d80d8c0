"""lab/tools/learning_summary.py: a run's evaluation points on its train config and on each held-out config, its
entropy every 20 iterations, and its mean approx_kl and clipfrac over the finite ones."""
import json
import sys

from support import ROOT

sys.path.insert(0, str(ROOT / "lab/tools"))
import learning_summary  # noqa: E402 (lab/tools is no package)


def test_a_run_s_summary_names_each_held_out_config(tmp_path):
    def point(iteration, ret, success, held_out):
        return {"kind": "eval", "iteration": iteration, "train": {"return": ret, "success_once": success},
                "evals": {name: {"success_once": s} for name, s in held_out.items()}}

    def update(iteration, entropy, kl, clipfrac):
        return {"kind": "train", "iteration": iteration, "losses/entropy": entropy, "losses/approx_kl": kl,
                "losses/clipfrac": clipfrac}

    rows = [point(0, -3900.0, 0.0, {"filters_1": 0.0, "effects_1": 0.0}),
            update(20, 0.8, 0.01, 0.1), update(30, 0.7, 0.5, 0.9), update(40, None, None, None),
            point(50, -120.25, 0.5, {"filters_1": 0.25, "effects_1": 0.75})]
    path = tmp_path / "metrics.jsonl"
    path.write_text("".join(json.dumps(r) + "\n" for r in rows))
    assert learning_summary.summary(str(path)).splitlines() == [
        "  eval 0: -3900.0 (0.00)  50: -120.2 (0.50)",
        "  held out effects_1: 0: 0.00  50: 0.75",
        "  held out filters_1: 0: 0.00  50: 0.25",
        "  entropy every 20 iterations 0.80 nan",
        "  mean approx_kl 0.2550, clipfrac 0.500",
    ]
