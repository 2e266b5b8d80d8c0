// Environment::open: the front end, lowering and asset loading in one call.
#include "api/environment.h"

#include <unistd.h>

#include <algorithm>
#include <iomanip>
#include <sstream>

#include "compiler/lower/load_lowered.h"
#include "runtime/latent/latent_params.h"
#include "runtime/visual/render.h"

namespace kage {

uint64_t batch_bytes_estimate(const LoweredConfig& config, int64_t num_envs, int64_t num_threads) {
  const uint64_t frame = uint64_t(config.visual.H) * uint64_t(config.visual.W) * 3;
  const uint64_t per_env = 2 * frame /* observation, final observation */ + sizeof(LatentState) +
                           sizeof(VisualState) + uint64_t(layout_segment_count(config.latent)) + 256 /* info */;
  const uint64_t per_thread = uint64_t(render_scratch_floats(config.visual)) * sizeof(float);
  return uint64_t(std::max<int64_t>(num_envs, 0)) * per_env + uint64_t(std::max<int64_t>(num_threads, 0)) * per_thread;
}

uint64_t physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : 0;
}

std::string gib_text(uint64_t bytes) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << double(bytes) / double(uint64_t(1) << 30) << " GiB";
  return s.str();
}

std::string memory_refusal(const LoweredConfig& config, int64_t num_envs, int64_t num_threads) {
  const uint64_t need = batch_bytes_estimate(config, num_envs, num_threads), have = physical_memory_bytes();
  if (!have || need <= have / 2) return "";
  // Name what takes the memory: the environments, or the threads' render scratch.
  const uint64_t for_threads = batch_bytes_estimate(config, 0, num_threads);
  return "cannot build " + std::to_string(num_envs) + " environments of " + std::to_string(config.visual.H) + "x" +
         std::to_string(config.visual.W) + " observations on " + std::to_string(num_threads) + " threads: they need " +
         gib_text(need) + " (" + gib_text(for_threads) + " of it the threads' render scratch), more than half of this " +
         "machine's " + gib_text(have) +
         (for_threads > need / 2 ? "; use fewer threads" : "; use fewer environments or smaller observations");
}

EnvironmentResult Environment::from_lowered(const LoweredConfig& config, const EnvironmentOptions& options) {
  EnvironmentResult result;
  // Refused before anything is allocated: a batch larger than half the machine would fail or swap.
  result.error = memory_refusal(config, options.num_envs, options.num_threads);
  if (!result.error.empty()) {
    result.error += "\n";
    return result;
  }
  AssetPackResult loaded = load_asset_pack(config.assets);
  for (const std::string& w : loaded.warnings) result.warnings += w + "\n";
  if (!loaded.ok()) {
    result.error = loaded.error + "\n";
    return result;
  }
  std::unique_ptr<Environment> env(new Environment());
  env->config_ = config;
  env->pack_ = std::move(*loaded.pack);
  env->env_ = CpuEnv::create(config.latent, config.visual, env->pack_.view(), options.num_envs, options.num_threads);
  if (!env->env_) {
    result.error = "cannot build " + std::to_string(options.num_envs) + " environments on " +
                   std::to_string(options.num_threads) + " threads: both must be positive\n";
    return result;
  }
  result.env = std::move(env);
  return result;
}

EnvironmentResult Environment::open(const std::string& config_path, const EnvironmentOptions& options) {
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  ResolveOptions resolve;
  resolve.asset_root = options.asset_root;
  const LoweredFile loaded = load_lowered(config_path, resolve, sources, reader, diags);
  std::ostringstream text;
  print_text(diags, text);
  if (!loaded.spec) {
    EnvironmentResult failed;
    failed.error = text.str() + config_path + ": the config has errors; fix them (kagec lint " + config_path + ")\n";
    return failed;
  }
  if (!loaded.ok()) {
    EnvironmentResult failed;
    failed.error = config_path + ": " + loaded.lower_errors;
    return failed;
  }
  EnvironmentResult result = from_lowered(*loaded.config, options);
  result.warnings = text.str() + result.warnings;
  return result;
}

}  // namespace kage
