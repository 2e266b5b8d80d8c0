#!/usr/bin/env bash
# Builds (installing what is missing) and runs the whole test suite through CTest, the Python tests with
# the test environment's interpreter (.venv).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)"
