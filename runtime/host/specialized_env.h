// CPU backend, per environment: reset and step of one environment (latent, then visual, then the
// frame), written once over parameter values. The generic path passes run-time parameters; a
// generated file passes its config type's constexpr parameters, so the same code folds.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/latent/latent_step.h"
#include "runtime/rng.h"
#include "runtime/visual/render.h"
#include "runtime/visual/visual_update.h"

namespace kage {

/// One environment's host storage.
struct EnvSlot {
  LatentState* latent;
  VisualState* visual;
  uint8_t* segments;  ///< layout_segment_count(latent params) bytes
  uint8_t* obs;       ///< H x W x 3 bytes, row-major
  float* scratch;     ///< render_scratch_floats(visual params) floats
};

/// The observation of the current state of `e` (t = latent t).
inline void env_render(const LatentParams& lp, const VisualParams& vp, const AssetView& assets, Key episode_key,
                       const EnvSlot& e) {
  const LayoutView v{e.segments};
  const LatentState& s = *e.latent;
  const AgentView agent{s.x, s.y, s.camera_x};
  render_frame(vp, assets, agent, [&](int32_t r, int32_t c) { return solid(lp, v, r, c); }, *e.visual, episode_key,
               static_cast<uint32_t>(s.t), e.obs, e.scratch);
}

/// Starts episode `episode` (key `episode_key`): layout and latent reset, visual reset, first frame.
inline void env_reset(const LatentParams& lp, const VisualParams& vp, const AssetView& assets, Key episode_key,
                      uint32_t episode, const EnvSlot& e) {
  latent_reset(lp, episode_key, episode, e.segments, *e.latent);
  const LayoutView v{e.segments};
  visual_reset(vp, assets, episode_key, [&](int32_t c) { return ground_top(lp, v, c); }, *e.visual);
  env_render(lp, vp, assets, episode_key, e);
}

/// One step: latent step, visual update of the new t; renders unless `render` is false (the caller
/// resets a finished episode and renders that instead).
inline StepOutcome env_step(const LatentParams& lp, const VisualParams& vp, const AssetView& assets, Key episode_key,
                            int32_t action, bool render, const EnvSlot& e) {
  const StepOutcome o = latent_step(lp, LayoutView{e.segments}, *e.latent, action);
  visual_step(vp, assets, episode_key, static_cast<uint32_t>(e.latent->t), e.latent->vx, *e.visual);
  if (render) env_render(lp, vp, assets, episode_key, e);
  return o;
}

/// Version of the kage_host_* entry points below; a loader refuses a library with another one.
inline constexpr int32_t kHostAbiVersion = 2;

/// The entry points of a generated host library, as function pointers (filled by dlsym, or taken
/// from a generated file compiled into the program).
struct HostEntryPoints {
  int32_t (*abi_version)();
  const char* (*spec_hash)();
  void (*params)(LatentParams* latent, VisualParams* visual);
  void (*reset_env)(const AssetView* assets, Key episode_key, uint32_t episode, const EnvSlot* e);
  void (*step_env)(const AssetView* assets, Key episode_key, int32_t action, int32_t render, const EnvSlot* e,
                   StepOutcome* out);
  void (*render_env)(const AssetView* assets, Key episode_key, const EnvSlot* e);
};

/// The same entry points for a config type: Cfg::latent() and Cfg::visual() are constant expressions.
template <class Cfg>
struct SpecializedEnv {
  static constexpr LatentParams kLatent = Cfg::latent();
  static constexpr VisualParams kVisual = Cfg::visual();
  static int32_t abi_version() { return kHostAbiVersion; }
  static const char* spec_hash() { return Cfg::kSpecHash; }
  static void params(LatentParams* latent, VisualParams* visual) {
    *latent = kLatent;
    *visual = kVisual;
  }
  static void reset_env(const AssetView* assets, Key episode_key, uint32_t episode, const EnvSlot* e) {
    env_reset(kLatent, kVisual, *assets, episode_key, episode, *e);
  }
  static void step_env(const AssetView* assets, Key episode_key, int32_t action, int32_t render, const EnvSlot* e,
                       StepOutcome* out) {
    *out = env_step(kLatent, kVisual, *assets, episode_key, action, render != 0, *e);
  }
  static void render_env(const AssetView* assets, Key episode_key, const EnvSlot* e) {
    env_render(kLatent, kVisual, *assets, episode_key, *e);
  }
  static HostEntryPoints entry_points() { return {abi_version, spec_hash, params, reset_env, step_env, render_env}; }
};

}  // namespace kage

/// The extern "C" entry points of a generated host library (one config per library). A program that
/// compiles several generated files in (the equivalence test) defines KAGE_REGISTER_HOST_CONFIG(Cfg)
/// first and gets that instead.
#ifdef KAGE_REGISTER_HOST_CONFIG
#define KAGE_INSTANTIATE_HOST(Cfg) KAGE_REGISTER_HOST_CONFIG(Cfg)
#else
#define KAGE_INSTANTIATE_HOST(Cfg)                                                                          \
  extern "C" {                                                                                              \
  __attribute__((visibility("default"))) int32_t kage_host_abi_version() {                                  \
    return ::kage::SpecializedEnv<Cfg>::abi_version();                                                      \
  }                                                                                                         \
  __attribute__((visibility("default"))) const char* kage_host_spec_hash() {                                \
    return ::kage::SpecializedEnv<Cfg>::spec_hash();                                                        \
  }                                                                                                         \
  __attribute__((visibility("default"))) void kage_host_params(::kage::LatentParams* l, ::kage::VisualParams* v) { \
    ::kage::SpecializedEnv<Cfg>::params(l, v);                                                              \
  }                                                                                                         \
  __attribute__((visibility("default"))) void kage_host_reset_env(const ::kage::AssetView* a, ::kage::Key k,  \
                                                                  uint32_t ep, const ::kage::EnvSlot* e) {  \
    ::kage::SpecializedEnv<Cfg>::reset_env(a, k, ep, e);                                                    \
  }                                                                                                         \
  __attribute__((visibility("default"))) void kage_host_step_env(const ::kage::AssetView* a, ::kage::Key k,   \
                                                                 int32_t action, int32_t render,            \
                                                                 const ::kage::EnvSlot* e,                  \
                                                                 ::kage::StepOutcome* out) {                \
    ::kage::SpecializedEnv<Cfg>::step_env(a, k, action, render, e, out);                                    \
  }                                                                                                         \
  __attribute__((visibility("default"))) void kage_host_render_env(const ::kage::AssetView* a, ::kage::Key k, \
                                                                   const ::kage::EnvSlot* e) {              \
    ::kage::SpecializedEnv<Cfg>::render_env(a, k, e);                                                       \
  }                                                                                                         \
  }
#endif
