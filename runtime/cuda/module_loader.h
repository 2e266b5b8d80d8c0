// Loading compiled configs onto the GPU through the CUDA driver API: a fatbin or cubin file, or a
// generated source compiled at load time with NVRTC for the device's architecture, with the cubin
// cached on disk (keyed by SHA-256 of everything that determines it).
#pragma once

#include <cuda.h>

#include <optional>
#include <string>
#include <vector>

namespace kage {

/// "what: CUDA error name (message)" for a failed driver call; empty for CUDA_SUCCESS.
std::string cu_error_text(CUresult r, const char* what);

/// Whether driver call `what` returned CUDA_SUCCESS; if not, its cu_error_text in `error`.
bool cu_check(CUresult r, const char* what, std::string* error);

/// The primary context of device 0, made current on the calling thread. Null with a message in
/// `error` when there is no driver or no device (the CPU backend still works then).
CUcontext cuda_primary_context(std::string* error);

/// Options of a run-time compilation.
struct NvrtcOptions {
  /// Directory that holds runtime/ (the generated sources include "runtime/...").
  std::string include_dir;
  /// Version of the generator that wrote the source; part of the cache key.
  std::string generator_version;
  /// Further NVRTC options (the defaults are -std=c++20, --fmad=false and the device's arch).
  std::vector<std::string> extra_options;
};

/// The NVRTC options of a run-time compilation for `arch` (e.g. "sm_90"): the one list that the
/// loader uses and that tests/cuda/nvrtc_check.cpp compiles with.
std::vector<std::string> nvrtc_option_list(const std::string& arch, const NvrtcOptions& options);

/// Compiles `source` with NVRTC to a cubin (no driver, no GPU needed); null with the log in `error`.
std::optional<std::string> nvrtc_compile(const std::string& source, const std::string& name,
                                         const std::vector<std::string>& options, std::string* error);

/// The architecture of the current device ("sm_90"); nullopt with a message when there is no driver or
/// no device.
std::optional<std::string> device_arch(std::string* error);

/// The cubin of `source` for `arch`: from the cache, or compiled with NVRTC and stored there. Needs no
/// driver and no GPU. Thread-safe. `cache_hit` and `read_cache` as for cubin_for.
std::optional<std::string> cubin_for_arch(const std::string& source, const std::string& name,
                                          const NvrtcOptions& options, const std::string& arch, std::string* error,
                                          bool* cache_hit = nullptr, bool read_cache = true);

/// The cubin of `source` for the current device: from the cache, or compiled with NVRTC and stored
/// there. Thread-safe (each call makes the primary context current on its thread), so several
/// configs can compile at once. `cache_hit`, if given, tells which happened; `read_cache` false
/// compiles even when the cache holds the cubin.
std::optional<std::string> cubin_for(const std::string& source, const std::string& name, const NvrtcOptions& options,
                                     std::string* error, bool* cache_hit = nullptr, bool read_cache = true);

/// Where the cubin cache lives: $KAGE_CACHE_DIR, else ~/.cache/kagec; empty when KAGE_CACHE=off.
std::string kernel_cache_dir();

/// A loaded module (owns the CUmodule; move-only).
class CudaModule {
 public:
  /// Loads a fatbin or cubin image from memory.
  static std::optional<CudaModule> load_image(const void* image, std::string* error);
  /// Loads a fatbin or cubin file.
  static std::optional<CudaModule> load_file(const std::string& path, std::string* error);
  /// Compiles `source` with NVRTC for the current device (or takes the cubin from the cache) and loads
  /// it. `name` is the source's file name in diagnostics. `cache_hit`, if given, tells which happened.
  static std::optional<CudaModule> compile(const std::string& source, const std::string& name,
                                           const NvrtcOptions& options, std::string* error,
                                           bool* cache_hit = nullptr);

  CudaModule(CudaModule&& other) noexcept;
  CudaModule& operator=(CudaModule&& other) noexcept;
  CudaModule(const CudaModule&) = delete;
  CudaModule& operator=(const CudaModule&) = delete;
  ~CudaModule();

  /// The kernel `name`, or null with a message in `error`.
  CUfunction function(const char* name, std::string* error) const;
  /// The device address and size of global `name`, or 0 when the module has none.
  CUdeviceptr global(const char* name, size_t* bytes) const;

 private:
  explicit CudaModule(CUmodule m) : module_(m) {}
  CUmodule module_ = nullptr;
};

}  // namespace kage
