# Sourced by the device scripts (lab/*/*_device.sh): builds kagec and the Python package on the device
# machine against its python3 (pip's pybind11, torch, JAX, CuPy) and the Debian libraries carried in
# .deps (lab/tools/make_deps.sh), then sets PYTHONPATH. Incremental: a warm machine keeps the build.
OUT=${OUT:-/tmp/kage-device-out}
BUILD=${BUILD:-build-dev}
mkdir -p "$OUT"
DEPS=$PWD/.deps/usr
if [ ! -d "$DEPS" ]; then
  echo "device_build.sh: no $DEPS: make it here with lab/tools/make_deps.sh and carry .deps (or link it)" >&2
  exit 1
fi
export CPATH=$DEPS/include
export LD_LIBRARY_PATH=$DEPS/lib/x86_64-linux-gnu:/usr/local/cuda/lib64:${LD_LIBRARY_PATH:-}
export KAGE_CACHE_DIR=/tmp/kage-cache PYTHONUNBUFFERED=1
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem --format=csv | tee "$OUT/gpu.txt"
python3 -c 'import sys, torch, pybind11; print(sys.version.split()[0], torch.__version__, pybind11.__version__)' | tee -a "$OUT/gpu.txt"
# The interpreter's headers, or the carried 3.12 headers when its distribution left them out.
python_include=()
if ! python3 -c 'import os, sysconfig, sys; sys.exit(not os.path.exists(sysconfig.get_paths()["include"] + "/Python.h"))'; then
  python_include=(-DPython_INCLUDE_DIR="$PWD/.deps/python3.12/include/python3.12")
fi
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release -DKAGE_BUILD_TESTS=OFF \
  -DPython_EXECUTABLE="$(command -v python3)" "${python_include[@]}" -DCMAKE_PREFIX_PATH="$DEPS" \
  >"$OUT/build.log" 2>&1 && ninja -C "$BUILD" kagec kage_python >>"$OUT/build.log" 2>&1 ||
  { tail -40 "$OUT/build.log"; exit 1; }
export PYTHONPATH=$PWD/$BUILD/python
