// kage: the public C++ API. Open a config (a YAML file, or a directory written by `kagec compile`),
// pick a backend, then reset(seeds) / step(actions) a batch of environments.
//
//   kage::Options o;
//   o.num_envs = 64;
//   std::string err;
//   auto env = kage::open("configs/throughput/simplest.yaml", o, &err);   // or "out/simplest" (compiled)
//   if (!env) { std::cerr << err; return 1; }
//   env->reset(seeds);                  // seeds: num_envs uint64
//   env->step(actions);                 // actions: num_envs int32 (bit 0 left, bit 1 right, bit 2 jump)
//   const uint8_t* obs = env->obs();    // [num_envs][H][W][3]; device memory on the GPU backend
//
// No exception crosses this API: failures return null / false with a message in `error`.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace kage {

enum class Backend {
  kCpu,  ///< host memory; a compiled dir runs its generated kernels_host.so, a YAML the generic path
  kGpu,  ///< device memory; a compiled dir loads kernels.fatbin (else NVRTC), a YAML is compiled by NVRTC
};

struct Options {
  Backend backend = Backend::kCpu;
  int32_t num_envs = 1;
  int32_t num_threads = 1;  ///< CPU worker threads; results do not depend on it
  /// YAML only: resolve asset paths against this directory (empty: the file that names them).
  std::string asset_root;
};

/// Per-environment info of the last reset or step (spec 5.8); for an environment whose episode just
/// ended (and was reset) they describe the finished episode's last step.
enum class InfoField { kX, kY, kVx, kVy, kPassedDistance, kProgress, kEpisodeReturn };

/// A batch of environments of one configuration.
class Env {
 public:
  virtual ~Env() = default;

  /// Starts episode 0 of every environment. `seeds`: num_envs() host values.
  [[nodiscard]] virtual bool reset(const uint64_t* seeds, std::string* error = nullptr) = 0;
  /// One step; an environment whose episode ends is reset at once. `actions`: num_envs() host values.
  [[nodiscard]] virtual bool step(const int32_t* actions, std::string* error = nullptr) = 0;

  virtual Backend backend() const = 0;
  virtual int32_t num_envs() const = 0;
  virtual int32_t height() const = 0;
  virtual int32_t width() const = 0;
  /// SHA-256 of the configuration's canonical Spec.
  virtual const std::string& spec_hash() const = 0;

  /// Outputs of the last reset or step: host pointers on the CPU backend, device pointers (CUdeviceptr
  /// values) on the GPU backend. Valid until the next call.
  virtual const uint8_t* obs() const = 0;         ///< [N][H][W][3] uint8, row-major
  virtual const float* reward() const = 0;        ///< [N]
  virtual const uint8_t* terminated() const = 0;  ///< [N] 0/1
  virtual const uint8_t* truncated() const = 0;   ///< [N] 0/1
  /// CPU: [N] floats of one info field. GPU: null (read the StepInfo array of runtime/cuda instead).
  virtual const float* info(InfoField field) const = 0;
  /// Copies the observations of the last reset or step (num_envs() * height() * width() * 3 bytes)
  /// into host memory `dst`, on either backend.
  [[nodiscard]] virtual bool copy_obs(uint8_t* dst, std::string* error = nullptr) const = 0;
};

/// Opens `path`: a directory with manifest.json (from `kagec compile`) or a YAML config. Null on error.
std::unique_ptr<Env> open(const std::string& path, const Options& options, std::string* error);

/// Whether this build can run the GPU backend (the CUDA runtime pieces were compiled in).
bool gpu_backend_built();

}  // namespace kage
