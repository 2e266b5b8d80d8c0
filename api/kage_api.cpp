// The public API (include/kage/kage.h): a compiled config dir or a YAML file -> a CPU or GPU batch.
// CPU: HostBatch over the generated kernels_host.so (compiled dir) or the generic path (YAML). GPU:
// DeviceBatch (runtime/cuda).
#include "kage/kage.h"

#include <dlfcn.h>

#include <climits>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <set>

#include "api/environment.h"
#include "compiler/analysis/mixture.h"
#include "compiler/codegen/codegen.h"
#include "compiler/codegen/compiled_dir.h"
#include "compiler/lower/load_lowered.h"
#include "runtime/cpu/host_batch.h"
#include "runtime/io/asset_pack.h"
#if defined(KAGE_API_HAVE_CUDA)
#include "compiler/codegen/nvrtc_options.h"
#include "runtime/cuda/device_batch.h"
#include "runtime/cuda/parallel_compile.h"
#endif

namespace kage {

namespace fs = std::filesystem;

namespace {

bool fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

constexpr InfoFieldDesc kInfoFields[] = {
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) {InfoField::k##Enum, name, DType::dtype, doc},
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
};

template <class T>
const void* column_data(const std::vector<T>& v) {
  return v.data();
}
template <class T>
const void* column_data(T* p) {
  return p;
}

/// Column `field` of an info table (host or device pointers).
template <class Table>
const void* info_column(const Table& t, InfoField field) {
  switch (field) {
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) \
  case InfoField::k##Enum:                                     \
    return column_data(t.member);
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
  }
  return nullptr;
}

/// Host actions as int32, checked to be in 0..7; the reason when they are not, and its kind in `kind`.
std::string host_actions(const Actions& a, int32_t n, std::vector<int32_t>* out, ErrorKind* kind) {
  if (a.dtype != DType::kInt32 && a.dtype != DType::kInt64) {
    *kind = ErrorKind::kOther;
    return "actions must be int32 or int64";
  }
  out->resize(static_cast<size_t>(n));
  for (int32_t i = 0; i < n; ++i) {
    const int64_t at = static_cast<int64_t>(i) * a.stride;
    const int64_t v = a.dtype == DType::kInt64 ? static_cast<const int64_t*>(a.data)[at]
                                               : static_cast<const int32_t*>(a.data)[at];
    if (v < 0 || v > 7) {
      *kind = ErrorKind::kAction;
      return "action " + std::to_string(v) + " for environment " + std::to_string(i) + ": " + action_range_text();
    }
    (*out)[static_cast<size_t>(i)] = static_cast<int32_t>(v);
  }
  return {};
}

/// host_actions for a step: false with the message in `error` and the failure's kind in `kind` (kAction for
/// a value outside 0..7, kOther for a wrong dtype).
bool checked_host_actions(const Actions& a, int32_t n, std::vector<int32_t>* out, ErrorKind* kind, std::string* error) {
  const std::string problem = host_actions(a, n, out, kind);
  return problem.empty() || fail(error, "kage: " + problem);
}

/// A state saved before the first reset would restore as a started batch of all-zero episodes.
constexpr const char* kSaveBeforeReset =
    "kage: save_state before reset: the batch holds no episode until its first reset (or load_state); reset it first";

/// Before its first reset (or load_state) a batch holds no episode: a step, or a reset that leaves some
/// environments out, would run an all-zero state. The reason to refuse, or empty.
std::string unstarted_problem(bool started, bool stepping, const uint8_t* mask, int32_t n) {
  if (started) return {};
  if (stepping) return "kage: step before reset: reset the batch (or load a saved state) first";
  for (int32_t i = 0; mask && i < n; ++i)
    if (!mask[i])
      return "kage: the first reset must reset every environment (environment " + std::to_string(i) +
             " is masked out and has never been reset): reset without a mask first";
  return {};
}

/// A lowered config with its Spec hash, from a YAML file or a compiled dir's params.bin.
struct Loaded {
  std::string spec_hash;
  LoweredConfig config;
};

/// The asset loader's warnings, one a line, after `warnings`.
void add_asset_warnings(const AssetPackResult& assets, const std::string& who, std::string* warnings) {
  for (const std::string& w : assets.warnings) *warnings += who + ": warning: " + w + "\n";
}

/// The lowered config of a YAML file; its warnings (kagec's located text) into `warnings`.
std::optional<Loaded> load_yaml(const std::string& path, const Options& options, std::string* error,
                                std::string* warnings = nullptr) {
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  ResolveOptions ro;
  if (!options.asset_root.empty()) ro.asset_root = options.asset_root;
  LoweredFile loaded = load_lowered(path, ro, sources, reader, diags);
  if (!loaded.spec) {
    fail(error, diagnostics_text(diags) + "kage::open: no Spec for '" + path + "'");
    return std::nullopt;
  }
  if (!loaded.ok()) {
    fail(error, loaded.lower_errors);
    return std::nullopt;
  }
  if (warnings) *warnings = diagnostics_text(diags);
  return Loaded{loaded.spec->sha256(), std::move(*loaded.config)};
}

/// One config of a CPU batch: its kernels (from `lib`, a compiled dir's kernels_host.so, or the generic path
/// when null), its assets and its environment count.
struct HostEnvPart {
  void* lib = nullptr;
  std::unique_ptr<HostKernels> kernels;
  AssetPack pack;
  int32_t num_envs = 0;
};

std::vector<HostEnvPart> one_part(void* lib, std::unique_ptr<HostKernels> kernels, AssetPack pack, int32_t num_envs) {
  std::vector<HostEnvPart> parts;
  parts.push_back(HostEnvPart{lib, std::move(kernels), std::move(pack), num_envs});
  return parts;
}

/// The CPU backend: a HostBatch over generated code (a compiled dir's kernels_host.so) or the generic path,
/// of one config or of a mixture's (one part each).
class HostEnv final : public Env {
 public:
  HostEnv(std::vector<HostEnvPart> parts, int32_t num_threads, std::string hash)
      : parts_(std::move(parts)), batch_(host_parts(parts_), num_threads), hash_(std::move(hash)) {}
  HostEnv(void* lib, std::unique_ptr<HostKernels> kernels, AssetPack pack, const Options& o, std::string hash)
      : HostEnv(one_part(lib, std::move(kernels), std::move(pack), o.num_envs), o.num_threads, std::move(hash)) {}
  ~HostEnv() override {
    for (const HostEnvPart& p : parts_)
      if (p.lib) ::dlclose(p.lib);
  }
  bool reset(const uint64_t* seeds, const uint8_t* mask, std::string* e) override {
    last_error_kind_ = ErrorKind::kUsage;
    const std::string problem = unstarted_problem(started_, false, mask, batch_.size());
    if (!problem.empty()) return fail(e, problem);
    last_error_kind_ = ErrorKind::kNone;
    started_ = true;
    return batch_.reset(seeds, mask), true;
  }
  bool step(const Actions& a, std::string* e) override {
    last_error_kind_ = ErrorKind::kUsage;
    const std::string problem = unstarted_problem(started_, true, nullptr, batch_.size());
    if (!problem.empty()) return fail(e, problem);
    last_error_kind_ = ErrorKind::kOther;
    if (a.memory != Memory::kHost) return fail(e, "kage: device actions given to a CPU environment: pass host memory");
    if (!checked_host_actions(a, batch_.size(), &actions_, &last_error_kind_, e)) return false;
    last_error_kind_ = ErrorKind::kNone;
    return batch_.step(actions_.data()), true;
  }
  Backend backend() const override { return Backend::kCpu; }
  int32_t num_envs() const override { return batch_.size(); }
  int32_t height() const override { return batch_.visual_params().H; }
  int32_t width() const override { return batch_.visual_params().W; }
  const std::string& spec_hash() const override { return hash_; }
  void set_stream(void*) override {}
  void* stream() const override { return nullptr; }
  const uint8_t* obs() const override { return batch_.observations(); }
  const float* reward() const override { return batch_.info().reward.data(); }
  const uint8_t* terminated() const override { return batch_.info().terminated.data(); }
  const uint8_t* truncated() const override { return batch_.info().truncated.data(); }
  const void* info(InfoField f) const override { return info_column(batch_.info(), f); }
  const uint8_t* final_mask() const override { return batch_.final_mask(); }
  const uint8_t* final_obs() const override { return batch_.final_observations(); }
  const void* final_info(InfoField f) const override { return info_column(batch_.final_info(), f); }
  const int32_t* config_index() const override { return batch_.part_index(); }
  bool copy_obs(uint8_t* dst, std::string*) const override {
    std::memcpy(dst, batch_.observations(), batch_.frame_bytes() * static_cast<size_t>(batch_.size()));
    return true;
  }
  bool synchronize(std::string*) override { return true; }
  std::string pending_error() override { return {}; }
  bool save_state(std::vector<uint8_t>* out, std::string* e) const override {
    if (!started_) return fail(e, kSaveBeforeReset);
    return *out = batch_.save_state(hash_), true;
  }
  bool load_state(const uint8_t* data, size_t size, std::string* e) override {
    const std::string problem = batch_.load_state(data, size, hash_);
    if (!problem.empty()) return fail(e, "kage: load_state: " + problem);
    return started_ = true;
  }

