// CUDA driver module loading and NVRTC compilation with an on-disk cubin cache.
#include "runtime/cuda/module_loader.h"

#include <nvrtc.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "fileio/sha256.h"

namespace kage {
namespace {

namespace fs = std::filesystem;

/// First line of a cache file: this tag, a space, the key.
constexpr const char* kCacheTag = "kagec-cubin-v1";

bool read_file(const std::string& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream ss;
  ss << in.rdbuf();
  out = ss.str();
  return static_cast<bool>(in) || in.eof();
}

/// SHA-256 over every header under include_dir/runtime (sorted by path): a generated source includes
/// them, so a change in the semantics must change the cache key.
std::string runtime_headers_digest(const std::string& include_dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  const fs::path root = fs::path(include_dir) / "runtime";
  for (fs::recursive_directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string ext = it->path().extension().string();
    if (it->is_regular_file() && (ext == ".h" || ext == ".cuh" || ext == ".def")) files.push_back(it->path());
  }
  std::sort(files.begin(), files.end());
  Sha256 h;
  for (const fs::path& f : files) {
    std::string text;
    if (!read_file(f.string(), text)) continue;
    h.update(fs::relative(f, root).generic_string());
    h.update(std::string_view("\0", 1));
    h.update(text);
  }
  return h.hex_digest();
}

std::string nvrtc_text(nvrtcResult r, const char* what) { return std::string(what) + ": " + nvrtcGetErrorString(r); }

/// Writes `data` to `path` atomically: a unique temporary file in the same directory, then a rename.
bool write_atomically(const fs::path& path, const std::string& data) {
  std::random_device rd;
  const fs::path tmp = path.string() + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(rd());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return false;
    out.write(data.data(), static_cast<std::streamsize>(data.size()));
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      return false;
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) fs::remove(tmp, ec);
  return !ec;
}

/// The cubin stored under `key`, if the file exists and its first line names exactly that key.
std::optional<std::string> cache_lookup(const fs::path& file, const std::string& key) {
  std::string text;
  if (!read_file(file.string(), text)) return std::nullopt;
  const std::string header = std::string(kCacheTag) + " " + key + "\n";
  if (text.compare(0, header.size(), header) != 0) return std::nullopt;
  return text.substr(header.size());
}

}  // namespace

std::vector<std::string> nvrtc_option_list(const std::string& arch, const NvrtcOptions& options) {
  // --no-source-include: quoted includes come from include_dir alone, never from the working directory (a
  // checkout's runtime/ beside an installed one would otherwise mix two copies of the headers).
  std::vector<std::string> opts = {"--gpu-architecture=" + arch, "-std=c++20", "--fmad=false",
                                   "--no-source-include", "-I" + options.include_dir};
  opts.insert(opts.end(), options.extra_options.begin(), options.extra_options.end());
  return opts;
}

std::optional<std::string> nvrtc_compile(const std::string& source, const std::string& name,
                                         const std::vector<std::string>& options, std::string* error) {
  nvrtcProgram prog;
  nvrtcResult r = nvrtcCreateProgram(&prog, source.c_str(), name.c_str(), 0, nullptr, nullptr);
  if (r != NVRTC_SUCCESS) {
    *error = nvrtc_text(r, "nvrtcCreateProgram");
    return std::nullopt;
  }
  std::vector<const char*> opts;
  for (const std::string& o : options) opts.push_back(o.c_str());
  r = nvrtcCompileProgram(prog, static_cast<int>(opts.size()), opts.data());
  size_t log_size = 0;
  std::string log;
  if (nvrtcGetProgramLogSize(prog, &log_size) == NVRTC_SUCCESS && log_size > 1) {
    log.resize(log_size);
    if (nvrtcGetProgramLog(prog, log.data()) != NVRTC_SUCCESS) log.clear();
  }
  std::optional<std::string> cubin;
  if (r != NVRTC_SUCCESS) {
    *error = nvrtc_text(r, "nvrtcCompileProgram") + "\n" + log;
  } else {
    size_t size = 0;
    r = nvrtcGetCUBINSize(prog, &size);
    std::string bytes(size, '\0');
    if (r == NVRTC_SUCCESS) r = nvrtcGetCUBIN(prog, bytes.data());
    if (r == NVRTC_SUCCESS) {
      cubin = std::move(bytes);
    } else {
      *error = nvrtc_text(r, "nvrtcGetCUBIN");
    }
  }
  const nvrtcResult d = nvrtcDestroyProgram(&prog);
  if (d != NVRTC_SUCCESS && cubin) {
    *error = nvrtc_text(d, "nvrtcDestroyProgram");
    return std::nullopt;
  }
  return cubin;
}

