// kage.jax's config registry: a YAML file through the front end and lowering, or a compile directory's
// params.bin and assets.bin, kept by Spec hash for the life of the process.
#include "api/jax/jax_config.h"

#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>

#include "compiler/codegen/compiled_dir.h"
#include "compiler/lower/load_lowered.h"
#include "runtime/cuda/device_envs.h"

namespace kage::jax {
namespace {

std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}

/// Entries are never removed: a compiled XLA program may run as long as the process does.
std::map<std::string, std::shared_ptr<const JaxConfig>, std::less<>>& registry() {
  static std::map<std::string, std::shared_ptr<const JaxConfig>, std::less<>> r;
  return r;
}

/// Fills latent, visual, assets and the hash from a YAML file; the reason when it cannot.
std::string load_yaml(const std::string& path, const std::string& asset_root, JaxConfig* c) {
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  ResolveOptions options;
  if (!asset_root.empty()) options.asset_root = asset_root;
  LoweredFile loaded = load_lowered(path, options, sources, reader, diags);
  if (!loaded.spec) {
    std::ostringstream text;
    print_text(diags, text);
    return text.str() + "kage.jax: no Spec for '" + path + "'";
  }
  if (!loaded.ok()) return "kage.jax: " + path + ": " + loaded.lower_errors;
  AssetPackResult assets = load_asset_pack(loaded.config->assets);
  if (!assets.ok()) return "kage.jax: " + path + ": " + assets.error;
  c->spec_hash = loaded.spec->sha256();
  c->latent = loaded.config->latent;
  c->visual = loaded.config->visual;
  c->assets = std::move(*assets.pack);
  return {};
}

/// Fills latent, visual, assets and the hash from a compile directory; the reason when it cannot.
std::string load_compiled(const std::string& path, JaxConfig* c) {
  std::string problem;
  const std::optional<CompiledDir> dir = open_compiled_dir(path, &problem);
  if (!dir) return "kage.jax: " + problem;
  if (!read_compiled_params(*dir, &c->latent, &c->visual, &problem)) return "kage.jax: " + path + ": " + problem;
  std::optional<AssetPack> assets = read_compiled_assets(*dir, &problem);
  if (!assets) return "kage.jax: " + path + ": " + problem;
  c->spec_hash = dir->spec_sha256();
  c->assets = std::move(*assets);
  c->compiled_dir = true;
  return {};
}

}  // namespace

RegisterResult register_config(const std::string& path, const std::string& asset_root) {
  auto c = std::make_shared<JaxConfig>();
  c->path = path;
  std::error_code ec;
  const std::string problem =
      std::filesystem::is_directory(path, ec) ? load_compiled(path, c.get()) : load_yaml(path, asset_root, c.get());
  if (!problem.empty()) return {nullptr, problem};
  // The view points into the pack's buffers, which stay where they are from here on.
  c->asset_view = c->assets.view();
  c->host = generic_host_kernels(c->latent, c->visual);
  c->segment_count = layout_segment_count(c->latent);
  c->segment_stride = segment_stride_bytes(c->segment_count);
  std::lock_guard<std::mutex> lock(registry_mutex());
  return {registry().emplace(c->spec_hash, c).first->second, {}};
}

std::shared_ptr<const JaxConfig> find_config(std::string_view spec_hash) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  const auto it = registry().find(spec_hash);
  return it == registry().end() ? nullptr : it->second;
}

}  // namespace kage::jax