 private:
  /// The batch's parts over `parts`' kernels (moved out) and assets (which stay in `parts`).
  static std::vector<HostPart> host_parts(std::vector<HostEnvPart>& parts) {
    std::vector<HostPart> out;
    for (HostEnvPart& p : parts) out.push_back(HostPart{std::move(p.kernels), p.pack.view(), p.num_envs});
    return out;
  }

  bool started_ = false;  // a reset or load_state has run
  std::vector<HostEnvPart> parts_;  // their libraries and assets, which the batch's kernels use
  HostBatch batch_;
  std::string hash_;
  std::vector<int32_t> actions_;
};

std::unique_ptr<Env> open_compiled_cpu(const CompiledDir& c, const Options& o, std::string* error) {
  const std::string hash = c.spec_sha256();
  const fs::path so = fs::absolute(c.path(kHostLibraryFile));
  void* lib = ::dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!lib) return fail(error, "kage::open: cannot load " + so.string() + " (run kagec compile without --no-build)"), nullptr;
  HostEntryPoints ep{};
  ep.abi_version = reinterpret_cast<decltype(ep.abi_version)>(::dlsym(lib, "kage_host_abi_version"));
  ep.spec_hash = reinterpret_cast<decltype(ep.spec_hash)>(::dlsym(lib, "kage_host_spec_hash"));
  ep.params = reinterpret_cast<decltype(ep.params)>(::dlsym(lib, "kage_host_params"));
  ep.reset_env = reinterpret_cast<decltype(ep.reset_env)>(::dlsym(lib, "kage_host_reset_env"));
  ep.step_env = reinterpret_cast<decltype(ep.step_env)>(::dlsym(lib, "kage_host_step_env"));
  ep.render_env = reinterpret_cast<decltype(ep.render_env)>(::dlsym(lib, "kage_host_render_env"));
  std::string problem;
  if (!ep.abi_version)
    problem = "missing kage_host_* entry points";
  else if (ep.abi_version() != kHostAbiVersion)
    problem = "host ABI " + std::to_string(ep.abi_version()) + ", this program speaks " +
              std::to_string(kHostAbiVersion) + ": compile the config again with this kagec";
  else if (!ep.spec_hash || !ep.params || !ep.reset_env || !ep.step_env || !ep.render_env)
    problem = "missing kage_host_* entry points";
  else if (hash != ep.spec_hash())
    problem = "library built for spec " + std::string(ep.spec_hash()) + ", manifest says " + hash;
  std::string unused;
  std::optional<AssetPack> pack = read_compiled_assets(c, &unused);
  if (problem.empty() && !pack) problem = "assets.bin missing or unreadable";
  if (!problem.empty()) {
    ::dlclose(lib);
    return fail(error, "kage::open: " + so.string() + ": " + problem), nullptr;
  }
  return std::make_unique<HostEnv>(lib, generated_host_kernels(ep), std::move(*pack), o, hash);
}

