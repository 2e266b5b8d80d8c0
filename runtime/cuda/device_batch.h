// GPU batch runtime: N environments of one compiled config in device memory, stepped and rendered by
// the kernels of a loaded module (kernels.cuh entry points), or of several configs (a mixture): one part
// per config, each running its own module's kernels on its rows of the one set of buffers. Observations
// stay on the device.
//
// Every launch and copy is ordered on one CUDA stream (set_stream; the legacy default stream unless set), in
// call order, so a consumer on that stream needs no synchronisation. A mixture's step forks its parts onto
// streams of their own and joins them back (events), so that small parts step side by side instead of one
// after another. Nothing here waits for the device except the calls documented as synchronising (downloads,
// save_state, load_state).
#pragma once

#include <cuda.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/cuda/device_envs.h"
#include "runtime/cuda/module_loader.h"
#include "runtime/latent/latent_params.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_params.h"

namespace kage {

/// Leading bytes of VisualState that a step or a render of this config can read or write: the entity
/// arrays of disabled entity kinds are never touched, so the rendering blocks copy only this prefix.
int32_t visual_state_extent(const VisualParams& vp, const AssetView& assets);

/// A config's assets in device memory: one allocation, and a view whose pointers point into it.
struct DeviceAssets {
  CUdeviceptr memory = 0;  ///< freed by the owner (cuMemFree)
  AssetView view{};
};

/// Copies host assets into the current context's device memory (synchronous copies); nothing on error.
std::optional<DeviceAssets> upload_assets(const AssetView& host_assets, std::string* error);

/// Writes the parameters into the generic build's __constant__ memory where `module` has it (a specialized
/// build has them folded in); false with a message on error.
[[nodiscard]] bool upload_dynamic_params(const CudaModule& module, const LatentParams& lp, const VisualParams& vp,
                                         std::string* error);

/// Actions in device memory: element env * stride of an int32 or int64 array.
struct DeviceActions {
  CUdeviceptr data = 0;
  int64_t stride = 1;
  bool is_int64 = false;
};

/// One config of a batch: `num_envs` environments running `module`'s kernels with these parameters
/// (uploaded to the module's __constant__ parameters when it has them, so two parts never share a module
/// instance). `host_assets` points to host memory; it is copied to the device.
struct DevicePartSource {
  const CudaModule* module = nullptr;  ///< must outlive the batch
  LatentParams lp{};
  VisualParams vp{};
  AssetView host_assets{};
  int32_t num_envs = 0;
  /// What the module's code is (its config's Spec hash, for a specialized module): parts of one code in
  /// several batches step in one launch (step_together). Empty (a generic module, whose parameters are its
  /// own __constant__ memory): the part launches alone.
  std::string code;
};

struct GroupPlan;

/// Threads per block of the kernels with one thread per environment (reset, step, random actions).
constexpr int32_t kPerEnvThreads = 256;

class DeviceBatch {
 public:
  /// A batch of `num_envs` environments running `module`'s kernels with these parameters (uploaded to
  /// the generic build's __constant__ parameters when the module has them). `host_assets` points to
  /// host memory; it is copied to the device. Nothing on error, with the reason in `error`.
  static std::optional<DeviceBatch> create(const CudaModule& module, const LatentParams& lp, const VisualParams& vp,
                                           const AssetView& host_assets, int32_t num_envs, std::string* error);
  /// A batch of several parts (a mixture), numbered part by part: the first part's environments first.
  /// One allocation of per-environment state and one of observations for all of them; each part's
  /// kernels see only its own rows (a DeviceEnvs whose pointers start at its first environment), so
  /// environment i equals environment i - first of its config run alone. The parts must share the layout
  /// segment count (one hidden game) and the frame size. Nothing on error, with the reason in `error`.
  static std::optional<DeviceBatch> create(const std::vector<DevicePartSource>& parts, std::string* error);

