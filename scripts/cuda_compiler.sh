# Sourced by scripts/build.sh and scripts/check_pip_install.sh: the CUDA toolkit by one path for both builds, so that
# their compile commands name the same include folders and ccache shares their objects (left to itself, CMake finds
# /usr/local/cuda as /usr/local/cuda-13.0 here). CUDACXX set by the caller wins.
if [[ -z ${CUDACXX:-} && -x /usr/local/cuda/bin/nvcc ]]; then export CUDACXX=/usr/local/cuda/bin/nvcc; fi
