// Reward, episode counters, metrics and truncation of one step (spec 5.8, 5.10).
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/latent/latent_params.h"
#include "runtime/latent/latent_state.h"

namespace kage {

/// Updates the bookkeeping of `s`, whose x, vx, vy and t already hold the step's new values (t
/// incremented, spec 5.1 step 6), from the previous x and the pressed JUMP bit; returns the step's
/// reward and metrics. Float32 in the original's left-to-right order.
KAGE_HD StepOutcome update_reward(const LatentParams& p, LatentState& s, float x_prev, bool jump_pressed) {
  const float forward = maxf(0.0f, s.x - s.x_max) * p.forward_reward_scale;
  // The penalty charges a pressed JUMP bit whether or not a jump happened (spec 11.22).
  const float jump_cost = (jump_pressed ? 1.0f : 0.0f) * p.jump_penalty;
  // Exact float equality of the rounded positions (spec 11.23).
  const float idle_cost = (s.x == x_prev ? 1.0f : 0.0f) * p.idle_penalty;
  const float reward = forward - jump_cost - p.timestep_penalty - idle_cost;

  s.episode_return += reward;
  s.jump_count += jump_pressed ? 1 : 0;
  s.x_max = maxf(s.x_max, s.x);

  StepOutcome out;
  out.reward = reward;
  out.passed_distance = s.x - s.initial_x;
  out.success = out.passed_distance >= p.dist_to_success ? 1 : 0;
  out.progress = p.dist_to_success > 0.0f ? out.passed_distance / p.dist_to_success : 0.0f;
  s.success_once = (s.success_once || out.success) ? 1 : 0;

  const float t = static_cast<float>(s.t);
  const float t_prev = static_cast<float>(s.t - 1);
  s.vx_mean = (s.vx_mean * t_prev + s.vx) / t;
  s.vy_mean = (s.vy_mean * t_prev + s.vy) / t;

  // The core environment never terminates and keeps stepping after truncation (spec 11.26, 5.10).
  out.terminated = 0;
  out.truncated = s.t >= p.episode_length ? 1 : 0;
  return out;
}

}  // namespace kage
