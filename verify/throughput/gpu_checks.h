// Correctness checks of the GPU batch against the CPU batch (same seeds and actions): latent
// state and layout identical, visual state identical, observations within a tolerance; output
// buffers poisoned before every checked launch so that unwritten bytes show.
#pragma once

#include <string>

#include "runtime/cuda/module_loader.h"
#include "runtime/latent/latent_params.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_params.h"

namespace kage::throughput {

/// What a check found.
struct CheckResult {
  bool ok = false;
  int32_t state_mismatches = 0;  ///< (environment, checkpoint) pairs whose states differ
  int32_t obs_max_abs = 0;       ///< worst observation code difference over all checkpoints
  double obs_equal = 1.0;        ///< share of equal observation values
  std::string error;             ///< a CUDA error, if one stopped the check
  std::string summary() const;
};

/// Runs reset and `steps` steps (random actions; checkpoints at reset, steps 1-3, 100 and around
/// the first automatic reset) on `envs` environments, then the state-only kernel over the same steps.
/// Passes when every state matches and observations differ by at most `max_code_diff`.
CheckResult check_against_cpu(const CudaModule& module, const LatentParams& lp, const VisualParams& vp,
                              const AssetView& assets, int32_t envs, int32_t steps, int32_t max_code_diff);

}  // namespace kage::throughput