bool cu_check(CUresult r, const char* what, std::string* error) {
  if (r == CUDA_SUCCESS) return true;
  *error = cu_error_text(r, what);
  return false;
}

std::string cu_error_text(CUresult r, const char* what) {
  if (r == CUDA_SUCCESS) return {};
  const char* name = nullptr;
  const char* msg = nullptr;
  if (cuGetErrorName(r, &name) != CUDA_SUCCESS) name = "unknown CUDA error";
  if (cuGetErrorString(r, &msg) != CUDA_SUCCESS) msg = "";
  return std::string(what) + ": " + name + " (" + msg + ")";
}

CUcontext cuda_primary_context(std::string* error) {
  CUresult r = cuInit(0);
  if (r != CUDA_SUCCESS) {
    *error = cu_error_text(r, "cuInit") + ": no usable CUDA driver or GPU; use the CPU backend";
    return nullptr;
  }
  CUdevice dev;
  r = cuDeviceGet(&dev, 0);
  if (r != CUDA_SUCCESS) {
    *error = cu_error_text(r, "cuDeviceGet") + ": no CUDA device; use the CPU backend";
    return nullptr;
  }
  CUcontext ctx = nullptr;
  r = cuDevicePrimaryCtxRetain(&ctx, dev);
  if (r == CUDA_SUCCESS) r = cuCtxSetCurrent(ctx);
  if (r != CUDA_SUCCESS) {
    *error = cu_error_text(r, "cuDevicePrimaryCtxRetain");
    return nullptr;
  }
  return ctx;
}

std::string kernel_cache_dir() {
  const char* off = std::getenv("KAGE_CACHE");
  if (off && std::string(off) == "off") return {};
  if (const char* dir = std::getenv("KAGE_CACHE_DIR"); dir && *dir) return dir;
  const char* home = std::getenv("HOME");
  return (fs::path(home && *home ? home : ".") / ".cache" / "kagec").string();
}

std::optional<CudaModule> CudaModule::load_image(const void* image, std::string* error) {
  if (!cuda_primary_context(error)) return std::nullopt;
  CUmodule m = nullptr;
  const CUresult r = cuModuleLoadData(&m, image);
  if (r != CUDA_SUCCESS) {
    *error = cu_error_text(r, "cuModuleLoadData");
    return std::nullopt;
  }
  return CudaModule(m);
}

std::optional<CudaModule> CudaModule::load_file(const std::string& path, std::string* error) {
  std::string image;
  if (!read_file(path, image)) {
    *error = path + ": cannot read";
    return std::nullopt;
  }
  std::optional<CudaModule> m = load_image(image.data(), error);
  if (!m) *error = path + ": " + *error;
  return m;
}

std::optional<std::string> device_arch(std::string* error) {
  if (!cuda_primary_context(error)) return std::nullopt;
  CUdevice dev;
  int major = 0, minor = 0;
  CUresult r = cuCtxGetDevice(&dev);
  if (r == CUDA_SUCCESS) r = cuDeviceGetAttribute(&major, CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MAJOR, dev);
  if (r == CUDA_SUCCESS) r = cuDeviceGetAttribute(&minor, CU_DEVICE_ATTRIBUTE_COMPUTE_CAPABILITY_MINOR, dev);
  if (r != CUDA_SUCCESS) {
    *error = cu_error_text(r, "cuDeviceGetAttribute");
    return std::nullopt;
  }
  return "sm_" + std::to_string(major) + std::to_string(minor);
}

