#!/usr/bin/env python3
"""Checks that this repository's KAGE-Bench configs mean what the original's files mean.

For each pair of suites/kage_bench.yaml and tests/compat/kage_bench_original.yaml (matched by name and
axis), both sides are resolved the simple way (follow `extends:`, deep-merge mappings, resolve asset paths
relative to the file that writes them, map `assets/` to the original's `src/kage_bench/assets/`) and
compared key by key with the original-format fixture, with type-strict values. Also compares
configs/default.yaml with original/default_config.yaml and checks that every config a suite names exists
and parses. A key the original file lacks and ours sets to its dataclass default (null asset sources,
dist_to_success 490.0) counts as equal.

This is an independent cross-check of the data files, not of kagec. Needs PyYAML.
Usage: python3 tests/compat/check_equivalence.py   (exit 0 when everything matches)
"""
import os
import sys

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
ASSET_KEYS = {
    "background.image_dir", "background.image_path", "background.image_paths",
    "character.sprite_dir", "character.sprite_paths", "character.sprite_path",
    "npc.sprite_dir", "npc.sprite_paths", "npc.sprite_path",
    "npc.sticky_sprite_dir", "npc.sticky_sprite_dirs", "npc.sticky_sprite_path",
}
# Dataclass defaults of the keys some files leave out (kage-env.md 1.1, 1.2, 1.3, 1.4).
ABSENT_DEFAULT = {
    "dist_to_success": 490.0,
    "background.image_dir": None,
    "character.sprite_dir": None,
    "npc.sprite_dir": None,
    "npc.sticky_sprite_dir": None,
}


def flatten(doc, prefix=""):
    out = {}
    for key, value in doc.items():
        if isinstance(value, dict):
            out.update(flatten(value, prefix + key + "."))
        else:
            out[prefix + key] = value
    return out


def to_original_path(path, file_dir):
    rel = os.path.relpath(os.path.normpath(os.path.join(file_dir, path)), REPO).replace(os.sep, "/")
    assert rel.startswith("assets/"), f"asset path outside assets/: {path} (from {file_dir})"
    return "src/kage_bench/" + rel


def load_ours(path, seen=()):
    """Flattened mapping of one of our configs, extends resolved, asset paths in the original's form."""
    path = os.path.normpath(path)
    assert path not in seen, f"extends cycle at {path}"
    with open(path) as f:
        doc = yaml.safe_load(f) or {}
    base = {}
    if "extends" in doc:
        base = load_ours(os.path.join(os.path.dirname(path), doc.pop("extends")), seen + (path,))
    own = flatten(doc)
    for key, value in own.items():
        if key in ASSET_KEYS and value is not None:
            if isinstance(value, list):
                own[key] = [to_original_path(v, os.path.dirname(path)) for v in value]
            else:
                own[key] = to_original_path(value, os.path.dirname(path))
    base.update(own)  # flattened keys: a deep merge where scalars and lists replace
    return base


def load_original(path):
    with open(path) as f:
        return flatten(yaml.safe_load(f))


def normalised(flat):
    out = dict(flat)
    for key, default in ABSENT_DEFAULT.items():
        out.setdefault(key, default)
    return out


def same(a, b):
    if type(a) is not type(b):
        return False
    if isinstance(a, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return a == b


def compare(label, ours, original):
    ours, original = normalised(ours), normalised(original)
    problems = []
    for key in sorted(set(ours) | set(original)):
        a, b = ours.get(key, "<absent>"), original.get(key, "<absent>")
        if not same(a, b):
            problems.append(f"{label}: {key}: ours {a!r}, original {b!r}")
    return problems


def config_paths(side) -> list:
    """The configs of a pair's side: one path, or a mixture's list of paths and {config, weight} items."""
    if isinstance(side, str):
        return [side]
    return [item if isinstance(item, str) else item["config"] for item in side]


def main():
    problems = compare("default", load_ours(os.path.join(REPO, "configs/default.yaml")),
                       load_original(os.path.join(HERE, "original/default_config.yaml")))
    with open(os.path.join(REPO, "suites/kage_bench.yaml")) as f:
        ours = yaml.safe_load(f)["pairs"]
    with open(os.path.join(HERE, "kage_bench_original.yaml")) as f:
        theirs = {p["name"]: p for p in yaml.safe_load(f)["pairs"]}
    if len(ours) != 34 or len(theirs) != 34:
        problems.append(f"pair counts: ours {len(ours)}, original {len(theirs)} (want 34)")
    for pair in ours:
        other = theirs.get(pair["name"])
        if other is None:
            problems.append(f"{pair['name']}: missing from the original manifest")
            continue
        if pair["axis"] != other["axis"] or pair.get("allow") != other.get("allow"):
            problems.append(f"{pair['name']}: axis or allowance differs between the manifests")
        for side in ("train", "eval"):
            problems += compare(f"{pair['name']} {side}",
                                load_ours(os.path.join(REPO, "suites", pair[side])),
                                load_original(os.path.join(HERE, other[side])))
    for name in sorted(os.listdir(os.path.join(REPO, "suites"))):
        with open(os.path.join(REPO, "suites", name)) as f:
            suite = yaml.safe_load(f)
        configs = [c for p in suite.get("pairs", []) for s in ("train", "eval") for c in config_paths(p[s])]
        for sweep in suite.get("sweeps", []):
            configs += config_paths(sweep["train"]) + [e["config"] for e in sweep["evals"]]
        for config in configs:
            flat = load_ours(os.path.join(REPO, "suites", config))
            if len(flat) < 93:
                problems.append(f"{name}: {config}: only {len(flat)} keys after extends")
    for problem in problems:
        print(problem)
    print("ok" if not problems else f"{len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
