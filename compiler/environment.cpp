// Environment::open: the front end, lowering and asset loading in one call.
#include "compiler/environment.h"

#include <sstream>

#include "compiler/resolve.h"
#include "compiler/source.h"

namespace kage {

EnvironmentResult Environment::from_lowered(const LoweredConfig& config, const EnvironmentOptions& options) {
  EnvironmentResult result;
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
  const std::optional<Spec> spec = analyze_file(config_path, resolve, sources, reader, diags);
  std::ostringstream text;
  print_text(diags, text);
  if (!spec || diags.has_errors()) {
    EnvironmentResult failed;
    failed.error = text.str() + config_path + ": the config has errors; fix them (kagec lint " + config_path + ")\n";
    return failed;
  }
  const LowerResult lowered = lower_spec(*spec);
  if (!lowered.ok()) {
    EnvironmentResult failed;
    failed.error = config_path + ": " + lowered.error_text();
    return failed;
  }
  EnvironmentResult result = from_lowered(*lowered.config, options);
  result.warnings = text.str() + result.warnings;
  return result;
}

}  // namespace kage
