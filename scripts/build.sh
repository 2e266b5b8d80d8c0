#!/usr/bin/env bash
# Installs what is missing (Debian packages, and the Python test environment .venv: scripts/venv.sh),
# then builds kagec, the Python package and the tests into ./build by installing the project into .venv
# with pip (scikit-build-core): the installed package and CTest share that one build folder, which is
# built incrementally. Safe to run again.
#   KAGE_CUDA=AUTO|ON|OFF  the CUDA backend (default AUTO: built where nvcc and NVRTC's header are found)
#   BUILD=DIR              the build folder (default build)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake ninja-build pkg-config ccache
          libyaml-cpp-dev nlohmann-json3-dev libfmt-dev libstb-dev catch2 libcli11-dev libdlpack-dev
          clang libclang-rt-14-dev  # the fuzzer (tests/fuzz)
          slurm-wlm munge)          # the kage.bench job-array test starts a one-node Slurm cluster
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "build.sh: installing ${missing[*]}"
  sudo_cmd=()
  [[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
fi

# The CUDA toolkit is optional: with it (and NVRTC's header, which the venv's nvidia-cuda-nvrtc wheel
# carries), the GPU backend is compiled and checked too.
source scripts/cuda_compiler.sh
python=$(scripts/venv.sh)
build=${BUILD:-build}
# ccache shares object files between build folders (build/, the KAGE_CUDA=OFF build, a fresh clone's).
if command -v ccache >/dev/null; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=1
fi
export CMAKE_BUILD_PARALLEL_LEVEL=$(nproc)
# No build isolation: the venv's pinned scikit-build-core and pybind11 build it, and the build folder's
# paths stay the same from one run to the next.
"$python" -m pip install -q --no-build-isolation -C build-dir="$build" -C cmake.define.KAGE_BUILD_TESTS=ON \
  -C cmake.define.KAGE_CUDA="${KAGE_CUDA:-AUTO}" .
"$python" -c 'import kage; print(f"build.sh: kage {kage.__version__} installed into .venv, GPU backend built: "
                                 f"{kage.gpu_backend_built()}; build folder '"$build"'")'
