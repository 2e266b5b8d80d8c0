// Dynamic isolation evidence of a train/eval pair (design.md "Latent and visual are separated"):
// equal latent Spec parts, a byte-identical generated dynamics section, identical latent trajectories
// under the same seeds and actions, and eval frames that do differ from train.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "compiler/sema/schema.h"
#include "compiler/sema/spec.h"

namespace kage {

struct IsolationOptions {
  std::vector<uint64_t> seeds = {0, 1, 2};  ///< K environments, one seed each
  int32_t steps = 200;                      ///< T steps after the reset
  /// Whether the pair may change the hidden game (its declared axis is latent): then only the frame
  /// evidence is required.
  bool latent_pair = false;
};

struct IsolationEvidence {
  bool latent_spec_equal = false;
  bool dynamics_source_identical = false;
  std::string train_latent_hash, eval_latent_hash;  ///< SHA-256 of each latent section
  bool trajectories_identical = false;
  int32_t first_divergent_step = -1;  ///< -1 when identical
  double mean_abs_pixel_diff = 0;     ///< over every frame byte of every env and step
  bool frames_differ = false;
  std::vector<std::string> problems;  ///< why the evidence fails; empty when it holds
  bool ok() const { return problems.empty(); }
  Json to_json(const IsolationOptions& options) const;
};

/// Lowers both Specs, generates both latent sections and runs both on the CPU path (assets loaded as
/// the specs name them). Lowering or loading failures are reported as problems.
IsolationEvidence dynamic_isolation(const Spec& train, const Spec& eval, const Schema& schema,
                                    const IsolationOptions& options);

}  // namespace kage
