#!/usr/bin/env bash
# Installs the build into a temporary prefix, moves the build tree out of reach (restored on exit, also
# on failure), and compiles and renders a config with the installed kagec alone: proof that an install
# needs neither the build tree nor the source tree's runtime/.
#   scripts/check_install_without_build.sh [CONFIG]   (default configs/throughput/simplest.yaml)
set -euo pipefail
cd "$(dirname "$0")/.."
config=${1:-configs/throughput/simplest.yaml}
work=$(mktemp -d)
cmake --install build --prefix "$work/prefix" >/dev/null
mv build "$work/build"
trap 'mv "$work/build" build && rm -rf "$work"' EXIT
unset KAGE_ROOT
"$work/prefix/bin/kagec" compile "$config" -o "$work/compiled" --no-gpu
"$work/prefix/bin/kagec" render "$config" --steps 10 --every 5 --gif "$work/run.gif" | grep -q "rendered 3 frames"
echo "check_install_without_build: the installed kagec compiled and rendered $config with the build tree removed"
