// kage.jax's configs, by Spec hash: a process-wide registry that kage.jax.make_env fills and the XLA FFI
// handlers read. A compiled XLA program names its config by the Spec hash (an FFI attribute), which means
// the same in every process, so JAX's persistent compilation cache stays correct; a pointer would not.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "runtime/cpu/host_batch.h"
#include "runtime/io/asset_pack.h"
#include "runtime/latent/latent_params.h"
#include "runtime/visual/visual_params.h"

namespace kage::jax {

/// One config as the handlers need it. Immutable once registered.
struct JaxConfig {
  std::string spec_hash;
  std::string path;           ///< the YAML file or `kagec compile` directory it was loaded from
  bool compiled_dir = false;  ///< `path` is a compile directory (the GPU loads its fatbin or source)
  LatentParams latent{};
  VisualParams visual{};
  AssetPack assets;
  AssetView asset_view{};  ///< host pointers into `assets`
  /// The CPU handlers' semantics: the generic path over these parameters, bit for bit the generated
  /// host code (the equivalence tests), so a compile directory needs no kernels_host.so here.
  std::unique_ptr<HostKernels> host;
  int32_t segment_count = 0;   ///< layout bytes an environment uses
  int32_t segment_stride = 0;  ///< its row in the state: segment_count rounded up to 4, as on the GPU

  size_t frame_bytes() const { return static_cast<size_t>(visual.H) * static_cast<size_t>(visual.W) * 3; }
};

/// Result of register_config: `config`, or the reason in `error`.
struct [[nodiscard]] RegisterResult {
  std::shared_ptr<const JaxConfig> config;
  std::string error;
};

/// Loads `path` (asset paths resolved against `asset_root` when it is not empty) and registers it under
/// its Spec hash. A hash registered before keeps its first entry (equal hashes mean equal configs).
RegisterResult register_config(const std::string& path, const std::string& asset_root);

/// The config registered under `spec_hash`, or null.
std::shared_ptr<const JaxConfig> find_config(std::string_view spec_hash);

}  // namespace kage::jax
