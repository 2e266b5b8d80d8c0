#!/usr/bin/env bash
# Makes .venv (ignored by git), the test environment: python3 from PATH (3.10+; 3.11 here), with every
# package of scripts/constraints.txt at its pinned version. Safe to run again: it reinstalls only when
# the constraints changed since the last install (a stamp in .venv). Prints the venv's python.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=.venv
stamp=$venv/.constraints.sha256
want=$(sha256sum scripts/constraints.txt | cut -d' ' -f1)
if [[ ! -x $venv/bin/python ]]; then
  python3 -c 'import sys; sys.exit(sys.version_info < (3, 10))' ||
    { echo "venv.sh: python3 on PATH is $(python3 --version 2>&1); kage needs 3.10 or newer" >&2; exit 1; }
  python3 -m venv "$venv" >&2
fi
if [[ ! -f $stamp || $(cat "$stamp") != "$want" ]]; then
  echo "venv.sh: installing scripts/constraints.txt into $venv" >&2
  "$venv/bin/python" -m pip install -q --upgrade -r scripts/constraints.txt >&2
  echo "$want" >"$stamp"
fi
echo "$PWD/$venv/bin/python"
