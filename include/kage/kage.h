// kage: the public C++ API. Open a config (a YAML file, or a directory written by `kagec compile`),
// pick a backend, then reset(seeds) / step(actions) a batch of environments.
//
//   kage::Options o;
//   o.num_envs = 64;
//   std::string err;
//   auto env = kage::open("configs/throughput/simplest.yaml", o, &err);   // or "out/simplest" (compiled)
//   if (!env) { std::cerr << err; return 1; }
//   env->reset(seeds);                  // seeds: num_envs uint64
//   env->step(actions);                 // actions: num_envs int32 (bit 0 left, bit 1 right, bit 2 jump)
//   const uint8_t* obs = env->obs();    // [num_envs][H][W][3]; device memory on the GPU backend
//
// Same-step autoreset (as the original's AutoResetWrapper and Gymnasium 1.x "same-step" mode): a step
// that ends an episode returns that step's reward and flags, the next episode's first observation and
// info, and the finished episode's last observation and info in final_obs() / final_info(), flagged in
// final_mask().
//
// GPU ordering: every launch and copy of a batch goes to one CUDA stream (Options::stream, or
// set_stream), in call order, and no call waits for the device except save_state, load_state, copy_obs
// and synchronize. A consumer that reads the outputs on that stream, or produces device actions on it,
// needs no synchronisation; one on another stream orders itself with an event. Outputs are valid until
// the next reset, step or load_state of the batch has run on its stream.
//
// No exception crosses this API: failures return null / false with a message in `error`.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace kage {

enum class Backend {
  kCpu,  ///< host memory; a compiled dir runs its generated kernels_host.so, a YAML the generic path
  kGpu,  ///< device memory; a compiled dir loads kernels.fatbin (else NVRTC), a YAML is compiled by NVRTC
};

/// Where an array lives.
enum class Memory { kHost, kDevice };

/// Element types of the arrays of this API.
enum class DType { kUInt8, kInt32, kInt64, kFloat32, kBool };  ///< kBool: one byte, 0 or 1

struct Options {
  Backend backend = Backend::kCpu;
  int32_t num_envs = 1;
  int32_t num_threads = 1;  ///< CPU worker threads; results do not depend on it
  /// YAML only: resolve asset paths against this directory (empty: the file that names them).
  std::string asset_root;
  /// GPU: the CUstream of every launch and copy (null: the legacy default stream).
  void* stream = nullptr;
};

/// The per-environment info fields (spec 5.8, plus the episode length): runtime/info_fields.def.
enum class InfoField {
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) k##Enum,
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
};

/// An info field's original name (`x`, `passed_distance`, `return`, ...), element type and meaning.
struct InfoFieldDesc {
  InfoField field;
  const char* name;
  DType dtype;
  const char* doc;
};

/// Every info field, in runtime/info_fields.def order; `count` receives their number.
const InfoFieldDesc* info_fields(int32_t* count);

/// The text in every error about an action outside 0..7 (from step, reset, synchronize or
/// pending_error), by which a caller can tell that error from the others.
const char* action_range_text();

/// Actions for step(): num_envs() integers, element env * stride of `data`. Values outside 0..7 are an
/// error: host arrays are checked before the step; device arrays are checked by the step kernel and
/// reported by a later call (pending_error), since checking at once would wait for the device.
struct Actions {
  const void* data = nullptr;
  Memory memory = Memory::kHost;
  DType dtype = DType::kInt32;  ///< kInt32 or kInt64
  int64_t stride = 1;           ///< in elements
};

/// Why host actions `a` cannot step a batch of `num_envs` environments, as step() would refuse them ("action 8 for
/// environment 3: " and action_range_text(), or a dtype other than int32 and int64), or empty: for a caller that
/// checks several batches' actions before stepping any.
std::string host_actions_problem(const Actions& a, int32_t num_envs);

/// What a failure was about: open() reports it through `kind`, an Env's calls through last_error_kind().
enum class ErrorKind {
  kNone,
  kConfig,  ///< the config has errors: the message holds the located diagnostics (file:line:col)
  kFile,    ///< a compiled directory is missing a file or is not one
  kDevice,  ///< no usable GPU (no driver, no device, or a build without the GPU backend)
  kUsage,   ///< an option is out of range
  kAction,  ///< an action outside 0..7 (action_range_text())
  kOther,
};

