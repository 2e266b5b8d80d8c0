// The public API (include/kage/kage.h): a compiled config dir or a YAML file -> a CPU or GPU batch.
// CPU: the generated kernels_host.so (compiled dir) or the generic CpuEnv (YAML). GPU: runtime/cuda.
#include "kage/kage.h"

#include <dlfcn.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "compiler/codegen.h"
#include "compiler/environment.h"
#include "compiler/lower.h"
#include "compiler/resolve.h"
#include "runtime/host/specialized_assets.h"
#include "runtime/host/specialized_batch.h"
#if defined(KAGE_API_HAVE_CUDA)
#include "compiler/build.h"
#include "runtime/cuda/device_batch.h"
#endif

namespace kage {

namespace fs = std::filesystem;

namespace {

bool fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

std::optional<std::string> read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  if (!f) return std::nullopt;
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

const float* info_column(const BatchInfo& info, InfoField field) {
  switch (field) {
    case InfoField::kX: return info.x.data();
    case InfoField::kY: return info.y.data();
    case InfoField::kVx: return info.vx.data();
    case InfoField::kVy: return info.vy.data();
    case InfoField::kPassedDistance: return info.passed_distance.data();
    case InfoField::kProgress: return info.progress.data();
    case InfoField::kEpisodeReturn: return info.episode_return.data();
  }
  return nullptr;
}

/// The CPU backends' copy_obs: their observations are host memory already.
void copy_host_obs(const Env& env, uint8_t* dst) {
  const size_t bytes = static_cast<size_t>(env.num_envs()) * env.height() * env.width() * 3;
  std::memcpy(dst, env.obs(), bytes);
}

/// A lowered config with its Spec hash, from a YAML file or a compiled dir's params.bin.
struct Loaded {
  std::string spec_hash;
  LoweredConfig config;
};

std::optional<Loaded> load_yaml(const std::string& path, const Options& options, std::string* error) {
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  ResolveOptions ro;
  if (!options.asset_root.empty()) ro.asset_root = options.asset_root;
  const auto spec = analyze_file(path, ro, sources, reader, diags);
  if (!spec || diags.has_errors()) {
    std::ostringstream s;
    print_text(diags, s);
    fail(error, s.str() + "kage::open: no Spec for '" + path + "'");
    return std::nullopt;
  }
  LowerResult lowered = lower_spec(*spec);
  if (!lowered.ok()) {
    fail(error, lowered.error_text());
    return std::nullopt;
  }
  return Loaded{spec->sha256(), *lowered.config};
}

/// CPU over the generic path (parameters at run time).
class GenericCpuEnv final : public Env {
 public:
  GenericCpuEnv(std::unique_ptr<Environment> env, std::string hash) : env_(std::move(env)), hash_(std::move(hash)) {}
  bool reset(const uint64_t* seeds, std::string*) override { return env_->env().reset(seeds), true; }
  bool step(const int32_t* actions, std::string*) override { return env_->env().step(actions), true; }
  Backend backend() const override { return Backend::kCpu; }
  int32_t num_envs() const override { return env_->env().size(); }
  int32_t height() const override { return env_->env().height(); }
  int32_t width() const override { return env_->env().width(); }
  const std::string& spec_hash() const override { return hash_; }
  const uint8_t* obs() const override { return env_->env().observations(); }
  const float* reward() const override { return env_->env().info().reward.data(); }
  const uint8_t* terminated() const override { return env_->env().info().terminated.data(); }
  const uint8_t* truncated() const override { return env_->env().info().truncated.data(); }
  const float* info(InfoField f) const override { return info_column(env_->env().info(), f); }
  bool copy_obs(uint8_t* dst, std::string*) const override { return copy_host_obs(*this, dst), true; }

