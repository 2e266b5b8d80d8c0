// The throughput measurements shared by kage_gpu_throughput and `kagec bench --gpu`: a device-to-device
// copy roofline and the step rates of one batch (step + render, state only), so both
// report numbers taken the same way.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>

#include "runtime/cuda/module_loader.h"
#include "runtime/latent/latent_params.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_params.h"

namespace kage::throughput {

/// A CUDA call or a batch operation failed while measuring; what() says which.
class MeasureError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Median of 5 timings (ms) of `run_once`, each bracketed by events on the default stream.
double median_ms(const std::function<void()>& run_once);

/// Device-to-device copy bandwidth in GB/s (bytes read + written), 4 GiB each way.
double measure_roofline();

/// The FP32 rate in GFLOP/s (fused multiply-adds counted as 2), from kage_fp32_peak of `module`
/// (verify/throughput/modules/fp32_peak.cu) on a grid that fills the device.
double measure_fp32_rate(const CudaModule& module);

/// What one batch of one config is run with.
struct MeasureTarget {
  const CudaModule* module;
  LatentParams lp;
  VisualParams vp;
  AssetView assets;
};

/// Steps/s of n environments (each step: random actions sampled on the device, then the step).
/// Rates that were not asked for are 0.
struct Timing {
  double render_steps_per_s;  ///< DeviceBatch's step: step + autoreset, then render the observations
  double state_steps_per_s;   ///< state-only step (observations left as they were)
};

/// Times one batch of n environments: the rate with observations when `render`, the state-only rate
/// when `state_too`.
Timing time_config(const MeasureTarget& t, int32_t n, bool render, bool state_too);

}  // namespace kage::throughput