  DeviceBatch(DeviceBatch&& other) noexcept;
  DeviceBatch& operator=(DeviceBatch&&) = delete;
  DeviceBatch(const DeviceBatch&) = delete;
  DeviceBatch& operator=(const DeviceBatch&) = delete;
  ~DeviceBatch();

  /// The stream of every later launch and copy (0: the legacy default stream).
  void set_stream(CUstream stream) { stream_ = stream; }
  CUstream stream() const { return stream_; }

  /// Starts episode 0 with the new seeds of the environments with mask[env] != 0 (every one when `mask`
  /// is null) and renders the observations; `seeds` and `mask` are size() host values. No environment
  /// is final afterwards.
  bool reset(const uint64_t* seeds, const uint8_t* mask, std::string* error);
  /// Uploads size() host actions and runs one step (with autoreset), then renders the observations.
  bool step(const int32_t* actions, std::string* error);
  /// One step reading the actions from device memory (no copy), then the render.
  bool step(const DeviceActions& actions, std::string* error);
  /// step() with the actions already in the batch's own buffer (actions()).
  bool step_device_actions(std::string* error);
  /// Steps batches[i] by row i of `actions` (device memory), as batches[i]->step would, with one step launch
  /// and one render launch per code over every part of every batch that runs it (a pack's runs of one
  /// config, a mixture's parts across runs) instead of a launch pair per batch part. Launched on batches[0]'s
  /// stream after the work queued so far on the others' streams, which are ordered after the step (the codes'
  /// launches fork onto streams of their own and join back). The launches' plan is made at a list's first
  /// call, outside any stream capture, and kept by batches[0]: later calls and CUDA graphs of them reuse it.
  static bool step_together(const std::vector<DeviceBatch*>& batches, const ActionRows& actions, std::string* error);
  /// One step without rendering (observations are left as they were).
  bool step_no_render(std::string* error);
  /// Fills actions() (every environment of every part) with uniform random actions in [0, 8) for step t,
  /// on the device.
  bool sample_actions(uint64_t seed, uint32_t t, std::string* error);
  /// The first out-of-range device action a finished step reported (none if none; `env` is the batch's
  /// index), then forgets it. Reads host-mapped memory: no synchronisation, so a report arrives once its
  /// step has run.
  std::optional<ActionError> take_action_error();

  int32_t size() const { return envs_.num_envs; }
  /// Device pointers: [N][H][W][3] uint8 observations, [N] float reward, [N] uint8 flags.
  CUdeviceptr obs() const { return reinterpret_cast<CUdeviceptr>(envs_.obs); }
  CUdeviceptr reward() const { return reinterpret_cast<CUdeviceptr>(envs_.reward); }
  CUdeviceptr terminated() const { return reinterpret_cast<CUdeviceptr>(envs_.terminated); }
  CUdeviceptr truncated() const { return reinterpret_cast<CUdeviceptr>(envs_.truncated); }
  CUdeviceptr actions() const { return reinterpret_cast<CUdeviceptr>(envs_.actions.data); }
  /// [N] device columns of the info; final_*: the finished episodes of the last step (final_mask 1).
  const InfoArrays& info() const { return envs_.info; }
  const InfoArrays& final_info() const { return envs_.final_info; }
  CUdeviceptr final_mask() const { return reinterpret_cast<CUdeviceptr>(envs_.final_mask); }
  CUdeviceptr final_obs() const { return reinterpret_cast<CUdeviceptr>(envs_.final_obs); }
  /// Copies every observation into host memory (size() * obs_bytes_per_env() bytes); synchronises.
  bool download_obs(uint8_t* host, std::string* error) const;
  /// The device view of the whole batch (latent, layout and visual state pointers included); its assets
  /// are the first part's. A batch of one part launches its kernels on this very view.
  const DeviceEnvs& envs() const { return envs_; }
  /// The number of parts (1 unless a mixture), and each part's first environment and count.
  int32_t part_count() const { return static_cast<int32_t>(parts_.size()); }
  int32_t part_first(int32_t part) const { return parts_[static_cast<size_t>(part)].first; }
  int32_t part_size(int32_t part) const { return parts_[static_cast<size_t>(part)].envs.num_envs; }
  size_t obs_bytes_per_env() const { return obs_stride_; }
  int32_t segment_bytes() const { return segment_count_; }

