#!/usr/bin/env python3
"""Checks that both schemas are valid draft-07 JSON Schemas, and that every config
and suite manifest in the repository validates against them (what an editor with
the yaml-language-server modeline would report)."""
import json
import pathlib
import sys

import jsonschema
import yaml

root = pathlib.Path(sys.argv[1])
config_schema = json.loads((root / "schemas/kage-config.schema.json").read_text())
suite_schema = json.loads((root / "schemas/kage-suite.schema.json").read_text())
failures = 0
for schema in (config_schema, suite_schema):
    jsonschema.Draft7Validator.check_schema(schema)

config_validator = jsonschema.Draft7Validator(config_schema)
resolver = jsonschema.RefResolver("", suite_schema, store={"kage-config.schema.json": config_schema})
suite_validator = jsonschema.Draft7Validator(suite_schema, resolver=resolver)

def check(validator, path):
    global failures
    doc = yaml.safe_load(path.read_text()) or {}
    for error in validator.iter_errors(doc):
        failures += 1
        print(f"{path}: {'/'.join(map(str, error.absolute_path))}: {error.message}")

configs = sorted((root / "configs").rglob("*.yaml")) + sorted((root / "tests/compat/original").rglob("*.yaml"))
for path in configs:
    check(config_validator, path)
suites = sorted((root / "suites").glob("*.yaml")) + [root / "tests/compat/kage_bench_original.yaml"]
for path in suites:
    check(suite_validator, path)
if len(configs) < 80 or len(suites) < 4:
    print(f"too few files found ({len(configs)} configs, {len(suites)} suites): wrong root?")
    failures += 1
print(f"schemas valid; {len(configs)} configs and {len(suites)} suites checked, {failures} problems")
sys.exit(1 if failures else 0)
