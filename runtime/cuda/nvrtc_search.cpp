#include "runtime/cuda/nvrtc_search.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>

namespace kage {
namespace {

namespace fs = std::filesystem;

std::mutex& dirs_mutex() {
  static std::mutex m;
  return m;
}

std::vector<std::string>& dirs() {
  static std::vector<std::string> d;
  return d;
}

// Newest first: a CUDA 13 driver runs code from either release's NVRTC.
constexpr const char* kNames[] = {"libnvrtc.so.13", "libnvrtc.so.12", "libnvrtc.so"};

void add_dir(std::vector<std::string>* out, const std::string& dir) {
  if (dir.empty()) return;
  for (const char* name : kNames) out->push_back(dir + "/" + name);
}

}  // namespace

void set_nvrtc_dirs(std::vector<std::string> d) {
  std::lock_guard<std::mutex> lock(dirs_mutex());
  dirs() = std::move(d);
}

std::vector<std::string> nvrtc_candidates() {
  std::vector<std::string> out;
  {
    std::lock_guard<std::mutex> lock(dirs_mutex());
    for (const std::string& d : dirs()) add_dir(&out, d);
  }
  for (const char* var : {"CUDA_HOME", "CUDA_PATH"}) {
    if (const char* v = std::getenv(var); v && *v) add_dir(&out, std::string(v) + "/lib64");
  }
  for (const char* name : kNames) out.emplace_back(name);
#ifdef KAGE_NVRTC_BUILD_LIB_DIR
  add_dir(&out, KAGE_NVRTC_BUILD_LIB_DIR);  // beside the header the build used (runtime/cuda/CMakeLists.txt)
#endif
  add_dir(&out, "/usr/local/cuda/lib64");  // the toolkit's default place, often not on the loader's path
  return out;
}

void* open_nvrtc() {
  for (const std::string& c : nvrtc_candidates()) {
    const fs::path path(c);
    std::error_code ec;
    if (path.has_parent_path() && !fs::exists(path, ec)) continue;
    // NVRTC opens its builtins library (libnvrtc-builtins.so.<major.minor>) by name when it compiles: from
    // a folder off the loader's path (the wheel's), load it first so that that name is already loaded.
    if (path.has_parent_path()) {
      for (const auto& e : fs::directory_iterator(path.parent_path(), ec)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("libnvrtc-builtins.so.", 0) == 0) ::dlopen(e.path().c_str(), RTLD_NOW | RTLD_LOCAL);
      }
    }
    if (void* h = ::dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL)) return h;
  }
  return nullptr;
}

}  // namespace kage
