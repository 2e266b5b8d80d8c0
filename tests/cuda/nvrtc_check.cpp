// NVRTC compile check of exactly what the loader compiles at run time: a generated config source
// (tests/codegen/simplest.expected.cu, which the codegen golden test keeps equal to the generator's
// output; it includes runtime/cuda/kernels.cuh) with the loader's own option list for sm_90. NVRTC is a
// library, so this runs without a GPU. Exit 1 with the NVRTC log when the source does not compile, or
// when the cubin lacks one of the entry points the device batch looks up. Compiled twice: from the source
// root, then from a folder whose own runtime/ headers fail, so that a checkout in the working directory
// can never shadow the include root the loader names (an installed package run from a checkout).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "runtime/cuda/module_loader.h"

int main() {
  const std::string root = KAGE_SOURCE_DIR;
  const std::string path = root + "/tests/codegen/simplest.expected.cu";
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || text.str().empty()) {
    std::fprintf(stderr, "%s: cannot read the generated source\n", path.c_str());
    return 1;
  }
  kage::NvrtcOptions options;
  options.include_dir = root;
  std::string error;
  std::optional<std::string> cubin =
      kage::nvrtc_compile(text.str(), "simplest.expected.cu", kage::nvrtc_option_list("sm_90", options), &error);
  if (!cubin) {
    std::fprintf(stderr, "NVRTC could not compile %s:\n%s\n", path.c_str(), error.c_str());
    return 1;
  }
  namespace fs = std::filesystem;
  const fs::path decoy = fs::temp_directory_path() / ("kage_nvrtc_decoy_" + std::to_string(::getpid()));
  fs::create_directories(decoy / "runtime" / "cuda");
  std::ofstream(decoy / "runtime" / "cuda" / "kernels.cuh") << "#error \"read from the working directory\"\n";
  const fs::path source_dir = fs::current_path();
  fs::current_path(decoy);
  const std::optional<std::string> from_elsewhere =
      kage::nvrtc_compile(text.str(), "simplest.expected.cu", kage::nvrtc_option_list("sm_90", options), &error);
  fs::current_path(source_dir);
  fs::remove_all(decoy);
  if (!from_elsewhere) {
    std::fprintf(stderr, "NVRTC read headers outside the include root %s:\n%s\n", root.c_str(), error.c_str());
    return 1;
  }
  // Each kernel has its own code section, named after its unmangled extern "C" name.
  int missing = 0;
  for (const char* kernel : {"kage_reset", "kage_step", "kage_render", "kage_sample_actions"}) {
    if (cubin->find(std::string(".text.") + kernel + '\0') == std::string::npos) {
      std::fprintf(stderr, "the cubin has no code for %s\n", kernel);
      ++missing;
    }
  }
  if (missing) return 1;
  std::printf("NVRTC compiled %s for sm_90: 4 kernels, %zu bytes of cubin\n", path.c_str(), cubin->size());
  return 0;
}
