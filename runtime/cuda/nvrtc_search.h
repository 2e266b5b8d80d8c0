// Where NVRTC's library is looked for, by the CUDA backend's loader and by `kagec compile`'s version
// probe. A CPU-only build has it too: the Python package names its directories on any build, and the
// list is checked without a GPU.
#pragma once

#include <string>
#include <vector>

namespace kage {

/// Directories searched first, in order, by a program that knows where NVRTC is: the Python package
/// names the nvidia-cuda-nvrtc wheel's library folder. Call before the first GPU use.
void set_nvrtc_dirs(std::vector<std::string> dirs);

/// What dlopen tries, first loaded wins: libnvrtc.so.13, libnvrtc.so.12 and libnvrtc.so in each
/// directory set above, then in $CUDA_HOME/lib64 and $CUDA_PATH/lib64 (where set), then the bare names
/// (the loader's path: LD_LIBRARY_PATH, ld.so.cache), then in the folder of the NVRTC library the build
/// found beside its nvrtc.h (a build with the CUDA backend), then in /usr/local/cuda/lib64.
std::vector<std::string> nvrtc_candidates();

/// dlopen (RTLD_NOW | RTLD_LOCAL) of the first candidate that loads, or nullptr.
void* open_nvrtc();

}  // namespace kage
