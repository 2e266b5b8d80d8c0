#!/usr/bin/env bash
# What a pip user does, checked end to end: a fresh clone of the committed tree, installed with plain
# `pip install <clone>` (build isolation, so the build requirements come from the index) into a fresh
# venv that has NVRTC's wheel (so the build makes the CUDA backend where nvcc is found) and Gymnasium;
# then, with the clone moved away and from an empty folder: `import kage` and a shipped config by name,
# Gymnasium's make_vec of kage/KAGE-v0, the versions of the package and the distribution, `kagec` on the
# venv's PATH compiling a shipped config with the installed runtime headers. Prints each step's time.
#   scripts/check_pip_install.sh   (python3 from PATH)
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
step() {
  local t0=$SECONDS
  "$@"
  echo "check_pip_install: $((SECONDS - t0)) s: $*"
}
step git clone -q "$repo" "$work/clone"
step python3 -m venv "$work/venv"
step "$work/venv/bin/pip" install -q -c "$repo/scripts/constraints.txt" nvidia-cuda-nvrtc gymnasium
# ccache, where build.sh's builds filled it, with paths relative to the clone so its objects match: the build
# folder inside the clone as build.sh's is inside the repository, and the CUDA toolkit by build.sh's path.
if command -v ccache >/dev/null; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CCACHE_BASEDIR=$work/clone CCACHE_NOHASHDIR=1
  export SKBUILD_BUILD_DIR=$work/clone/build
  source scripts/cuda_compiler.sh
fi
export CMAKE_BUILD_PARALLEL_LEVEL=$(nproc)
step "$work/venv/bin/pip" install -q "$work/clone"
mv "$work/clone" "$work/moved-away"
mkdir "$work/empty" && cd "$work/empty"
export PATH=$work/venv/bin:$PATH
unset KAGE_ROOT PYTHONPATH
step python -c "import kage; kage.make_vec('throughput/simplest', 4).reset(seed=0)"
python -c "import gymnasium, kage
env = gymnasium.make_vec('kage/KAGE-v0', num_envs=2, vectorization_mode='vector_entry_point', config='kage_bench/bases/shape_black')
env.reset(seed=0)"
python - <<'PY'
import importlib.metadata
import kage
import kage.resources

assert kage.__version__ == importlib.metadata.version("kagec"), (kage.__version__, importlib.metadata.version("kagec"))
root = str(kage.resources.data_root())
assert "moved-away" not in root and "/share/kagec" in root, root
print(f"check_pip_install: kage {kage.__version__}, GPU backend built: {kage.gpu_backend_built()}, shipped files in {root}")
PY
[[ $(command -v kagec) == "$work/venv/bin/kagec" ]] || { echo "kagec is not the venv's: $(command -v kagec)" >&2; exit 1; }
config=$(python -c "import kage.resources as r; print(r.config_path('throughput/simplest'))")
step kagec compile "$config" -o compiled --no-gpu
kagec render "$config" --steps 10 --every 5 --gif run.gif | grep -q "rendered 3 frames"
echo "check_pip_install: the pip-installed package and kagec work with the clone moved away"