/// A batch of environments of one configuration.
class Env {
 public:
  virtual ~Env() = default;

  /// Starts episode 0 of every environment. `seeds`: num_envs() host values.
  [[nodiscard]] bool reset(const uint64_t* seeds, std::string* error = nullptr) {
    return reset(seeds, nullptr, error);
  }
  /// Starts episode 0, with seeds[env], of the environments with mask[env] != 0 (all of them when `mask`
  /// is null); the others keep their state and outputs. `seeds` and `mask`: num_envs() host values.
  /// No environment is final afterwards.
  [[nodiscard]] virtual bool reset(const uint64_t* seeds, const uint8_t* mask, std::string* error) = 0;
  /// One step with same-step autoreset. `actions`: num_envs() int32 host values.
  [[nodiscard]] bool step(const int32_t* actions, std::string* error = nullptr) {
    return step(Actions{actions, Memory::kHost, DType::kInt32, 1}, error);
  }
  /// One step with same-step autoreset; device actions are read in place on the GPU backend.
  [[nodiscard]] virtual bool step(const Actions& actions, std::string* error) = 0;

  virtual Backend backend() const = 0;
  virtual int32_t num_envs() const = 0;
  virtual int32_t height() const = 0;
  virtual int32_t width() const = 0;
  /// SHA-256 of the configuration's canonical Spec.
  virtual const std::string& spec_hash() const = 0;
  /// GPU: the CUstream of later launches and copies (null: the legacy default stream). CPU: ignored.
  virtual void set_stream(void* stream) = 0;
  virtual void* stream() const = 0;

  /// Outputs of the last reset or step: host pointers on the CPU backend, device pointers (CUdeviceptr
  /// values) on the GPU backend. Valid until the next call.
  virtual const uint8_t* obs() const = 0;         ///< [N][H][W][3] uint8, row-major
  virtual const float* reward() const = 0;        ///< [N]
  virtual const uint8_t* terminated() const = 0;  ///< [N] 0/1 (DType::kBool)
  virtual const uint8_t* truncated() const = 0;   ///< [N] 0/1 (DType::kBool)
  /// [N] values of one info field (element type from info_fields()), of the state after the call: for
  /// an environment that was reset by the step, the new episode's.
  virtual const void* info(InfoField field) const = 0;
  /// [N] 0/1: the last step ended the environment's episode (and reset it). All 0 after reset().
  virtual const uint8_t* final_mask() const = 0;
  /// [N][H][W][3]: where final_mask is 1, the finished episode's last observation; other rows are stale.
  virtual const uint8_t* final_obs() const = 0;
  /// [N] values of one info field of the finished episode's last step, where final_mask is 1.
  virtual const void* final_info(InfoField field) const = 0;
  /// [N] int32, the same for the life of the batch: the index of the config each environment runs (0 for
  /// every environment of a batch of one config). Python's info["config"].
  virtual const int32_t* config_index() const = 0;

  /// Copies the observations of the last reset or step (num_envs() * height() * width() * 3 bytes)
  /// into host memory `dst`, on either backend.
  [[nodiscard]] virtual bool copy_obs(uint8_t* dst, std::string* error = nullptr) const = 0;
  /// Waits until the batch's queued work has finished (GPU), and reports an out-of-range device action
  /// of an earlier step as an error.
  [[nodiscard]] virtual bool synchronize(std::string* error = nullptr) = 0;
  /// An out-of-range device action reported by a step that has finished since the last report (empty
  /// if none); does not wait.
  virtual std::string pending_error() = 0;
  /// What the last failed reset, step or synchronize was about (kAction for an action outside 0..7, else
  /// kOther); kNone after a call that succeeded.
  ErrorKind last_error_kind() const { return last_error_kind_; }