#if defined(KAGE_API_HAVE_CUDA)
/// GPU over runtime/cuda: a fatbin, or NVRTC on the generated source.
class GpuEnv final : public Env {
 public:
  /// `modules` and `packs`: one per part of `b` (a mixture has several), kept as long as the batch runs.
  GpuEnv(CUcontext ctx, std::vector<CudaModule> modules, DeviceBatch b, std::vector<AssetPack> packs, int32_t H,
         int32_t W, std::string hash, CUdeviceptr config_index)
      : ctx_(ctx), modules_(std::move(modules)), packs_(std::move(packs)), batch_(std::move(b)), H_(H), W_(W),
        hash_(std::move(hash)), config_index_(config_index) {}
  // The members free device memory: in this batch's context, whichever thread drops the last reference,
  // once the device has run all queued work (this batch's launches, and a consumer's kernels on its own
  // stream still reading an output it viewed): cuMemFree alone does not promise to wait.
  ~GpuEnv() override {
    if (cuCtxSetCurrent(ctx_) == CUDA_SUCCESS) {
      cuCtxSynchronize();
      cuMemFree(config_index_);
    }
  }
  bool reset(const uint64_t* seeds, const uint8_t* mask, std::string* e) override {
    last_error_kind_ = ErrorKind::kUsage;
    const std::string problem = unstarted_problem(started_, false, mask, batch_.size());
    if (!problem.empty()) return fail(e, problem);
    last_error_kind_ = ErrorKind::kOther;
    return bind(e) && no_pending_error(e) && batch_.reset(seeds, mask, e) && (started_ = true) && succeeded();
  }
  bool step(const Actions& a, std::string* e) override {
    if (!ready_to_step(e)) return false;
    if (a.memory == Memory::kDevice) {
      if (a.dtype != DType::kInt32 && a.dtype != DType::kInt64) return fail(e, "kage: actions must be int32 or int64");
      return batch_.step(DeviceActions{reinterpret_cast<CUdeviceptr>(a.data), a.stride, a.dtype == DType::kInt64}, e) &&
             succeeded();
    }
    if (!checked_host_actions(a, batch_.size(), &actions_, &last_error_kind_, e)) return false;
    return batch_.step(actions_.data(), e) && succeeded();
  }
  Backend backend() const override { return Backend::kGpu; }
  int32_t num_envs() const override { return batch_.size(); }
  int32_t height() const override { return H_; }
  int32_t width() const override { return W_; }
  const std::string& spec_hash() const override { return hash_; }
  void set_stream(void* stream) override { batch_.set_stream(static_cast<CUstream>(stream)); }
  void* stream() const override { return batch_.stream(); }
  const uint8_t* obs() const override { return reinterpret_cast<const uint8_t*>(batch_.obs()); }
  const float* reward() const override { return reinterpret_cast<const float*>(batch_.reward()); }
  const uint8_t* terminated() const override { return reinterpret_cast<const uint8_t*>(batch_.terminated()); }
  const uint8_t* truncated() const override { return reinterpret_cast<const uint8_t*>(batch_.truncated()); }
  const void* info(InfoField f) const override { return info_column(batch_.info(), f); }
  const uint8_t* final_mask() const override { return reinterpret_cast<const uint8_t*>(batch_.final_mask()); }
  const uint8_t* final_obs() const override { return reinterpret_cast<const uint8_t*>(batch_.final_obs()); }
  const void* final_info(InfoField f) const override { return info_column(batch_.final_info(), f); }
  const int32_t* config_index() const override { return reinterpret_cast<const int32_t*>(config_index_); }
  bool copy_obs(uint8_t* dst, std::string* e) const override { return bind(e) && batch_.download_obs(dst, e); }
  bool synchronize(std::string* e) override {
    last_error_kind_ = ErrorKind::kOther;
    return bind(e) && batch_.synchronize(e) && no_pending_error(e) && succeeded();
  }
  std::string pending_error() override {
    const std::optional<ActionError> e = batch_.take_action_error();
    if (!e) return {};
    return "kage: the actions of step " + std::to_string(e->step) + " held " + std::to_string(e->value) +
           " for environment " + std::to_string(e->env) + ": " + action_range_text() +
           "; that step ran with the value masked to its low 3 bits";
  }
  bool save_state(std::vector<uint8_t>* out, std::string* e) const override {
    if (!started_) return fail(e, kSaveBeforeReset);
    return bind(e) && batch_.save_state(hash_, out, e);
  }
  bool load_state(const uint8_t* data, size_t size, std::string* e) override {
    return bind(e) && (batch_.load_state(data, size, hash_, e) || fail(e, "kage: load_state: " + *e)) &&
           (started_ = true);
  }

