// GPU batch runtime: N environments of one compiled config in device memory, stepped and rendered by
// the kernels of a loaded module (kernels.cuh entry points). Observations stay on the device.
#pragma once

#include <cuda.h>

#include <cstdint>
#include <optional>
#include <string>

#include "runtime/cuda/device_envs.h"
#include "runtime/cuda/module_loader.h"
#include "runtime/latent/latent_params.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_params.h"

namespace kage {

/// Bytes of one environment's device state: latent state, layout, visual state, seed, action, reward,
/// flags and info (the observation not included).
size_t device_state_bytes_per_env(const LatentParams& lp);

/// Leading bytes of VisualState that a step or a render of this config can read or write: the entity
/// arrays of disabled entity kinds are never touched, so the rendering blocks copy only this prefix.
int32_t visual_state_extent(const VisualParams& vp, const AssetView& assets);

class DeviceBatch {
 public:
  /// A batch of `num_envs` environments running `module`'s kernels with these parameters (uploaded to
  /// the generic build's __constant__ parameters when the module has them). `host_assets` points to
  /// host memory; it is copied to the device. Nothing on error, with the reason in `error`.
  static std::optional<DeviceBatch> create(const CudaModule& module, const LatentParams& lp, const VisualParams& vp,
                                           const AssetView& host_assets, int32_t num_envs, std::string* error);

  DeviceBatch(DeviceBatch&& other) noexcept;
  DeviceBatch& operator=(DeviceBatch&&) = delete;
  DeviceBatch(const DeviceBatch&) = delete;
  DeviceBatch& operator=(const DeviceBatch&) = delete;
  ~DeviceBatch();

  /// Starts episode 0 of every environment (`seeds`: size() host values) and renders the observations.
  bool reset(const uint64_t* seeds, std::string* error);
  /// Uploads size() host actions and runs one step (with autoreset), then renders the observations.
  bool step(const int32_t* actions, std::string* error);
  /// step() with the actions already in device memory (actions()).
  bool step_device_actions(std::string* error);
  /// One step without rendering (observations are left as they were).
  bool step_no_render(std::string* error);
  /// Fills actions() with uniform random actions in [0, 8) for step t, on the device.
  bool sample_actions(uint64_t seed, uint32_t t, std::string* error);

  int32_t size() const { return envs_.num_envs; }
  /// Device pointers ([N][H][W][3] uint8, [N] float, [N] uint8, [N] uint8, [N] StepInfo, [N] int32).
  CUdeviceptr obs() const { return reinterpret_cast<CUdeviceptr>(envs_.obs); }
  /// Copies every observation into host memory (size() * obs_bytes_per_env() bytes).
  bool download_obs(uint8_t* host, std::string* error) const;
  CUdeviceptr reward() const { return reinterpret_cast<CUdeviceptr>(envs_.reward); }
  CUdeviceptr terminated() const { return reinterpret_cast<CUdeviceptr>(envs_.terminated); }
  CUdeviceptr truncated() const { return reinterpret_cast<CUdeviceptr>(envs_.truncated); }
  CUdeviceptr info() const { return reinterpret_cast<CUdeviceptr>(envs_.info); }
  CUdeviceptr actions() const { return reinterpret_cast<CUdeviceptr>(envs_.actions); }
  /// The device view the kernels get (latent, layout and visual state pointers included).
  const DeviceEnvs& envs() const { return envs_; }
  size_t obs_bytes_per_env() const { return obs_stride_; }

 private:
  DeviceBatch() = default;
  bool launch_per_env(CUfunction f, std::string* error);
  /// Launches the render kernel: frames_per_block_ environments per block.
  bool launch_render(std::string* error);

  DeviceEnvs envs_{};
  size_t obs_stride_ = 0;
  int32_t render_threads_ = 0;
  int32_t render_smem_ = 0;
  int32_t frames_per_block_ = 1;
  CUdeviceptr state_ = 0;   ///< one allocation for every per-env array but the observations
  CUdeviceptr obs_buf_ = 0;
  CUdeviceptr assets_ = 0;
  CUfunction reset_ = nullptr;
  CUfunction step_ = nullptr;
  CUfunction render_ = nullptr;
  CUfunction sample_actions_ = nullptr;
};

}  // namespace kage
