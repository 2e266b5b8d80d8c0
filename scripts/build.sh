#!/usr/bin/env bash
# Installs what is missing (Debian packages), then configures and builds kagec
# and its tests into ./build. Safe to run again: it only does what is needed.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake ninja-build pkg-config
          libyaml-cpp-dev nlohmann-json3-dev libfmt-dev libstb-dev catch2 libcli11-dev
          python3-jsonschema python3-yaml clang libclang-rt-14-dev
          python3-dev pybind11-dev libdlpack-dev python3-numpy python3-pytest python3-torch python3-matplotlib
          python3-pil slurm-wlm munge)  # pil: GIF videos; slurm-wlm, munge: the kage.bench job-array test starts a one-node Slurm cluster
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

# The CUDA toolkit is optional: with it, the GPU code is compiled (and checked) too.
if [[ -z ${CUDACXX:-} && -x /usr/local/cuda/bin/nvcc ]]; then export CUDACXX=/usr/local/cuda/bin/nvcc; fi

# The Python package is built for Debian's interpreter, the one that has the python3-* packages above
# (a python3 earlier on PATH may be another one).
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPython_EXECUTABLE=/usr/bin/python3 >/dev/null
cmake --build build -j"$(nproc)"