 private:
  std::unique_ptr<Environment> env_;
  std::string hash_;
};

/// CPU over a compiled dir's generated host library.
class GeneratedCpuEnv final : public Env {
 public:
  GeneratedCpuEnv(void* lib, const HostEntryPoints& ep, AssetPack pack, const Options& o, std::string hash)
      : lib_(lib), pack_(std::move(pack)), batch_(ep, pack_.view(), o.num_envs, o.num_threads), hash_(std::move(hash)) {}
  ~GeneratedCpuEnv() override { ::dlclose(lib_); }
  bool reset(const uint64_t* seeds, std::string*) override { return batch_.reset(seeds), true; }
  bool step(const int32_t* actions, std::string*) override { return batch_.step(actions), true; }
  Backend backend() const override { return Backend::kCpu; }
  int32_t num_envs() const override { return batch_.size(); }
  int32_t height() const override { return batch_.visual_params().H; }
  int32_t width() const override { return batch_.visual_params().W; }
  const std::string& spec_hash() const override { return hash_; }
  const uint8_t* obs() const override { return batch_.observations(); }
  const float* reward() const override { return batch_.info().reward.data(); }
  const uint8_t* terminated() const override { return batch_.info().terminated.data(); }
  const uint8_t* truncated() const override { return batch_.info().truncated.data(); }
  const float* info(InfoField f) const override { return info_column(batch_.info(), f); }
  bool copy_obs(uint8_t* dst, std::string*) const override { return copy_host_obs(*this, dst), true; }

 private:
  void* lib_;
  AssetPack pack_;
  SpecializedCpuBatch batch_;
  std::string hash_;
};

std::unique_ptr<Env> open_compiled_cpu(const fs::path& dir, const Json& manifest, const Options& o,
                                       std::string* error) {
  const std::string hash = manifest.value("spec_sha256", "");
  const fs::path so = fs::absolute(dir / "kernels_host.so");
  void* lib = ::dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!lib) return fail(error, "kage::open: cannot load " + so.string() + " (run kagec compile without --no-build)"), nullptr;
  HostEntryPoints ep{};
  ep.abi_version = reinterpret_cast<decltype(ep.abi_version)>(::dlsym(lib, "kage_host_abi_version"));
  ep.spec_hash = reinterpret_cast<decltype(ep.spec_hash)>(::dlsym(lib, "kage_host_spec_hash"));
  ep.params = reinterpret_cast<decltype(ep.params)>(::dlsym(lib, "kage_host_params"));
  ep.reset_env = reinterpret_cast<decltype(ep.reset_env)>(::dlsym(lib, "kage_host_reset_env"));
  ep.step_env = reinterpret_cast<decltype(ep.step_env)>(::dlsym(lib, "kage_host_step_env"));
  std::string problem;
  if (!ep.abi_version || !ep.spec_hash || !ep.params || !ep.reset_env || !ep.step_env)
    problem = "missing kage_host_* entry points";
  else if (ep.abi_version() != kHostAbiVersion)
    problem = "host ABI " + std::to_string(ep.abi_version()) + ", this program speaks " + std::to_string(kHostAbiVersion);
  else if (hash != ep.spec_hash())
    problem = "library built for spec " + std::string(ep.spec_hash()) + ", manifest says " + hash;
  const auto blob = read_file(dir / "assets.bin");
  std::optional<AssetPack> pack = blob ? deserialize_asset_pack(*blob) : std::nullopt;
  if (problem.empty() && !pack) problem = "assets.bin missing or unreadable";
  if (!problem.empty()) {
    ::dlclose(lib);
    return fail(error, "kage::open: " + so.string() + ": " + problem), nullptr;
  }
  return std::make_unique<GeneratedCpuEnv>(lib, ep, std::move(*pack), o, hash);
}

#if defined(KAGE_API_HAVE_CUDA)
/// GPU over runtime/cuda: a fatbin, or NVRTC on the generated source.
class GpuEnv final : public Env {
 public:
  GpuEnv(CudaModule m, DeviceBatch b, AssetPack pack, int32_t H, int32_t W, std::string hash)
      : module_(std::move(m)), pack_(std::move(pack)), batch_(std::move(b)), H_(H), W_(W), hash_(std::move(hash)) {}
  bool reset(const uint64_t* seeds, std::string* e) override { return batch_.reset(seeds, e); }
  bool step(const int32_t* actions, std::string* e) override { return batch_.step(actions, e); }
  Backend backend() const override { return Backend::kGpu; }
  int32_t num_envs() const override { return batch_.size(); }
  int32_t height() const override { return H_; }
  int32_t width() const override { return W_; }
  const std::string& spec_hash() const override { return hash_; }
  const uint8_t* obs() const override { return reinterpret_cast<const uint8_t*>(batch_.obs()); }
  const float* reward() const override { return reinterpret_cast<const float*>(batch_.reward()); }
  const uint8_t* terminated() const override { return reinterpret_cast<const uint8_t*>(batch_.terminated()); }
  const uint8_t* truncated() const override { return reinterpret_cast<const uint8_t*>(batch_.truncated()); }
  const float* info(InfoField) const override { return nullptr; }
  bool copy_obs(uint8_t* dst, std::string* e) const override { return batch_.download_obs(dst, e); }

