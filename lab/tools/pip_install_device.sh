#!/usr/bin/env bash
# One device-machine call: `pip install .` into the machine's python3 (3.12 with torch, JAX, Triton and
# pybind11; no package index, none of the Debian C++ libraries), with build isolation off and the carried
# scikit-build-core wheel, KAGE_CUDA=ON; then, from an empty folder, the installed package and kagec;
# then tests/gpu against the installed package. Logs and times under $OUT.
# Here first: lab/tools/make_deps.sh (fills .deps, wheels included); then run with carry [".deps"]:
#   bash lab/tools/pip_install_device.sh
set -uo pipefail
OUT=${OUT:-/tmp/kage-device-out}
mkdir -p "$OUT"
repo=$PWD
DEPS=$repo/.deps/usr
# The carried Debian libraries: headers and CMake configs for the build, shared objects for kagec and
# the extension at run time.
export CPATH=$DEPS/include CMAKE_PREFIX_PATH=$DEPS
export LD_LIBRARY_PATH=$DEPS/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}
export KAGE_CACHE_DIR=/tmp/kage-cache PYTHONUNBUFFERED=1 CMAKE_BUILD_PARALLEL_LEVEL=$(nproc)
{
  nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
  python3 -c 'import sys, torch, pybind11; print(sys.executable, sys.version.split()[0], "torch", torch.__version__, "pybind11", pybind11.__version__)'
  git -C "$repo" rev-parse HEAD 2>/dev/null || echo "commit: (no git metadata in the copy)"
} 2>&1 | tee "$OUT/machine.txt"

# The build backend, from the carried wheels (packaging only where the machine has none).
wheels=(.deps/wheels/scikit_build_core-*.whl .deps/wheels/pathspec-*.whl)
python3 -c 'import packaging' 2>/dev/null || wheels+=(.deps/wheels/packaging-*.whl)
python3 -m pip install -q --no-index --no-deps "${wheels[@]}" || exit 1
# The interpreter's headers, or the carried 3.12 headers when its distribution left them out.
python_include=()
if ! python3 -c 'import os, sysconfig, sys; sys.exit(not os.path.exists(sysconfig.get_paths()["include"] + "/Python.h"))'; then
  python_include=(-C cmake.define.Python_INCLUDE_DIR="$repo/.deps/python3.12/include/python3.12")
fi
t0=$SECONDS
python3 -m pip install -v --no-build-isolation --no-index --no-deps -C cmake.define.KAGE_CUDA=ON \
  "${python_include[@]}" . >"$OUT/pip_install.log" 2>&1 || { tail -60 "$OUT/pip_install.log"; exit 1; }
echo "pip install: $((SECONDS - t0)) s" | tee "$OUT/times.txt"
grep "kage: backends" "$OUT/pip_install.log" | tee -a "$OUT/times.txt"

# The installed package from an empty folder: nothing read from this copy of the repository.
mkdir -p /tmp/kage-empty && cd /tmp/kage-empty || exit 1
python3 - <<'PY' 2>&1 | tee "$OUT/installed.txt"
import shutil, importlib.metadata
import kage, kage.resources
print("kage", kage.__version__, "from", kage.__file__, "distribution", importlib.metadata.version("kagec"))
print("GPU backend built:", kage.gpu_backend_built(), "shipped files:", kage.resources.data_root())
print("kagec on PATH:", shutil.which("kagec"), "NVRTC folders from wheels:", kage.resources.nvrtc_dirs())
env = kage.make_vec("throughput/simplest", 1024, device="cuda")
obs, _ = env.reset(seed=0)
print("make_vec('throughput/simplest', 1024, device='cuda'):", obs)
PY
kagec compile "$(python3 -c 'import kage.resources as r; print(r.config_path("throughput/simplest"))')" \
  -o /tmp/kage-empty/compiled 2>&1 | tee -a "$OUT/installed.txt"
cd "$repo" || exit 1

t0=$SECONDS
python3 -m pytest -q -p no:cacheprovider tests/gpu 2>&1 | tee "$OUT/gpu_tests.log"
echo "tests/gpu: $((SECONDS - t0)) s" | tee -a "$OUT/times.txt"