  /// The whole batch's state and last outputs (about 1.4 KB per environment, not the observations),
  /// readable by load_state on either backend. Waits for queued work. Refused before the first reset (or
  /// load_state): the batch holds no episode yet.
  [[nodiscard]] virtual bool save_state(std::vector<uint8_t>* out, std::string* error = nullptr) const = 0;
  /// Restores a state saved from the same configuration and environment count, then renders its
  /// observations: the batch continues exactly as the one that was saved.
  [[nodiscard]] virtual bool load_state(const uint8_t* data, size_t size, std::string* error = nullptr) = 0;

 protected:
  ErrorKind last_error_kind_ = ErrorKind::kNone;
};


/// Opens `path`: a directory with manifest.json (from `kagec compile`) or a YAML config. Null on error,
/// with the message in `error` and its kind in `kind` (if given). `warnings` (if given) receives, on success,
/// the YAML config's warnings located as `kagec lint` prints them (an inert setting, a reproduced quirk, ...)
/// and the asset loader's, one per line; empty when there are none (a compiled directory was linted by
/// `kagec compile`).
std::unique_ptr<Env> open(const std::string& path, const Options& options, std::string* error,
                          ErrorKind* kind = nullptr, std::string* warnings = nullptr);

/// One config of a mixture (open_mixture) and how many environments run it.
struct MixturePart {
  std::string path;      ///< a YAML config
  int32_t num_envs = 0;  ///< >= 0
};

/// Opens one batch whose environments run several configs: part k's num_envs environments, numbered after
/// the earlier parts' (config_index() gives each environment's part). The configs must differ only on visual
/// axes: one hidden game (every latent key equal) and one observation shape, which kagec certifies first (its
/// located diagnostics, kind kConfig, before anything is loaded). Each part runs its own kernels and writes its
/// rows of the one set of outputs, so environment i equals environment i of its config run alone with the same
/// seed and actions. options.num_envs is ignored (the batch has the parts' sum). Either backend: on the GPU one
/// device batch whose parts each run their config's own module (config_index() is then a device array), on the
/// stream options.stream. The spec hash is a mixture's (the configs' Spec hashes and counts: kagec diff
/// --mixture). `warnings`: every config's, as open's.
std::unique_ptr<Env> open_mixture(const std::vector<MixturePart>& parts, const Options& options, std::string* error,
                                  ErrorKind* kind = nullptr, std::string* warnings = nullptr);

/// Steps envs[i] by row i of the device array `actions` (element i * row_stride + env * actions.stride), as
/// envs[i]->step(row i) would, byte for byte, with one step launch and one render launch per config over every
/// batch that runs it (a pack's runs of one config, a mixture's parts across runs) instead of a launch pair per
/// batch and mixture part: for a learner that steps many small batches every step. GPU batches of one context,
/// each started; ordered on envs[0]'s stream after the work queued so far on the others' streams, which are
/// ordered after the step. A refusal steps nothing and puts the index of the batch it is about in `failed` (-1:
/// none): a batch on the CPU or not started, or an out-of-range action an earlier step of it reported (that
/// batch's last_error_kind() is then kAction).
[[nodiscard]] bool step_together(const std::vector<Env*>& envs, const Actions& actions, int64_t row_stride,
                                 std::string* error, int64_t* failed = nullptr);

/// What compile_kernels did: how many configs' kernels NVRTC compiled, and how many the kernel cache held.
struct KernelsCompiled {
  int32_t compiled = 0;
  int32_t cached = 0;
};

/// Compiles the GPU kernels of the YAML configs `paths` for device 0 into the kernel cache ($KAGE_CACHE_DIR,
/// else ~/.cache/kagec), several configs at once (one per core, up to 16), so that opening their batches
/// afterwards (open, open_mixture with the GPU backend) takes their kernels from the cache instead of
/// compiling one config after another. A config given twice is compiled once. options.asset_root resolves the
/// configs as open would; the other options are ignored. Every config is loaded before anything compiles: a
/// config with errors fails with its located diagnostics and path (kind kConfig), then a missing GPU (kDevice);
/// no configs need no GPU.
std::optional<KernelsCompiled> compile_kernels(const std::vector<std::string>& paths, const Options& options,
                                               std::string* error, ErrorKind* kind = nullptr);

/// Whether this build can run the GPU backend (the CUDA runtime pieces were compiled in).
bool gpu_backend_built();

}  // namespace kage