  /// What a step checks before it launches: started, the context bound, no action error reported.
  bool ready_to_step(std::string* e) {
    last_error_kind_ = ErrorKind::kUsage;
    const std::string problem = unstarted_problem(started_, true, nullptr, batch_.size());
    if (!problem.empty()) return fail(e, problem);
    last_error_kind_ = ErrorKind::kOther;
    return bind(e) && no_pending_error(e);
  }
  /// The device batch, for step_together; stepped() marks a step of it (run there) as the last call's success.
  DeviceBatch& device_batch() { return batch_; }
  CUcontext context() const { return ctx_; }
  void stepped() { succeeded(); }

 private:
  /// Makes the batch's context current: the driver API acts on the calling thread's context, and the
  /// caller may be another thread than the one that opened the batch.
  bool bind(std::string* e) const {
    const CUresult r = cuCtxSetCurrent(ctx_);
    return r == CUDA_SUCCESS || fail(e, cu_error_text(r, "cuCtxSetCurrent"));
  }
  bool no_pending_error(std::string* e) {
    const std::string problem = pending_error();
    if (problem.empty()) return true;
    last_error_kind_ = ErrorKind::kAction;
    return fail(e, problem);
  }
  bool succeeded() {
    last_error_kind_ = ErrorKind::kNone;
    return true;
  }

