#!/usr/bin/env bash
# The CPU-only build (KAGE_CUDA=OFF), which AUTO never makes on a machine with nvcc and NVRTC: kagec and
# the Python package built into build-cpu-only (only the targets the checks need; ccache supplies the
# objects that do not differ from build/'s), then a compile with its kagec and the Python tests of what
# KAGE_CUDA changes: the extension (the environment API, its arrays, threads, errors, resources and
# compile_kernels, the Gymnasium and JAX bindings) and a short training run. The rest of the Python side is the same code on
# either build and runs in scripts/test.sh. Run after scripts/build.sh, whose .venv it uses.
set -euo pipefail
cd "$(dirname "$0")/.."
python=$(scripts/venv.sh)
build=build-cpu-only
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=1
  # build/'s compiler by the same name (ccache hashes it: /usr/bin/c++ for build/'s /usr/bin/g++ matched no object).
  compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' build/CMakeCache.txt 2>/dev/null)
  [[ -n $compiler ]] && launcher+=(-DCMAKE_CXX_COMPILER="$compiler")
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
native='vec_api|zero_copy|errors|compile_kernels|env_checks|gymnasium|array_layout|threads|autoreset|resources|jax_env|same_bytes'
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" -R "^python/test_($native|state|train_options)(::|\$)"
