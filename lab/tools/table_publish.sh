#!/usr/bin/env bash
# Rebuilds results/kage-bench-table's report/ and paper.md from its packs/, after new packs come in: unpacks them
# (checksums checked) into DIR, runs `kage.bench report` there, copies the report into the folder and writes
# the comparison with the paper (lab/tools/table_paper.py). Every Markdown file it writes begins with the
# provenance block of the folder's README.md (device, date, commit, command of each lease: update it there
# first), and report.json carries the same lines as its "provenance" key. Run from the repository root with the
# project's Python (the package importable):
#   bash lab/tools/table_publish.sh
set -euo pipefail
HERE=results/kage-bench-table
DIR=${DIR:-/tmp/kage-bench-table}
PYTHON=${PYTHON:-python3}
block=$(sed -n '/^<!-- provenance$/,/^-->$/p' "$HERE/README.md")
[ -n "$block" ] || { echo "table_publish: $HERE/README.md has no '<!-- provenance' block: add one" >&2; exit 1; }
rm -rf "$DIR"
"$PYTHON" lab/tools/table_unpack.py "$HERE/packs" "$DIR"
"$PYTHON" -m kage.bench report "$DIR"
rm -rf "$HERE/report"
cp -r "$DIR/report" "$HERE/report"
"$PYTHON" lab/tools/table_paper.py "$DIR" "$HERE/paper.json" "$HERE/paper.md"
for page in "$HERE"/report/*.md "$HERE/paper.md"; do
  { printf '%s\n' "$block"; cat "$page"; } >"$page.tmp" && mv "$page.tmp" "$page"
done
BLOCK=$block "$PYTHON" - "$HERE/report/report.json" <<'PY'
import json, os, sys
lines = os.environ["BLOCK"].splitlines()[1:-1]
with open(sys.argv[1]) as f:
    report = json.load(f)
with open(sys.argv[1], "w") as f:
    json.dump({"provenance": dict(line.split(": ", 1) for line in lines), **report}, f, indent=1)
    f.write("\n")
PY
