#!/usr/bin/env bash
# The CPU-only build (KAGE_CUDA=OFF), which AUTO never makes on a machine with nvcc and NVRTC: kagec and
# the Python package built into build-cpu-only (only the targets the checks need; ccache supplies the
# objects that do not differ from build/'s), then the Python tests against it and a compile with its
# kagec. Run after scripts/build.sh, whose .venv it uses.
set -euo pipefail
cd "$(dirname "$0")/.."
python=$(scripts/venv.sh)
build=build-cpu-only
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=1
fi
mkdir -p "$build"
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DKAGE_CUDA=OFF -DPython_EXECUTABLE="$python" \
  "${launcher[@]}" >"$build/configure.log" || { cat "$build/configure.log"; exit 1; }
grep -q "kage: backends: CPU only (KAGE_CUDA=OFF)" "$build/configure.log"
cmake --build "$build" -j"$(nproc)" --target kagec kage_python kage_api_trace
PYTHONPATH=$build/python "$python" -c 'import kage, sys; sys.exit(kage.gpu_backend_built())' ||
  { echo "check_cpu_only: the KAGE_CUDA=OFF build has the GPU backend" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$build/kagec" compile configs/throughput/simplest.yaml -o "$work/compiled" --no-gpu
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" -R '^python/'