  /// The saved state (runtime/cpu/batch_state.h) under `spec_hash`; synchronises.
  bool save_state(const std::string& spec_hash, std::vector<uint8_t>* out, std::string* error) const;
  /// Restores a saved state and renders its observations (each part with its own kernels).
  bool load_state(const uint8_t* data, size_t size, const std::string& spec_hash, std::string* error);
  /// Waits until every launch and copy of this batch has finished.
  bool synchronize(std::string* error) const;

 private:
  /// One config's environments [first, first + envs.num_envs): its kernels, its render launch and its
  /// view of the batch's buffers.
  struct Part {
    int32_t first = 0;
    DeviceEnvs envs{};  ///< every per-env pointer offset by `first`; assets the part's own
    CUfunction reset = nullptr;
    CUfunction step = nullptr;
    CUfunction render = nullptr;       ///< also step_together's, over a table of rows
    CUfunction step_rows = nullptr;    ///< the grouped step (step_together)
    std::string code;                  ///< DevicePartSource::code
    bool frame_passes = false;         ///< needs_frame_passes of its config (one frame per rendering block)
    int32_t render_threads = 0;
    int32_t render_smem = 0;
    int32_t frames_per_block = 1;
    CUdeviceptr assets = 0;     ///< owned
    CUstream stream = nullptr;  ///< owned, a mixture's part only: where its step and render run
    CUevent stepped = nullptr;  ///< owned, a mixture's part only: recorded after them, joined by the batch's stream
  };

  DeviceBatch() = default;
  bool launch_per_env(CUfunction f, const DeviceEnvs& envs, CUstream stream, std::string* error);
  /// Launches a part's render kernel on `stream`: frames_per_block environments per block.
  bool launch_render(const Part& p, CUstream stream, std::string* error);
  /// A mixture's parts: a stream and an event each, and the fork event.
  bool create_part_streams(std::string* error);
  /// Every part's render, in part order.
  bool launch_renders(std::string* error);
  /// One step of every part reading `source` (element env * stride, env the batch's index), then renders.
  bool launch_step(const ActionSource& source, bool render, std::string* error);
  /// The plan of step_together over `batches` (this batch first): found among plans_, or made.
  GroupPlan* group_plan(const std::vector<DeviceBatch*>& batches, std::string* error);
  /// Queues the copies between the saved-state sections of `blob` and the device (to_host: download).
  bool copy_state(uint8_t* blob, bool to_host, std::string* error) const;

  DeviceEnvs envs_{};
  std::vector<Part> parts_;
  CUstream stream_ = nullptr;
  size_t obs_stride_ = 0;
  int32_t segment_count_ = 0;
  CUdeviceptr state_ = 0;    ///< one allocation for every per-env array but the observations
  CUdeviceptr obs_buf_ = 0;  ///< observations, then final observations
  CUdeviceptr step_counts_ = 0;  ///< a StepCount per part: its step launches, numbered in an action's report
  uint8_t* reset_mask_ = nullptr;        ///< device buffer for a reset's mask
  std::vector<uint64_t> seeds_;          ///< host copy of the device seeds
  ActionError* action_error_ = nullptr;  ///< host-mapped, one per part (its env is the part's index)
  CUfunction sample_actions_ = nullptr;  ///< the first part's (every module's is the same code)
  CUevent fork_ = nullptr;               ///< a mixture only: recorded on stream_, waited for by the parts' streams
  uint64_t serial_ = 0;                  ///< this batch's number in the process: a plan names its batches by it
  int32_t multiprocessors_ = 0;
  std::vector<std::unique_ptr<GroupPlan>> plans_;  ///< step_together's plans led by this batch
};

}  // namespace kage