  bool started_ = false;  // a reset or load_state has run
  CUcontext ctx_;
  std::vector<CudaModule> modules_;  ///< the kernels of each part, unloaded after the batch is freed
  std::vector<AssetPack> packs_;
  DeviceBatch batch_;
  int32_t H_, W_;
  std::string hash_;
  CUdeviceptr config_index_;  ///< [N] int32: each environment's part (zeros for one config)
  std::vector<int32_t> actions_;
};

/// The module of one config: its fatbin when given, else NVRTC on its generated `source` (through the
/// kernel cache). Each call loads a module of its own, with its own __constant__ parameters.
std::optional<CudaModule> gpu_module(const std::string& spec_hash, const std::string& source, const std::string& fatbin,
                                     std::string* error) {
  if (!fatbin.empty()) return CudaModule::load_file(fatbin, error);
  return CudaModule::compile(source, generated_file_name(spec_hash), generated_source_options(), error);
}

/// One config of a GPU batch: its Spec hash and lowered parameters, its generated source (or fatbin path),
/// its assets and its environment count.
struct GpuEnvPart {
  const Loaded* loaded;
  std::string source, fatbin;
  AssetPack pack;
  int32_t num_envs;
};

/// A GpuEnv over one DeviceBatch of `parts` (a mixture when several), under `hash`; config_index() holds
/// each environment's part.
std::unique_ptr<Env> open_gpu_parts(std::vector<GpuEnvPart> parts, const std::string& hash, const Options& o,
                                    std::string* error, ErrorKind* kind) {
  const CUcontext ctx = cuda_primary_context(error);
  if (!ctx) return *kind = ErrorKind::kDevice, nullptr;
  // Every module first: the parts point at them, and a vector that grows moves its elements.
  std::vector<CudaModule> modules;
  for (const GpuEnvPart& p : parts) {
    std::optional<CudaModule> m = gpu_module(p.loaded->spec_hash, p.source, p.fatbin, error);
    if (!m) return nullptr;
    modules.push_back(std::move(*m));
  }
  std::vector<DevicePartSource> sources;
  for (size_t k = 0; k < parts.size(); ++k) {
    const LoweredConfig& c = parts[k].loaded->config;
    sources.push_back(DevicePartSource{&modules[k], c.latent, c.visual, parts[k].pack.view(), parts[k].num_envs,
                                       parts[k].loaded->spec_hash});
  }
  auto b = DeviceBatch::create(sources, error);
  if (!b) return nullptr;
  b->set_stream(static_cast<CUstream>(o.stream));
  CUdeviceptr config_index = 0;  // each environment's part
  CUresult r = cuMemAlloc(&config_index, static_cast<size_t>(b->size()) * sizeof(int32_t));
  for (int32_t k = 0; k < b->part_count() && r == CUDA_SUCCESS; ++k)
    if (b->part_size(k) > 0)
      r = cuMemsetD32(config_index + static_cast<size_t>(b->part_first(k)) * sizeof(int32_t), static_cast<unsigned>(k),
                      static_cast<size_t>(b->part_size(k)));
  if (r != CUDA_SUCCESS) {
    if (config_index) cuMemFree(config_index);
    return fail(error, cu_error_text(r, "config index")), nullptr;
  }
  const VisualParams& vp = parts.front().loaded->config.visual;
  std::vector<AssetPack> packs;
  for (GpuEnvPart& p : parts) packs.push_back(std::move(p.pack));
  return std::make_unique<GpuEnv>(ctx, std::move(modules), std::move(*b), std::move(packs), vp.H, vp.W, hash,
                                  config_index);
}

std::unique_ptr<Env> open_gpu(const Loaded& l, const std::string& source, const std::string& fatbin, AssetPack pack,
                              const Options& o, std::string* error, ErrorKind* kind) {
  std::vector<GpuEnvPart> parts;
  parts.push_back(GpuEnvPart{&l, source, fatbin, std::move(pack), o.num_envs});
  return open_gpu_parts(std::move(parts), l.spec_hash, o, error, kind);
}
#endif

/// Refuses a CPU batch that would need more than half of the machine's memory, before allocating it (as
/// kagec's commands do): it would fail or swap.
bool fits_in_memory(const LatentParams& latent, const VisualParams& visual, const Options& o, std::string* error) {
  LoweredConfig config;
  config.latent = latent;
  config.visual = visual;
  const std::string refusal = memory_refusal(config, o.num_envs, o.num_threads);
  return refusal.empty() || fail(error, "kage::open: " + refusal);
}

