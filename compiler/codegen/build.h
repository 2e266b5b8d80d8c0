// Build: the toolchain invocations of `kagec compile` (nvcc -> fatbin, host c++ -> shared object)
// and the versions a manifest records. Flags live here once; codegen prints them into its header.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace kage {

/// The GPU target: SASS for sm_90 plus compute_90 PTX for newer GPUs (JIT by the driver).
inline constexpr const char* kCudaArch = "sm_90";

/// nvcc flags besides input, output and include directory.
const std::vector<std::string>& nvcc_flags();
/// Host compiler flags besides input, output and include directory (float32 semantics unchanged:
/// no contraction, no fast-math, design.md "Floating point").
const std::vector<std::string>& host_flags();
/// Flags joined by spaces, for the generated header and the manifest.
std::string join_flags(const std::vector<std::string>& flags);

/// The nvcc to use: $CUDACXX, $CUDA_HOME/bin/nvcc, /usr/local/cuda/bin/nvcc, then PATH. Empty if none.
std::string find_nvcc();
/// The host compiler: $KAGE_HOST_CXX, $CXX, then `c++` on PATH. Empty if none.
std::string find_host_cxx();
/// The directory the generated source's #include "runtime/..." resolve against: $KAGE_ROOT, else the
/// directory set by set_runtime_include_dir, else <prefix>/share/kagec beside an installed binary
/// (<prefix>/bin or <prefix>/lib), else the source tree kagec was built from.
std::string runtime_include_dir();
/// Names the runtime headers' directory for a program that knows where they are installed: the
/// Python package (its extension lives in site-packages, not beside <prefix>/share/kagec).
void set_runtime_include_dir(const std::string& dir);

/// First line of `tool --version` (empty if it cannot run).
std::string tool_version(const std::string& tool);
/// "major.minor" of the NVRTC library that dlopen finds, or empty.
std::string nvrtc_version();

/// One finished tool run.
struct ToolRun {
  std::vector<std::string> argv;
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
  double seconds = 0;
  bool ok() const { return exit_code == 0; }
};

/// Runs argv (no shell) and waits.
ToolRun run_tool(const std::vector<std::string>& argv);

/// nvcc `source` -> `fatbin` (SASS and PTX).
ToolRun build_fatbin(const std::string& nvcc, const std::string& source, const std::string& fatbin,
                     const std::string& include_dir);
/// host c++ `source` -> `shared_object` exporting the kage_host_* entry points.
ToolRun build_host_library(const std::string& cxx, const std::string& source, const std::string& shared_object,
                           const std::string& include_dir);

}  // namespace kage