 private:
  CudaModule module_;
  AssetPack pack_;
  DeviceBatch batch_;
  int32_t H_, W_;
  std::string hash_;
};

std::unique_ptr<Env> open_gpu(const Loaded& l, const std::string& source, const std::string& fatbin, AssetPack pack,
                              const Options& o, std::string* error) {
  if (!cuda_primary_context(error)) return nullptr;
  std::optional<CudaModule> m;
  if (!fatbin.empty() && fs::exists(fatbin)) {
    m = CudaModule::load_file(fatbin, error);
  } else {
    NvrtcOptions no;
    no.include_dir = runtime_include_dir();
    no.generator_version = std::to_string(kCodegenVersion);
    m = CudaModule::compile(source, "kage_" + l.spec_hash.substr(0, 16) + ".cu", no, error);
  }
  if (!m) return nullptr;
  auto b = DeviceBatch::create(*m, l.config.latent, l.config.visual, pack.view(), o.num_envs, error);
  if (!b) return nullptr;
  return std::make_unique<GpuEnv>(std::move(*m), std::move(*b), std::move(pack), l.config.visual.H, l.config.visual.W,
                                  l.spec_hash);
}
#endif

}  // namespace

bool gpu_backend_built() {
#if defined(KAGE_API_HAVE_CUDA)
  return true;
#else
  return false;
#endif
}

std::unique_ptr<Env> open(const std::string& path, const Options& o, std::string* error) {
  if (o.num_envs <= 0 || o.num_threads <= 0) return fail(error, "kage::open: num_envs and num_threads must be positive"), nullptr;
#if !defined(KAGE_API_HAVE_CUDA)
  if (o.backend == Backend::kGpu) return fail(error, "kage::open: GPU backend not built (no CUDA toolkit at build time)"), nullptr;
#endif
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    const fs::path dir(path);
    const auto text = read_file(dir / "manifest.json");
    if (!text) return fail(error, "kage::open: no manifest.json in '" + path + "' (write one with kagec compile)"), nullptr;
    const Json manifest = Json::parse(*text, nullptr, false);
    if (manifest.is_discarded() || manifest.value("kagec_manifest", 0) != 1)
      return fail(error, "kage::open: '" + path + "/manifest.json' is not a kagec manifest"), nullptr;
    if (o.backend == Backend::kCpu) return open_compiled_cpu(dir, manifest, o, error);
#if defined(KAGE_API_HAVE_CUDA)
    const auto params = read_file(dir / "params.bin");
    const auto source = read_file(dir / manifest.value("source", ""));
    const auto blob = read_file(dir / "assets.bin");
    std::optional<AssetPack> pack = blob ? deserialize_asset_pack(*blob) : std::nullopt;
    if (!params || params->size() != sizeof(LatentParams) + sizeof(VisualParams) || !source || !pack)
      return fail(error, "kage::open: '" + path + "' lacks params.bin, its source or assets.bin"), nullptr;
    Loaded l{manifest.value("spec_sha256", ""), {}};
    std::memcpy(&l.config.latent, params->data(), sizeof(LatentParams));
    std::memcpy(&l.config.visual, params->data() + sizeof(LatentParams), sizeof(VisualParams));
    return open_gpu(l, *source, (dir / "kernels.fatbin").string(), std::move(*pack), o, error);
#endif
  }
  std::optional<Loaded> l = load_yaml(path, o, error);
  if (!l) return nullptr;
  if (o.backend == Backend::kCpu) {
    EnvironmentOptions eo;
    eo.num_envs = o.num_envs;
    eo.num_threads = o.num_threads;
    EnvironmentResult r = Environment::from_lowered(l->config, eo);
    if (!r.ok()) return fail(error, "kage::open: " + r.error), nullptr;
    return std::make_unique<GenericCpuEnv>(std::move(r.env), l->spec_hash);
  }
#if defined(KAGE_API_HAVE_CUDA)
  AssetPackResult assets = load_asset_pack(l->config.assets);
  if (!assets.ok()) return fail(error, "kage::open: " + assets.error), nullptr;
  const GeneratedSource g = generate_source({l->spec_hash, l->config.latent, l->config.visual});
  return open_gpu(*l, g.text, "", std::move(*assets.pack), o, error);
#else
  return nullptr;
#endif
}

}  // namespace kage
