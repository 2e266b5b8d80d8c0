// CPU environment: the checks of create(), then a HostBatch on the generic path.
#include "runtime/cpu/cpu_env.h"

#include "runtime/latent/layout.h"

namespace kage {

std::unique_ptr<CpuEnv> CpuEnv::create(const LatentParams& latent, const VisualParams& visual, const AssetView& assets,
                                       int32_t num_envs, int32_t num_threads) {
  if (latent.screen_h != visual.H || latent.screen_w != visual.W) return nullptr;
  if (!latent_params_supported(latent) || num_envs <= 0 || num_threads <= 0) return nullptr;
  return std::unique_ptr<CpuEnv>(new CpuEnv(latent, visual, assets, num_envs, num_threads));
}

CpuEnv::CpuEnv(const LatentParams& latent, const VisualParams& visual, const AssetView& assets, int32_t num_envs,
               int32_t num_threads)
    : batch_(generic_host_kernels(latent, visual), assets, num_envs, num_threads, /*info_shows_new_episode=*/false) {}

void CpuEnv::reset(const uint64_t* seeds) { batch_.reset(seeds, nullptr); }

void CpuEnv::step(const int32_t* actions) { batch_.step(actions); }

}  // namespace kage
