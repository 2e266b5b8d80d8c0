// NVRTC compile check: the semantics headers (through semantics_kernels.cuh) must compile as a
// runtime-compiled program for compute_90, with no host headers (kage_hd.h provides the fixed-width
// types under __CUDACC_RTC__). NVRTC is a library, so this runs without a GPU. Exit 1 with the NVRTC
// log when the program does not compile.
#include <nvrtc.h>

#include <cstdio>
#include <string>
#include <vector>

namespace {

bool ok(nvrtcResult r, const char* what) {
  if (r == NVRTC_SUCCESS) return true;
  std::fprintf(stderr, "%s: %s\n", what, nvrtcGetErrorString(r));
  return false;
}

}  // namespace

int main() {
  const char* source = "#include \"tests/cuda/semantics_kernels.cuh\"\n";
  nvrtcProgram prog;
  if (!ok(nvrtcCreateProgram(&prog, source, "kage_nvrtc_check.cu", 0, nullptr, nullptr), "nvrtcCreateProgram")) {
    return 1;
  }
  const std::string include = std::string("--include-path=") + KAGE_SOURCE_DIR;
  // The options of the runtime-compiled GPU build: sm_90 family, no contraction (style.md section 5).
  const char* options[] = {"--gpu-architecture=compute_90", "--std=c++20", "--fmad=false", include.c_str()};
  const nvrtcResult compiled = nvrtcCompileProgram(prog, 4, options);
  size_t log_size = 0;
  nvrtcGetProgramLogSize(prog, &log_size);
  std::vector<char> log(log_size + 1, '\0');
  if (log_size > 0) nvrtcGetProgramLog(prog, log.data());
  int major = 0, minor = 0;
  nvrtcVersion(&major, &minor);
  if (compiled != NVRTC_SUCCESS) {
    std::fprintf(stderr, "NVRTC %d.%d could not compile the semantics library (%s):\n%s\n", major, minor,
                 nvrtcGetErrorString(compiled), log.data());
    nvrtcDestroyProgram(&prog);
    return 1;
  }
  size_t ptx_size = 0;
  if (!ok(nvrtcGetPTXSize(prog, &ptx_size), "nvrtcGetPTXSize")) return 1;
  std::string ptx(ptx_size, '\0');
  if (!ok(nvrtcGetPTX(prog, ptx.data()), "nvrtcGetPTX")) return 1;
  int kernels = 0;
  for (size_t at = ptx.find(".entry"); at != std::string::npos; at = ptx.find(".entry", at + 1)) ++kernels;
  nvrtcDestroyProgram(&prog);
  if (log_size > 1) std::printf("NVRTC log:\n%s\n", log.data());
  std::printf("semantics compiled by NVRTC %d.%d for compute_90: %d kernels, %zu bytes of PTX\n", major, minor, kernels,
              ptx_size);
  return kernels == 4 ? 0 : 1;
}