/// open() without the final error kind: sets *kind where a failure has a specific one.
std::unique_ptr<Env> open_any(const std::string& path, const Options& o, std::string* error, ErrorKind* kind,
                              std::string* warnings) {
  if (o.num_envs <= 0 || o.num_threads <= 0)
    return *kind = ErrorKind::kUsage, fail(error, "kage::open: num_envs and num_threads must be positive"), nullptr;
#if !defined(KAGE_API_HAVE_CUDA)
  if (o.backend == Backend::kGpu)
    return *kind = ErrorKind::kDevice, fail(error, "kage::open: GPU backend not built (no CUDA toolkit at build time)"), nullptr;
#endif
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    *kind = ErrorKind::kFile;
    std::string problem;
    const std::optional<CompiledDir> c = open_compiled_dir(path, &problem);
    if (!c) return fail(error, "kage::open: " + problem), nullptr;
    if (o.backend == Backend::kCpu) {
      if (!c->has(kHostLibraryFile))
        return fail(error, "kage::open: '" + path + "' has no kernels_host.so (compile without --no-host/--no-build)"),
               nullptr;
      LoweredConfig params;
      if (!read_compiled_params(*c, &params.latent, &params.visual, &problem))
        return fail(error, "kage::open: '" + path + "': " + problem), nullptr;
      if (!fits_in_memory(params.latent, params.visual, o, error)) return *kind = ErrorKind::kUsage, nullptr;
      return open_compiled_cpu(*c, o, error);
    }
    *kind = ErrorKind::kOther;
#if defined(KAGE_API_HAVE_CUDA)
    Loaded l{c->spec_sha256(), {}};
    const bool params = read_compiled_params(*c, &l.config.latent, &l.config.visual, &problem);
    const std::optional<std::string> source = read_compiled_source(*c, &problem);
    std::optional<AssetPack> pack = read_compiled_assets(*c, &problem);
    if (!params || !source || !pack)
      return fail(error, "kage::open: '" + path + "' lacks params.bin, its source or assets.bin"), nullptr;
    const std::string fatbin = c->has(kFatbinFile) ? c->path(kFatbinFile).string() : std::string();
    return open_gpu(l, *source, fatbin, std::move(*pack), o, error, kind);
#endif
  }
  std::optional<Loaded> l = load_yaml(path, o, error, warnings);
  if (!l) return *kind = ErrorKind::kConfig, nullptr;
  if (o.backend == Backend::kCpu && !fits_in_memory(l->config.latent, l->config.visual, o, error))
    return *kind = ErrorKind::kUsage, nullptr;
  AssetPackResult assets = load_asset_pack(l->config.assets);
  if (!assets.ok()) return fail(error, "kage::open: " + assets.error), nullptr;
  add_asset_warnings(assets, "kage::open", warnings);
  if (o.backend == Backend::kCpu)
    return std::make_unique<HostEnv>(nullptr, generic_host_kernels(l->config.latent, l->config.visual),
                                     std::move(*assets.pack), o, l->spec_hash);
#if defined(KAGE_API_HAVE_CUDA)
  const GeneratedSource g = generate_source({l->spec_hash, l->config.latent, l->config.visual});
  return open_gpu(*l, g.text, "", std::move(*assets.pack), o, error, kind);
#else
  return nullptr;
#endif
}

