#!/usr/bin/env python3
"""Writes the compatibility fixtures: KAGE-Bench's configuration files in the ORIGINAL's format.

The original benchmark ships every configuration as a complete copy of its default_config.yaml (93 keys,
no merging, asset paths relative to the original repository root) with a few values changed. This script
rebuilds those files from a table of overrides over the default mapping, keeping the default's key order,
so that kagec can be tested on files that mean exactly what they meant to the original loader:

  original/default_config.yaml           the original default (93 keys)
  original/<axis>/<n>-train.yaml         the 34 pairs, train side
  original/<axis>/<n>-eval.yaml          the 34 pairs, eval side
  kage_bench_original.yaml               a suite manifest (our format) over those 68 files

Usage: python3 tests/compat/make_original_fixtures.py   (writes next to this script; no dependencies)
The output is committed; rerun after editing the tables below and commit both.
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
BG_DIR = "src/kage_bench/assets/backgrounds"
SPRITES = "src/kage_bench/assets/sprites"


def bg(n):
    return f"{BG_DIR}/bg-{n}.jpeg"


def skin(name):
    return f"{SPRITES}/{name}"


# The original default_config.yaml: 8 root keys, then 9 sections (85 keys). Order as written out.
DEFAULT = {
    "episode_length": 500,
    "forward_reward_scale": 0.2,
    "jump_penalty": 10.0,
    "timestep_penalty": 0.1,
    "idle_penalty": 5.0,
    "dist_to_success": 490.0,
    "H": 128,
    "W": 128,
    "background": {
        "mode": "image",
        "image_dir": BG_DIR,
        "parallax_factor": 0.5,
        "tile_horizontal": True,
        "switch_frequency": 0.0,
        "color_names": ["purple", "teal", "indigo"],
    },
    "character": {
        "width": 16,
        "height": 24,
        "use_sprites": True,
        "sprite_dir": SPRITES,
        "enable_animation": True,
        "animation_fps": 12.0,
        "idle_sprite_idx": 0,
        "use_shape": False,
        "shape_types": ["circle", "star"],
        "shape_colors": ["teal", "indigo"],
        "shape_rotate": True,
        "shape_rotation_speed": 5.0,
    },
    "npc": {
        "enabled": True,
        "min_npc_count": 5,
        "max_npc_count": 20,
        "spawn_y_offset": 0,
        "animation_fps": 12.0,
        "sprite_dir": SPRITES,
        "sticky_enabled": False,
        "min_sticky_count": 1,
        "max_sticky_count": 5,
        "sticky_sprite_dir": SPRITES,
        "sticky_can_jump": True,
        "sticky_jump_probability": 0.01,
        "sticky_y_min_offset": -40,
        "sticky_y_max_offset": -10,
        "sticky_x_offsets": [],
        "sticky_x_min": -60,
        "sticky_x_max": 60,
    },
    "distractors": {
        "enabled": True,
        "count": 5,
        "shape_types": ["circle", "star", "cross"],
        "shape_colors": ["red", "green", "blue"],
        "can_move": True,
        "min_speed": 0.0,
        "max_speed": 1.0,
        "can_rotate": True,
        "min_rotation_speed": -0.3,
        "max_rotation_speed": 0.3,
        "min_size": 4,
        "max_size": 12,
    },
    "filters": {
        "brightness": 0.0,
        "contrast": 1.0,
        "gamma": 1.0,
        "saturation": 1.0,
        "hue_shift": 0.0,
        "color_temp": 0.0,
        "color_jitter_std": 0.0,
        "gaussian_noise_std": 0.0,
        "poisson_noise_scale": 0.0,
        "blur_sigma": 0.0,
        "sharpen_amount": 0.0,
        "pixelate_factor": 1,
        "vignette_strength": 0.0,
        "radial_light_strength": 0.0,
        "pop_filter_list": [],
    },
    "effects": {
        "point_light_enabled": False,
        "point_light_intensity": 1.0,
        "point_light_radius": 0.1,
        "point_light_falloff": 2,
        "point_light_count": 4,
        "point_light_color_names": ["blue", "pink", "gold"],
    },
    "layout": {
        "length": 2048,
        "height_px": 128,
        "base_ground_y": 96,
        "pix_per_unit": 2,
        "ground_thickness": 2,
        "run_width": 25,
        "p_change": 0.7,
        "p_up_given_change": 0.5,
        "min_step_height": 5,
        "max_step_height": 17,
        "layout_colors": ["cyan"],
    },
    "physics": {
        "gravity": 0.75,
        "move_speed": 1,
        "jump_force": -7.5,
        "ground_friction": 0.8,
        "air_resistance": 0.95,
        "max_fall_speed": 8.0,
    },
}

# Override operations, applied in order to a deep copy of DEFAULT:
#   ("set", "a.b", v)          set a key (kept in place; a new key goes to the end of its section)
#   ("replace", "a.b", "c", v) remove key b and put key c with value v in its place
#   ("del", "a.b")             remove a key (the original loader then uses the dataclass default)
SET, REPLACE, DEL = "set", "replace", "del"

AGENT_SHAPE_INERT = [
    (SET, "character.shape_types", ["circle"]),
    (SET, "character.shape_colors", ["teal"]),
    (SET, "character.shape_rotate", False),
]
NO_ENTITIES = [(SET, "distractors.enabled", False), (SET, "npc.enabled", False)]

SHAPE_BLACK = [
    (SET, "background.mode", "black"),
    (SET, "character.use_sprites", False),
    (SET, "character.use_shape", True),
    *AGENT_SHAPE_INERT,
    *NO_ENTITIES,
]
SKELETON_BLACK = [
    (SET, "background.mode", "black"),
    (REPLACE, "character.sprite_dir", "sprite_paths", [skin("skeleton")]),
    *AGENT_SHAPE_INERT,
    *NO_ENTITIES,
]


def image_mode(images):
    return [(SET, "background.mode", "image"), (REPLACE, "background.image_dir", "image_paths", images)]


def image_shape(images):
    return [op for op in SHAPE_BLACK if op[1] != "background.mode"] + image_mode(images)


def image_skeleton(images):
    return [op for op in SKELETON_BLACK if op[1] != "background.mode"] + image_mode(images)


IMAGE_SKELETON = image_skeleton([bg(1)])
BG_123 = [bg(1), bg(2), bg(3)]
# dist_to_success is absent from both files of these pairs in the original (its dataclass default,
# 490.0, equals the YAML value, so this changes nothing).
NO_DIST = [(DEL, "dist_to_success")]
SAME_LOOK = [
    (SET, "distractors.enabled", True),
    (SET, "distractors.shape_types", ["circle"]),
    (SET, "distractors.shape_colors", ["teal"]),
    (SET, "distractors.min_size", 16),
    (SET, "distractors.max_size", 16),
]

# (axis folder, number, suite axis, train ops, eval ops = train ops + these)
PAIRS = [
    ("background", 1, "background", SHAPE_BLACK, [(SET, "background.mode", "noise")]),
    ("background", 2, "background", SHAPE_BLACK,
     [(SET, "background.mode", "color"), (SET, "background.color_names", ["purple"])]),
    ("background", 3, "background", SHAPE_BLACK,
     [(SET, "background.mode", "color"), (SET, "background.color_names", ["purple", "lime", "indigo"])]),
    ("background", 4, "background",
     SHAPE_BLACK + [(SET, "background.mode", "color"), (SET, "background.color_names", ["red", "green", "blue"])],
     [(SET, "background.color_names", ["purple", "lime", "indigo"])]),
    ("background", 5, "background", SHAPE_BLACK, [(SET, "background.mode", "image")]),
    ("background", 6, "background", image_shape([bg(1)]), [(SET, "background.image_paths", [bg(128)])]),
    ("background", 7, "background", image_shape(BG_123), [(SET, "background.image_paths", [bg(128)])]),
    ("background", 8, "background", SKELETON_BLACK,
     [(SET, "background.mode", "color"), (SET, "background.color_names", ["purple"])]),
    ("background", 9, "background", IMAGE_SKELETON, [(SET, "background.image_paths", [bg(128)])]),
    ("background", 10, "background", image_skeleton(BG_123), [(SET, "background.image_paths", [bg(128)])]),
    ("agent_appearance", 1, "agent", SHAPE_BLACK, [(SET, "character.shape_types", ["line"])]),
    ("agent_appearance", 2, "agent", SHAPE_BLACK, [(SET, "character.shape_colors", ["pink"])]),
    ("agent_appearance", 3, "agent", SHAPE_BLACK,
     [(SET, "character.shape_types", ["line"]), (SET, "character.shape_colors", ["pink"])]),
    ("agent_appearance", 4, "agent", SHAPE_BLACK,
     [(SET, "character.use_shape", False), (SET, "character.use_sprites", True),
      (REPLACE, "character.sprite_dir", "sprite_paths", [skin("skeleton")])]),
    ("agent_appearance", 5, "agent", SKELETON_BLACK, [(SET, "character.sprite_paths", [skin("clown")])]),
    ("distractors", 1, "distractors", SKELETON_BLACK,
     [(SET, "npc.enabled", True), (REPLACE, "npc.sprite_dir", "sprite_paths", [skin("skeleton")])]),
    ("distractors", 2, "distractors", SKELETON_BLACK, [(SET, "npc.enabled", True)]),
    ("distractors", 3, "distractors", SKELETON_BLACK,
     [(SET, "npc.sticky_enabled", True),
      (REPLACE, "npc.sticky_sprite_dir", "sticky_sprite_dirs", [skin("skeleton")])]),
    ("distractors", 4, "distractors", SKELETON_BLACK, [(SET, "npc.sticky_enabled", True)]),
    ("distractors", 5, "distractors", SHAPE_BLACK + NO_DIST, SAME_LOOK + [(SET, "distractors.count", 7)]),
    ("distractors", 6, "distractors", SHAPE_BLACK + NO_DIST,
     SAME_LOOK + [(SET, "distractors.count", 1), (SET, "character.shape_colors", ["indigo"])]),
    ("filters", 1, "filters", IMAGE_SKELETON, [(SET, "filters.brightness", 1.0)]),
    ("filters", 2, "filters", IMAGE_SKELETON, [(SET, "filters.contrast", 128.0)]),
    ("filters", 3, "filters", IMAGE_SKELETON, [(SET, "filters.saturation", 0.0)]),
    ("filters", 4, "filters", IMAGE_SKELETON, [(SET, "filters.hue_shift", 180.0)]),
    ("filters", 5, "filters", IMAGE_SKELETON, [(SET, "filters.color_jitter_std", 2.0)]),
    ("filters", 6, "filters", IMAGE_SKELETON, [(SET, "filters.gaussian_noise_std", 100.0)]),
    ("filters", 7, "filters", IMAGE_SKELETON, [(SET, "filters.pixelate_factor", 3)]),
    ("filters", 8, "filters", IMAGE_SKELETON, [(SET, "filters.vignette_strength", 10.0)]),
    ("filters", 9, "filters", IMAGE_SKELETON, [(SET, "filters.radial_light_strength", 1.0)]),
    ("effects", 1, "effects", IMAGE_SKELETON,
     [(SET, "effects.point_light_enabled", True), (SET, "effects.point_light_intensity", 0.5)]),
    ("effects", 2, "effects", IMAGE_SKELETON,
     [(SET, "effects.point_light_enabled", True), (SET, "effects.point_light_falloff", 4)]),
    ("effects", 3, "effects", IMAGE_SKELETON, [(SET, "effects.point_light_enabled", True)]),
    ("layout", 1, "layout", SHAPE_BLACK + NO_DIST, [(SET, "layout.layout_colors", ["red"])]),
]

ALLOW = {
    ("distractors", 6): [("agent", "distractors/6 deliberately dresses the agent in a new colour (indigo) "
                                   "while one distractor wears the agent's training look (a teal circle of "
                                   "the agent's size); the published pair changes the agent axis too")],
}


def apply(ops):
    doc = json.loads(json.dumps(DEFAULT))  # deep copy, order kept
    for op in ops:
        path = op[1].split(".")
        parent = doc
        for part in path[:-1]:
            parent = parent[part]
        key = path[-1]
        if op[0] == SET:
            parent[key] = op[2]
        elif op[0] == DEL:
            assert key in parent, op
            del parent[key]
        elif op[0] == REPLACE:
            assert key in parent, op
            items = [(op[2], op[3]) if k == key else (k, v) for k, v in parent.items()]
            parent.clear()
            parent.update(items)
        else:
            raise ValueError(op)
    return doc


def scalar(v):
    if v is None:
        return "null"
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(scalar(x) for x in v) + "]"
    raise TypeError(v)


def emit(doc, header, schema):
    lines = [f"# yaml-language-server: $schema={schema}", f"# {header}"]
    for k, v in doc.items():
        if isinstance(v, dict):
            lines.append("")
            lines.append(f"{k}:")
            lines += [f"  {kk}: {scalar(vv)}" for kk, vv in v.items()]
        else:
            lines.append(f"{k}: {scalar(v)}")
    return "\n".join(lines) + "\n"


def count_keys(doc):
    return sum(len(v) if isinstance(v, dict) else 1 for v in doc.values())


def write(rel, text):
    path = os.path.join(HERE, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", newline="\n") as f:
        f.write(text)


def main():
    assert count_keys(DEFAULT) == 93
    assert len(PAIRS) == 34
    write("original/default_config.yaml",
          emit(DEFAULT, "Compatibility fixture in the original's format: KAGE-Env 0.2.0 default_config.yaml "
                        "(93 keys; generated by make_original_fixtures.py).",
               "../../../schemas/kage-config.schema.json"))
    manifest = [
        "# yaml-language-server: $schema=../../schemas/kage-suite.schema.json",
        "# KAGE-Bench's 34 pairs over the original-format fixtures in original/ (generated by make_original_fixtures.py).",
        "suite: kage-bench-original",
        "description: >-",
        "  The 34 KAGE-Bench pairs as the original ships them: complete flat files, no extends, asset paths",
        "  relative to the original repository root. Same names, axes and allowances as suites/kage_bench.yaml.",
        "pairs:",
    ]
    for folder, n, axis, train_ops, eval_ops in PAIRS:
        sides = {"train": apply(train_ops), "eval": apply(train_ops + eval_ops)}
        for side, doc in sides.items():
            expected = 93 - (1 if "dist_to_success" not in doc else 0)
            assert count_keys(doc) == expected, (folder, n, side)
            write(f"original/{folder}/{n}-{side}.yaml",
                  emit(doc, f"Compatibility fixture in the original's format: KAGE-Bench {folder}/{n}, {side} side "
                            "(complete file, no extends; generated by make_original_fixtures.py).",
                       "../../../../schemas/kage-config.schema.json"))
        manifest += [f"  - name: {folder}/{n}", f"    axis: {axis}",
                     f"    train: original/{folder}/{n}-train.yaml", f"    eval: original/{folder}/{n}-eval.yaml"]
        if (folder, n) in ALLOW:
            manifest.append("    allow:")
            for ax, reason in ALLOW[(folder, n)]:
                manifest += [f"      - axis: {ax}", f"        reason: {json.dumps(reason)}"]
    write("kage_bench_original.yaml", "\n".join(manifest) + "\n")


if __name__ == "__main__":
    main()
