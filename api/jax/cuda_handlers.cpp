// kage.jax's CUDA handlers: the config's specialised kernels (kage_reset, kage_step and kage_render of
// runtime/cuda/kernels.cuh) launched on the stream XLA passes in, on the buffers XLA owns: the state is
// updated in place (the step's aliased buffers, copied over first where XLA gave a pair two), outputs are
// written where XLA put them, and nothing is allocated or waited for. The module and the assets are loaded
// once per process and config, at the instantiate stage.
//
// Device 0 only: the runtime's module loader binds to device 0's primary context (the one XLA uses too).
// A process per GPU (CUDA_VISIBLE_DEVICES) runs on any GPU.
#include <cuda.h>

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "api/jax/ffi_buffers.h"
#include "api/jax/ffi_handlers.h"
#include "compiler/codegen/codegen.h"
#include "compiler/codegen/compiled_dir.h"
#include "compiler/codegen/nvrtc_options.h"
#include "runtime/cuda/device_batch.h"
#include "runtime/cuda/device_envs.h"
#include "runtime/cuda/module_loader.h"
#include "runtime/cuda/render_plan.h"

namespace kage::jax {
namespace ffi = xla::ffi;
namespace {


/// A config's kernels and assets on device 0. Kept for the life of the process: a compiled XLA program may
/// run until it ends.
struct DeviceProgram {
  CUcontext context = nullptr;
  std::optional<CudaModule> module;
  DeviceAssets assets;
  CUfunction reset = nullptr, step = nullptr, render = nullptr;
  int32_t visual_extent = 0;
  int32_t render_threads = 0;
  int32_t render_smem = 0;
  int32_t multiprocessors = 0;
};

/// The module of `c`: a compile directory's fatbin (else its source through NVRTC), or the source
/// generated for a YAML config through NVRTC (cached on disk by the runtime's loader).
std::optional<CudaModule> load_module(const JaxConfig& c, std::string* error) {
  std::string source;
  if (c.compiled_dir) {
    const std::optional<CompiledDir> dir = open_compiled_dir(c.path, error);
    if (!dir) return std::nullopt;
    if (dir->has(kFatbinFile)) return CudaModule::load_file(dir->path(kFatbinFile).string(), error);
    std::optional<std::string> text = read_compiled_source(*dir, error);
    if (!text) return std::nullopt;
    source = std::move(*text);
  } else {
    source = generate_source({c.spec_hash, c.latent, c.visual}).text;
  }
  return CudaModule::compile(source, generated_file_name(c.spec_hash), generated_source_options(), error);
}

std::unique_ptr<DeviceProgram> load_program(const JaxConfig& c, std::string* error) {
  if (!render_supported(c.visual)) {
    *error = "frame size " + std::to_string(c.visual.H) + "x" + std::to_string(c.visual.W) + " not supported on the GPU";
    return nullptr;
  }
  auto p = std::make_unique<DeviceProgram>();
  p->context = cuda_primary_context(error);
  if (!p->context) return nullptr;
  p->module = load_module(c, error);
  if (!p->module) return nullptr;
  for (auto [fn, name] : {std::pair{&p->reset, "kage_reset"}, std::pair{&p->step, "kage_step"},
                          std::pair{&p->render, "kage_render"}})
    if (!(*fn = p->module->function(name, error))) return nullptr;
  if (!upload_dynamic_params(*p->module, c.latent, c.visual, error)) return nullptr;
  std::optional<DeviceAssets> assets = upload_assets(c.asset_view, error);
  if (!assets) return nullptr;
  p->assets = *assets;
  p->visual_extent = visual_state_extent(c.visual, c.asset_view);
  p->render_threads = render_threads(c.visual);
  p->render_smem = render_dynamic_smem_bytes(c.visual);
  CUdevice dev;
  if (!cu_check(cuCtxGetDevice(&dev), "cuCtxGetDevice", error) ||
      !cu_check(cuDeviceGetAttribute(&p->multiprocessors, CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT, dev),
             "cuDeviceGetAttribute(multiprocessors)", error) ||
      !cu_check(cuFuncSetAttribute(p->render, CU_FUNC_ATTRIBUTE_MAX_DYNAMIC_SHARED_SIZE_BYTES, p->render_smem),
             "cuFuncSetAttribute(dynamic shared memory)", error))
    return nullptr;
  return p;
}

/// The program of `c`, loaded on first use; null with the reason in `error`.
const DeviceProgram* program_for(const JaxConfig& c, std::string* error) {
  static std::mutex mutex;
  static std::map<std::string, std::unique_ptr<DeviceProgram>> programs;
  std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<DeviceProgram>& p = programs[c.spec_hash];
  if (!p) p = load_program(c, error);
  return p.get();
}

/// What an instantiated call keeps: its config and that config's program.
struct CudaInstance {
  static ffi::TypeId id;
  std::shared_ptr<const JaxConfig> config;
  const DeviceProgram* program = nullptr;
};
ffi::TypeId CudaInstance::id = {};

ffi::ErrorOr<std::unique_ptr<CudaInstance>> instantiate(std::string_view spec_hash) {
  auto instance = std::make_unique<CudaInstance>();
  instance->config = find_config(spec_hash);
  if (!instance->config)
    return ffi::Unexpected(handler_error("instantiate",
                                         "no config with spec hash " + std::string(spec_hash) +
                                             " in this process: make it with kage.jax.make_env first"));
  std::string error;
  instance->program = program_for(*instance->config, &error);
  if (!instance->program) return ffi::Unexpected(handler_error("instantiate", error));
  return instance;
}

/// The kernels' view of the call's buffers.
DeviceEnvs device_envs(const JaxConfig& c, const DeviceProgram& p, const EnvBuffers& b) {
  DeviceEnvs e{};
  e.num_envs = static_cast<int32_t>(b.n);
  e.segment_stride = c.segment_stride;
  e.visual_extent = p.visual_extent;
  e.seeds = b.seeds;
  e.latent = b.latent;
  e.segments = b.segments;
  e.visual = b.visual;
  // No error report: the Python side records out-of-range actions in the state; the kernel masks them.
  e.actions = ActionSource{b.actions, 1, 0, nullptr, nullptr};
  e.obs = b.obs;
  e.reward = b.reward;
  e.terminated = b.terminated;
  e.truncated = b.truncated;
  e.info = b.info;
  e.final_mask = b.final_mask;
  e.final_latent = b.final_latent;
  e.final_segments = b.final_segments;
  e.final_visual = b.final_visual;
  e.final_obs = b.final_obs;
  e.final_info = b.final_info;
  e.assets = p.assets.view;
  return e;
}

/// `per_env` (kage_reset or kage_step, one environment per thread), then kage_render, on `stream`.
ffi::Error launch(const char* call, const JaxConfig& c, const DeviceProgram& p, CUfunction per_env, DeviceEnvs e,
                  CUstream stream) {
  std::string error;
  void* args[] = {&e};
  const GroupRow* no_rows = nullptr;  // kage_render of this call's own view
  void* render_args[] = {&no_rows, &e};
  const unsigned grid = static_cast<unsigned>((e.num_envs + kPerEnvThreads - 1) / kPerEnvThreads);
  const int32_t frames = frames_per_block(c.visual, e.num_envs, p.multiprocessors);
  const unsigned render_grid = static_cast<unsigned>((e.num_envs + frames - 1) / frames);
  // The driver acts on the calling thread's context: device 0's primary context, which XLA's is.
  if (cu_check(cuCtxSetCurrent(p.context), "cuCtxSetCurrent", &error) &&
      cu_check(cuLaunchKernel(per_env, grid, 1, 1, kPerEnvThreads, 1, 1, 0, stream, args, nullptr), "cuLaunchKernel",
            &error) &&
      cu_check(cuLaunchKernel(p.render, render_grid, 1, 1, static_cast<unsigned>(p.render_threads), 1, 1,
                           static_cast<unsigned>(p.render_smem), stream, render_args, nullptr),
            "cuLaunchKernel(kage_render)", &error))
    return ffi::Error::Success();
  return handler_error(call, error);
}

/// The call's device, or an error for any but device 0.
ffi::Error on_device_zero(const char* call, int32_t ordinal) {
  if (ordinal == 0) return ffi::Error::Success();
  return handler_error(call, "runs on CUDA device 0 only (this call is on device " + std::to_string(ordinal) +
                                 "); run one process per GPU with CUDA_VISIBLE_DEVICES");
}

ffi::Error reset(CUstream stream, int32_t ordinal, CudaInstance* instance, std::string_view, ffi::RemainingArgs args,
                 ffi::RemainingRets rets) {
  if (ffi::Error e = on_device_zero("kage_reset", ordinal); e.failure()) return e;
  const JaxConfig& c = *instance->config;
  const ffi::ErrorOr<EnvBuffers> got = reset_buffers(c, args, rets);
  if (!got.has_value()) return got.error();
  const EnvBuffers& b = *got;
  if (b.n > INT32_MAX) return handler_error("kage_reset", "more than 2^31 - 1 environments");
  const DeviceProgram& p = *instance->program;
  std::string error;
  // Fresh buffers: zero the state first, so that padding and unused entity slots are defined bytes.
  const auto zero = [&](void* at, size_t bytes) {
    return cu_check(cuMemsetD8Async(reinterpret_cast<CUdeviceptr>(at), 0, bytes, stream), "cuMemsetD8Async", &error);
  };
  const size_t n = static_cast<size_t>(b.n);
  if (!cu_check(cuCtxSetCurrent(p.context), "cuCtxSetCurrent", &error) || !zero(b.latent, n * sizeof(LatentState)) ||
      !zero(b.segments, n * static_cast<size_t>(c.segment_stride)) || !zero(b.visual, n * sizeof(VisualState)))
    return handler_error("kage_reset", error);
  return launch("kage_reset", c, p, p.reset, device_envs(c, p, b), stream);
}

ffi::Error step(CUstream stream, int32_t ordinal, CudaInstance* instance, std::string_view, ffi::RemainingArgs args,
                ffi::RemainingRets rets) {
  if (ffi::Error e = on_device_zero("kage_step", ordinal); e.failure()) return e;
  const JaxConfig& c = *instance->config;
  const ffi::ErrorOr<EnvBuffers> got = step_buffers(c, args, rets);
  if (!got.has_value()) return got.error();
  if (got->n > INT32_MAX) return handler_error("kage_step", "more than 2^31 - 1 environments");
  const DeviceProgram& p = *instance->program;
  std::string error;
  if (!cu_check(cuCtxSetCurrent(p.context), "cuCtxSetCurrent", &error)) return handler_error("kage_step", error);
  for (size_t i = 0; i < got->copy_count; ++i) {
    const InPlaceCopy& copy = got->copies[i];
    if (!cu_check(cuMemcpyDtoDAsync(reinterpret_cast<CUdeviceptr>(copy.to), reinterpret_cast<CUdeviceptr>(copy.from),
                                 copy.bytes, stream),
               "cuMemcpyDtoDAsync", &error))
      return handler_error("kage_step", error);
  }
  return launch("kage_step", c, p, p.step, device_envs(c, p, *got), stream);
}

XLA_FFI_DEFINE_HANDLER(kInstantiate, instantiate, ffi::Ffi::BindInstantiate().Attr<std::string_view>("spec_hash"));
XLA_FFI_DEFINE_HANDLER(kReset, reset,
                       ffi::Ffi::Bind()
                           .Ctx<ffi::PlatformStream<CUstream>>()
                           .Ctx<ffi::DeviceOrdinal>()
                           .Ctx<ffi::State<CudaInstance>>()
                           .Attr<std::string_view>("spec_hash")
                           .RemainingArgs()
                           .RemainingRets());
XLA_FFI_DEFINE_HANDLER(kStep, step,
                       ffi::Ffi::Bind()
                           .Ctx<ffi::PlatformStream<CUstream>>()
                           .Ctx<ffi::DeviceOrdinal>()
                           .Ctx<ffi::State<CudaInstance>>()
                           .Attr<std::string_view>("spec_hash")
                           .RemainingArgs()
                           .RemainingRets());

}  // namespace

HandlerBundle cuda_reset_handler() { return {kInstantiate, kReset}; }
HandlerBundle cuda_step_handler() { return {kInstantiate, kStep}; }

StateType cuda_instance_type() {
  static const XLA_FFI_TypeInfo info = ffi::MakeTypeInfo<CudaInstance>();
  return {&CudaInstance::id, &info};
}

}  // namespace kage::jax
