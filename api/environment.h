// Environment::open: config file -> front end -> lowering -> assets -> a ready CpuEnv, errors as text.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "compiler/lower/lower.h"
#include "runtime/cpu/cpu_env.h"
#include "runtime/io/asset_pack.h"

namespace kage {

struct EnvironmentOptions {
  int32_t num_envs = 1;
  int32_t num_threads = 1;
  /// Resolve asset paths against this directory (as `--asset-root`); unset: the file that names them.
  std::optional<std::string> asset_root;
};

class Environment;

/// Bytes a CPU batch of this configuration holds (observations, states, layouts, render scratch).
uint64_t batch_bytes_estimate(const LoweredConfig& config, int64_t num_envs, int64_t num_threads);
/// The machine's physical memory in bytes (0 when unknown).
uint64_t physical_memory_bytes();
/// "1.5 GiB".
std::string gib_text(uint64_t bytes);
/// Why a CPU batch of this configuration does not fit (more than half of the machine's memory), naming
/// whether the environments or the threads take it and the fix; empty when it fits.
std::string memory_refusal(const LoweredConfig& config, int64_t num_envs, int64_t num_threads);

/// Result of Environment::open: `env`, or the diagnostics / loading errors as text in `error`.
struct [[nodiscard]] EnvironmentResult {
  std::unique_ptr<Environment> env;
  std::string error;
  /// Warnings printed along the way (front end diagnostics, asset loader messages).
  std::string warnings;
  bool ok() const { return env != nullptr; }
};

/// A batch of CPU environments with the configuration and assets it was built from.
class Environment {
 public:
  /// Runs the whole pipeline on a config file.
  static EnvironmentResult open(const std::string& config_path, const EnvironmentOptions& options);
  /// Builds the batch from an already lowered configuration (loads its assets).
  static EnvironmentResult from_lowered(const LoweredConfig& config, const EnvironmentOptions& options);

  CpuEnv& env() { return *env_; }
  const CpuEnv& env() const { return *env_; }
  const LoweredConfig& config() const { return config_; }
  const AssetPack& assets() const { return pack_; }

 private:
  Environment() = default;
  LoweredConfig config_;
  AssetPack pack_;
  std::unique_ptr<CpuEnv> env_;
};

}  // namespace kage
