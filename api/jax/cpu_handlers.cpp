// kage.jax's CPU handlers: reset and step of the CPU batch code (HostKernels, the episode driver) on
// XLA's buffers, split over threads as HostBatch splits them; results do not depend on the split.
#include <algorithm>
#include <cstring>
#include <memory>
#include <string_view>
#include <thread>
#include <vector>

#include "api/jax/ffi_buffers.h"
#include "api/jax/ffi_handlers.h"
#include "runtime/rng.h"
#include "runtime/visual/render.h"

namespace kage::jax {
namespace ffi = xla::ffi;
namespace {

/// What an instantiated call keeps: its config.
struct CpuInstance {
  static ffi::TypeId id;
  std::shared_ptr<const JaxConfig> config;
};
ffi::TypeId CpuInstance::id = {};

ffi::ErrorOr<std::unique_ptr<CpuInstance>> instantiate(std::string_view spec_hash) {
  auto instance = std::make_unique<CpuInstance>();
  instance->config = find_config(spec_hash);
  if (!instance->config)
    return ffi::Unexpected(handler_error("instantiate",
                                         "no config with spec hash " + std::string(spec_hash) +
                                             " in this process: make it with kage.jax.make_env first"));
  return instance;
}

/// fn(env, slot) for every environment, over a static partition, one render scratch per thread.
template <class Fn>
void for_each_env(const JaxConfig& c, const EnvBuffers& b, const Fn& fn) {
  const int64_t threads = std::max<int64_t>(1, std::min<int64_t>(b.n, std::thread::hardware_concurrency()));
  const size_t scratch_floats = static_cast<size_t>(render_scratch_floats(c.visual));
  std::vector<float> scratch(scratch_floats * static_cast<size_t>(threads));
  auto range = [&](int64_t i) {
    for (int64_t env = b.n * i / threads; env < b.n * (i + 1) / threads; ++env) {
      const EnvSlot slot{b.latent + env, b.visual + env, b.segments + env * c.segment_stride,
                         b.obs + static_cast<size_t>(env) * c.frame_bytes(), scratch.data() + scratch_floats * i};
      fn(static_cast<int32_t>(env), slot);
    }
  };
  std::vector<std::thread> workers;
  for (int64_t i = 1; i < threads; ++i) workers.emplace_back(range, i);
  range(0);
  for (std::thread& w : workers) w.join();
}

ffi::Error reset(CpuInstance* instance, std::string_view, ffi::RemainingArgs args, ffi::RemainingRets rets) {
  const JaxConfig& c = *instance->config;
  const ffi::ErrorOr<EnvBuffers> got = reset_buffers(c, args, rets);
  if (!got.has_value()) return got.error();
  const EnvBuffers& b = *got;
  // Fresh buffers: zero the state first, so that padding and unused entity slots are defined bytes.
  std::memset(b.latent, 0, static_cast<size_t>(b.n) * sizeof(LatentState));
  std::memset(b.segments, 0, static_cast<size_t>(b.n) * static_cast<size_t>(c.segment_stride));
  std::memset(b.visual, 0, static_cast<size_t>(b.n) * sizeof(VisualState));
  for_each_env(c, b, [&](int32_t env, const EnvSlot& slot) {
    c.host->reset_env(c.asset_view, fold(seed_key(b.seeds[env]), 0), 0, slot);
    b.reward[env] = 0.0f;
    b.terminated[env] = b.truncated[env] = b.final_mask[env] = 0;
    record_info(b.info, env, b.latent[env], StepOutcome{});
  });
  return ffi::Error::Success();
}

ffi::Error step(CpuInstance* instance, std::string_view, ffi::RemainingArgs args, ffi::RemainingRets rets) {
  const JaxConfig& c = *instance->config;
  const ffi::ErrorOr<EnvBuffers> got = step_buffers(c, args, rets);
  if (!got.has_value()) return got.error();
  const EnvBuffers& b = *got;
  for (size_t i = 0; i < b.copy_count; ++i) std::memcpy(b.copies[i].to, b.copies[i].from, b.copies[i].bytes);
  const StepRows rows{0, b.reward, b.terminated, b.truncated, b.info, b.final_mask, b.final_info, nullptr, 1};
  for_each_env(c, b, [&](int32_t env, const EnvSlot& slot) {
    StepRows row = rows;
    row.env = env;
    row.final_obs = b.final_obs + static_cast<size_t>(env) * c.frame_bytes();
    c.host->step_env(c.asset_view, seed_key(b.seeds[env]), b.actions[env], slot, row);
  });
  return ffi::Error::Success();
}

XLA_FFI_DEFINE_HANDLER(kInstantiate, instantiate, ffi::Ffi::BindInstantiate().Attr<std::string_view>("spec_hash"));
XLA_FFI_DEFINE_HANDLER(kReset, reset,
                       ffi::Ffi::Bind()
                           .Ctx<ffi::State<CpuInstance>>()
                           .Attr<std::string_view>("spec_hash")
                           .RemainingArgs()
                           .RemainingRets());
XLA_FFI_DEFINE_HANDLER(kStep, step,
                       ffi::Ffi::Bind()
                           .Ctx<ffi::State<CpuInstance>>()
                           .Attr<std::string_view>("spec_hash")
                           .RemainingArgs()
                           .RemainingRets());

}  // namespace

HandlerBundle cpu_reset_handler() { return {kInstantiate, kReset}; }
HandlerBundle cpu_step_handler() { return {kInstantiate, kStep}; }

StateType cpu_instance_type() {
  static const XLA_FFI_TypeInfo info = ffi::MakeTypeInfo<CpuInstance>();
  return {&CpuInstance::id, &info};
}

}  // namespace kage::jax
