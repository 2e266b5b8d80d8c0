#!/usr/bin/env bash
# Rebuilds this folder's report/ and paper.md from its packs/, after new packs come in: unpacks them (checksums
# checked) into DIR, runs `kage.bench report` there, copies the report here and writes the comparison with the
# paper. Run from the repository root with the project's Python (scripts/venv.sh, the package importable):
#   bash results/kage-bench-table/publish.sh
set -euo pipefail
HERE=results/kage-bench-table
DIR=${DIR:-/tmp/kage-bench-table}
PYTHON=${PYTHON:-python3}
rm -rf "$DIR"
"$PYTHON" "$HERE/unpack.py" "$HERE/packs" "$DIR"
"$PYTHON" -m kage.bench report "$DIR"
rm -rf "$HERE/report"
cp -r "$DIR/report" "$HERE/report"
"$PYTHON" "$HERE/paper_table.py" "$DIR" "$HERE/paper.json" "$HERE/paper.md"