/// open_mixture() without the final error kind (see open_any).
std::unique_ptr<Env> open_mixture_any(const std::vector<MixturePart>& parts, const Options& o, std::string* error,
                                      ErrorKind* kind, std::string* warnings) {
  *kind = ErrorKind::kUsage;
  int64_t total = 0;
  for (const MixturePart& p : parts) {
    if (p.num_envs < 0) return fail(error, "kage::open_mixture: a part with " + std::to_string(p.num_envs) +
                                               " environments"), nullptr;
    total += p.num_envs;
  }
  if (parts.empty() || total <= 0 || total > INT32_MAX || o.num_threads <= 0)
    return fail(error, "kage::open_mixture: give one or more parts with 1 to 2^31 - 1 environments in all, and a "
                       "positive thread count"), nullptr;
  std::error_code ec;
  for (const MixturePart& p : parts)
    if (fs::is_directory(p.path, ec))
      return fail(error, "kage::open_mixture: '" + p.path + "' is a kagec compile directory: a mixture is certified "
                         "from its configs' YAML, so give the YAML configs it was compiled from"), nullptr;
  // kagec's certificate first: nothing is lowered, loaded or allocated for configs that do not certify.
  *kind = ErrorKind::kConfig;
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  ResolveOptions ro;
  if (!o.asset_root.empty()) ro.asset_root = o.asset_root;
  std::vector<std::string> paths;
  for (const MixturePart& p : parts) paths.push_back(p.path);
  const std::optional<std::vector<Spec>> specs = analyze_mixture(paths, ro, sources, reader, diags);
  if (!specs)
    return fail(error, diagnostics_text(diags) + "kage::open_mixture: not a mixture of these configs"), nullptr;
  *warnings = diagnostics_text(diags);
#if !defined(KAGE_API_HAVE_CUDA)
  if (o.backend == Backend::kGpu)
    return *kind = ErrorKind::kDevice,
           fail(error, "kage::open_mixture: GPU backend not built (no CUDA toolkit at build time)"), nullptr;
#endif
  std::vector<LoweredConfig> lowered;
  std::vector<std::pair<std::string, int32_t>> identity;
  for (size_t k = 0; k < parts.size(); ++k) {
    LowerResult l = lower_spec((*specs)[k]);
    if (!l.ok()) return fail(error, l.error_text()), nullptr;
    lowered.push_back(std::move(*l.config));
    identity.emplace_back((*specs)[k].sha256(), parts[k].num_envs);
  }
  *kind = ErrorKind::kUsage;
  Options whole = o;  // the environments take the same memory in every part but the scratch
  whole.num_envs = static_cast<int32_t>(total);
  for (const LoweredConfig& c : lowered)
    if (o.backend == Backend::kCpu && !fits_in_memory(c.latent, c.visual, whole, error)) return nullptr;
  *kind = ErrorKind::kOther;
  std::vector<AssetPack> packs;
  for (const LoweredConfig& c : lowered) {
    AssetPackResult assets = load_asset_pack(c.assets);
    if (!assets.ok()) return fail(error, "kage::open_mixture: " + assets.error), nullptr;
    add_asset_warnings(assets, "kage::open_mixture", warnings);
    packs.push_back(std::move(*assets.pack));
  }
#if defined(KAGE_API_HAVE_CUDA)
  if (o.backend == Backend::kGpu) {
    // One module per part (each config's generated source through NVRTC and the kernel cache), one batch.
    std::vector<Loaded> loaded;
    for (size_t k = 0; k < parts.size(); ++k) loaded.push_back(Loaded{(*specs)[k].sha256(), std::move(lowered[k])});
    std::vector<GpuEnvPart> gpu;
    for (size_t k = 0; k < parts.size(); ++k) {
      const GeneratedSource g = generate_source({loaded[k].spec_hash, loaded[k].config.latent, loaded[k].config.visual});
      gpu.push_back(GpuEnvPart{&loaded[k], g.text, "", std::move(packs[k]), parts[k].num_envs});
    }
    std::unique_ptr<Env> env = open_gpu_parts(std::move(gpu), mixture_sha256(identity), o, error, kind);
    if (!env && error) *error = "kage::open_mixture: " + *error;
    return env;
  }
#endif
  std::vector<HostEnvPart> host;
  for (size_t k = 0; k < parts.size(); ++k)
    host.push_back(HostEnvPart{nullptr, generic_host_kernels(lowered[k].latent, lowered[k].visual), std::move(packs[k]),
                               parts[k].num_envs});
  std::vector<const HostKernels*> kernels;
  for (const HostEnvPart& h : host) kernels.push_back(h.kernels.get());
  const std::string problem = HostBatch::parts_problem(kernels);
  if (!problem.empty()) return fail(error, "kage::open_mixture: internal: a certified mixture whose " + problem), nullptr;
  return std::make_unique<HostEnv>(std::move(host), o.num_threads, mixture_sha256(identity));
}

}  // namespace

std::unique_ptr<Env> open_mixture(const std::vector<MixturePart>& parts, const Options& o, std::string* error,
                                  ErrorKind* kind_out, std::string* warnings_out) {
  ErrorKind ignored = ErrorKind::kOther;
  ErrorKind* kind = kind_out ? kind_out : &ignored;
  std::string warnings;
  std::unique_ptr<Env> env = open_mixture_any(parts, o, error, kind, &warnings);
  if (warnings_out) *warnings_out = env ? warnings : std::string();
  if (env) *kind = ErrorKind::kNone;
  return env;
}

const char* action_range_text() { return "an action is an integer in 0..7 (bit 0 left, bit 1 right, bit 2 jump)"; }

std::string host_actions_problem(const Actions& a, int32_t num_envs) {
  std::vector<int32_t> checked;
  ErrorKind kind = ErrorKind::kNone;
  return host_actions(a, num_envs, &checked, &kind);
}

const InfoFieldDesc* info_fields(int32_t* count) {
  *count = static_cast<int32_t>(std::size(kInfoFields));
  return kInfoFields;
}