std::optional<std::string> cubin_for(const std::string& source, const std::string& name, const NvrtcOptions& options,
                                     std::string* error, bool* cache_hit, bool read_cache) {
  if (cache_hit) *cache_hit = false;
  const std::optional<std::string> arch = device_arch(error);
  if (!arch) return std::nullopt;
  return cubin_for_arch(source, name, options, *arch, error, cache_hit, read_cache);
}

std::optional<std::string> cubin_for_arch(const std::string& source, const std::string& name,
                                          const NvrtcOptions& options, const std::string& arch, std::string* error,
                                          bool* cache_hit, bool read_cache) {
  if (cache_hit) *cache_hit = false;
  const std::vector<std::string> opts = nvrtc_option_list(arch, options);

  int nv_major = 0, nv_minor = 0;
  const nvrtcResult vr = nvrtcVersion(&nv_major, &nv_minor);
  if (vr != NVRTC_SUCCESS) {
    *error = nvrtc_text(vr, "nvrtcVersion");
    return std::nullopt;
  }
  Sha256 h;
  const std::string_view sep("\0", 1);
  for (const std::string& part : {std::string(kCacheTag), source, options.generator_version,
                                  std::to_string(nv_major) + "." + std::to_string(nv_minor), arch,
                                  runtime_headers_digest(options.include_dir)}) {
    h.update(part);
    h.update(sep);
  }
  for (const std::string& o : opts) {
    h.update(o);
    h.update(sep);
  }
  const std::string key = h.hex_digest();

  const std::string dir = kernel_cache_dir();
  const fs::path file = dir.empty() ? fs::path() : fs::path(dir) / (key + ".cubin");
  if (!dir.empty() && read_cache) {
    if (std::optional<std::string> cubin = cache_lookup(file, key)) {
      if (cache_hit) *cache_hit = true;
      return cubin;
    }
  }
  std::optional<std::string> cubin = nvrtc_compile(source, name, opts, error);
  if (!cubin) return std::nullopt;
  if (!dir.empty()) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    // A cache that cannot be written only costs the next load a compilation.
    if (!ec) write_atomically(file, std::string(kCacheTag) + " " + key + "\n" + *cubin);
  }
  return cubin;
}

std::optional<CudaModule> CudaModule::compile(const std::string& source, const std::string& name,
                                              const NvrtcOptions& options, std::string* error, bool* cache_hit) {
  bool hit = false;
  std::optional<std::string> cubin = cubin_for(source, name, options, error, &hit);
  if (!cubin) return std::nullopt;
  std::optional<CudaModule> m = load_image(cubin->data(), error);
  if (!m && hit) {  // a cached cubin that does not load is compiled again (and replaced)
    hit = false;
    cubin = cubin_for(source, name, options, error, nullptr, false);
    if (!cubin) return std::nullopt;
    m = load_image(cubin->data(), error);
  }
  if (cache_hit) *cache_hit = hit;
  return m;
}

CudaModule::CudaModule(CudaModule&& other) noexcept : module_(other.module_) { other.module_ = nullptr; }

CudaModule& CudaModule::operator=(CudaModule&& other) noexcept {
  if (this != &other) {
    if (module_) cuModuleUnload(module_);
    module_ = other.module_;
    other.module_ = nullptr;
  }
  return *this;
}

CudaModule::~CudaModule() {
  // Unloading at exit can fail once the context is gone; nothing is left to release then.
  if (module_) cuModuleUnload(module_);
}

CUfunction CudaModule::function(const char* name, std::string* error) const {
  CUfunction f = nullptr;
  const CUresult r = cuModuleGetFunction(&f, module_, name);
  if (r != CUDA_SUCCESS) {
    *error = cu_error_text(r, "cuModuleGetFunction") + ": " + name;
    return nullptr;
  }
  return f;
}

CUdeviceptr CudaModule::global(const char* name, size_t* bytes) const {
  CUdeviceptr p = 0;
  size_t size = 0;
  if (cuModuleGetGlobal(&p, &size, module_, name) != CUDA_SUCCESS) return 0;
  if (bytes) *bytes = size;
  return p;
}

}  // namespace kage
