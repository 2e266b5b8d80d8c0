// The CPU backend's per-environment entry points: reset, step and render of one environment through
// the episode driver (runtime/episode.h), over a parameter provider. The generic path passes run-time
// parameters (RuntimeParams); a generated file passes its config type's constants (StaticParams), so
// the same code folds. KAGE_INSTANTIATE_HOST emits a generated library's extern "C" entry points.
#pragma once

#include <cstring>

#include "runtime/episode.h"
#include "runtime/episode_info.h"
#include "runtime/kage_hd.h"
#include "runtime/rng.h"
#include "runtime/visual/render.h"

namespace kage {

/// One environment's host storage.
struct EnvSlot {
  LatentState* latent;
  VisualState* visual;
  uint8_t* segments;  ///< layout_segment_count(latent params) bytes
  uint8_t* obs;       ///< H x W x 3 bytes, row-major
  float* scratch;     ///< render_scratch_floats(visual params) floats
};

/// Where one step's results go: row `env` of the batch's columns, and this environment's final frame.
struct StepRows {
  int32_t env;
  float* reward;
  uint8_t* terminated;
  uint8_t* truncated;
  InfoArrays info;
  uint8_t* final_mask;
  InfoArrays final_info;
  uint8_t* final_obs;  ///< H x W x 3 bytes: the finished episode's last frame
  /// After an automatic reset, info shows the new episode's spawn point (1) or keeps the finished
  /// step's (0; final_info has it either way).
  int32_t info_shows_new_episode;
};

/// A generated config's parameters as constants (the specialized host path).
template <class Cfg>
struct StaticParams {
  static constexpr bool kVisual = true;
  static constexpr LatentParams kLatentValues = Cfg::latent();
  static constexpr VisualParams kVisualValues = Cfg::visual();
  static const LatentParams& latent() { return kLatentValues; }
  static const VisualParams& visual() { return kVisualValues; }
};

/// The observation of the current state of `e` (t = latent t).
template <class P>
void env_render(const P& p, const AssetView& assets, Key episode_key, const EnvSlot& e) {
  const LayoutView v{e.segments};
  const LatentState& s = *e.latent;
  const AgentView agent{s.x, s.y, s.camera_x};
  render_frame(p.visual(), assets, agent, [&](int32_t r, int32_t c) { return solid(p.latent(), v, r, c); },
               *e.visual, episode_key, static_cast<uint32_t>(s.t), e.obs, e.scratch);
}

/// Starts episode `episode` (key `episode_key`) and renders its first frame.
template <class P>
void env_reset(const P& p, const AssetView& assets, Key episode_key, uint32_t episode, const EnvSlot& e) {
  episode_reset(p, assets, episode_key, episode, e.segments, *e.latent, e.visual);
  env_render(p, assets, episode_key, e);
}

/// The episode driver's outputs on the CPU: every step renders; a finished episode's frame and info
/// are kept before the next episode starts.
template <class P>
struct HostStepOut {
  const P& p;
  const AssetView& assets;
  Key seed;  ///< seed_key of the environment's seed
  const EnvSlot& e;
  const StepRows& rows;

  Key episode_key(uint32_t episode) const { return fold(seed, episode); }
  void record(const LatentState& ls, const StepOutcome& o) const {
    rows.reward[rows.env] = o.reward;
    rows.terminated[rows.env] = o.terminated;
    rows.truncated[rows.env] = o.truncated;
    record_info(rows.info, rows.env, ls, o);
  }
  bool stepped(bool done, const uint8_t*, const LatentState& ls, const VisualState*) const {
    env_render(p, assets, episode_key(ls.episode), e);
    rows.final_mask[rows.env] = done ? 1 : 0;
    if (!done) return false;
    std::memcpy(rows.final_obs, e.obs, static_cast<size_t>(p.visual().H) * p.visual().W * 3);
    copy_info_row(rows.final_info, rows.info, rows.env);
    return true;
  }
  void restarted(const uint8_t*, const LatentState& ls, const VisualState*) const {
    env_render(p, assets, episode_key(ls.episode), e);
    if (rows.info_shows_new_episode) record_info(rows.info, rows.env, ls, StepOutcome{});
  }
};

/// One step of one environment (`seed`: seed_key of its seed) into `rows`.
template <class P>
void env_step(const P& p, const AssetView& assets, Key seed, int32_t action, const EnvSlot& e, const StepRows& rows) {
  HostStepOut<P> out{p, assets, seed, e, rows};
  episode_step(p, assets, action, e.segments, *e.latent, e.visual, out);
}

/// Version of the kage_host_* entry points below; a loader refuses a library with another one.
inline constexpr int32_t kHostAbiVersion = 3;

/// The entry points of a generated host library, as function pointers (filled by dlsym, or taken
/// from a generated file compiled into the program).
struct HostEntryPoints {
  int32_t (*abi_version)();
  const char* (*spec_hash)();
  void (*params)(LatentParams* latent, VisualParams* visual);
  void (*reset_env)(const AssetView* assets, Key episode_key, uint32_t episode, const EnvSlot* e);
  void (*step_env)(const AssetView* assets, Key seed, int32_t action, const EnvSlot* e, const StepRows* rows);
  void (*render_env)(const AssetView* assets, Key episode_key, const EnvSlot* e);
};

/// The same entry points for a config type: Cfg::latent() and Cfg::visual() are constant expressions.
template <class Cfg>
struct SpecializedEnv {
  static constexpr StaticParams<Cfg> kParams{};
  static int32_t abi_version() { return kHostAbiVersion; }
  static const char* spec_hash() { return Cfg::kSpecHash; }
  static void params(LatentParams* latent, VisualParams* visual) {
    *latent = kParams.latent();
    *visual = kParams.visual();
  }
  static void reset_env(const AssetView* assets, Key episode_key, uint32_t episode, const EnvSlot* e) {
    env_reset(kParams, *assets, episode_key, episode, *e);
  }
  static void step_env(const AssetView* assets, Key seed, int32_t action, const EnvSlot* e, const StepRows* rows) {
    env_step(kParams, *assets, seed, action, *e, *rows);
  }
  static void render_env(const AssetView* assets, Key episode_key, const EnvSlot* e) {
    env_render(kParams, *assets, episode_key, *e);
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
                                                                 int32_t action, const ::kage::EnvSlot* e,  \
                                                                 const ::kage::StepRows* rows) {            \
    ::kage::SpecializedEnv<Cfg>::step_env(a, k, action, e, rows);                                           \
  }                                                                                                         \
  __attribute__((visibility("default"))) void kage_host_render_env(const ::kage::AssetView* a, ::kage::Key k, \
                                                                   const ::kage::EnvSlot* e) {              \
    ::kage::SpecializedEnv<Cfg>::render_env(a, k, e);                                                       \
  }                                                                                                         \
  }
#endif