std::optional<KernelsCompiled> compile_kernels(const std::vector<std::string>& paths, const Options& o,
                                               std::string* error, ErrorKind* kind_out) {
  ErrorKind ignored = ErrorKind::kOther;
  ErrorKind* kind = kind_out ? kind_out : &ignored;
#if !defined(KAGE_API_HAVE_CUDA)
  for (const std::string& path : paths)  // a config's errors first, as with the GPU backend
    if (!load_yaml(path, o, error)) return *kind = ErrorKind::kConfig, std::nullopt;
  if (paths.empty()) return *kind = ErrorKind::kNone, KernelsCompiled{};
  *kind = ErrorKind::kDevice;
  fail(error, "kage::compile_kernels: GPU backend not built (no CUDA toolkit at build time)");
  return std::nullopt;
#else
  std::vector<KernelJob> jobs;
  std::vector<std::string> job_paths;
  std::set<std::string> seen;  // Spec hashes: a config named twice, or by two paths, compiles once
  for (const std::string& path : paths) {
    std::optional<Loaded> l = load_yaml(path, o, error);
    if (!l) return *kind = ErrorKind::kConfig, std::nullopt;
    if (!seen.insert(l->spec_hash).second) continue;
    GeneratedSource generated = generate_source({l->spec_hash, l->config.latent, l->config.visual});
    KernelJob job;
    job.source = std::move(generated.text);
    job.name = std::move(generated.file_name);
    jobs.push_back(std::move(job));
    job_paths.push_back(path);
  }
  if (jobs.empty()) return *kind = ErrorKind::kNone, KernelsCompiled{};
  const std::optional<std::string> arch = device_arch(error);
  if (!arch) return *kind = ErrorKind::kDevice, std::nullopt;
  compile_jobs(jobs, generated_source_options(), *arch, compile_threads(jobs.size()));
  KernelsCompiled done;
  for (size_t i = 0; i < jobs.size(); ++i) {
    if (!jobs[i].cubin) {
      *kind = ErrorKind::kOther;
      fail(error, "kage::compile_kernels: '" + job_paths[i] + "': " + jobs[i].error);
      return std::nullopt;
    }
    ++(jobs[i].cached ? done.cached : done.compiled);
  }
  *kind = ErrorKind::kNone;
  return done;
#endif
}

bool step_together(const std::vector<Env*>& envs, const Actions& actions, int64_t row_stride, std::string* error,
                   int64_t* failed) {
  int64_t ignored = -1;
  int64_t& at = failed ? *failed : ignored;
  at = -1;
  if (envs.empty()) return fail(error, "kage::step_together: no batches");
  if (actions.memory != Memory::kDevice) return fail(error, "kage::step_together: actions must be in device memory");
  if (actions.dtype != DType::kInt32 && actions.dtype != DType::kInt64)
    return fail(error, "kage: actions must be int32 or int64");
#if defined(KAGE_API_HAVE_CUDA)
  std::vector<GpuEnv*> gpu;
  for (size_t i = 0; i < envs.size(); ++i) {
    auto* g = dynamic_cast<GpuEnv*>(envs[i]);
    if (!g) return at = static_cast<int64_t>(i), fail(error, "kage::step_together: the batch runs on the CPU");
    if (!gpu.empty() && g->context() != gpu.front()->context())
      return at = static_cast<int64_t>(i), fail(error, "kage::step_together: the batch is on another GPU context");
    gpu.push_back(g);
  }
  std::vector<DeviceBatch*> batches;
  for (size_t i = 0; i < gpu.size(); ++i) {
    if (!gpu[i]->ready_to_step(error)) return at = static_cast<int64_t>(i), false;
    batches.push_back(&gpu[i]->device_batch());
  }
  const ActionRows rows{actions.data, row_stride, actions.stride, actions.dtype == DType::kInt64 ? 1 : 0};
  if (!DeviceBatch::step_together(batches, rows, error)) return false;
  for (GpuEnv* g : gpu) g->stepped();
  return true;
#else
  (void)row_stride;
  return at = 0, fail(error, "kage::step_together: the batch runs on the CPU");
#endif
}

bool gpu_backend_built() {
#if defined(KAGE_API_HAVE_CUDA)
  return true;
#else
  return false;
#endif
}

std::unique_ptr<Env> open(const std::string& path, const Options& o, std::string* error, ErrorKind* kind_out,
                          std::string* warnings_out) {
  ErrorKind ignored = ErrorKind::kOther;
  ErrorKind* kind = kind_out ? kind_out : &ignored;
  *kind = ErrorKind::kOther;
  std::string warnings;
  std::unique_ptr<Env> env = open_any(path, o, error, kind, &warnings);
  if (warnings_out) *warnings_out = env ? warnings : std::string();
  if (env) *kind = ErrorKind::kNone;
  return env;
}

}  // namespace kage
