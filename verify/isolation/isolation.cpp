// Dynamic isolation evidence: both configs of a pair stepped side by side on the CPU path.
#include "verify/isolation/isolation.h"

#include <cstring>

#include "api/environment.h"
#include "compiler/codegen/codegen.h"
#include "compiler/lower/lower.h"
#include "fileio/sha256.h"

namespace kage {

Json IsolationEvidence::to_json(const IsolationOptions& options) const {
  return Json{{"latent_spec_equal", latent_spec_equal},
              {"dynamics_source_identical", dynamics_source_identical},
              {"train_latent_section_sha256", train_latent_hash},
              {"eval_latent_section_sha256", eval_latent_hash},
              {"trajectories_identical", trajectories_identical},
              {"first_divergent_step", first_divergent_step},
              {"seeds", options.seeds},
              {"steps", options.steps},
              {"mean_abs_pixel_diff", mean_abs_pixel_diff},
              {"frames_differ", frames_differ},
              {"ok", ok()},
              {"problems", problems}};
}

IsolationEvidence dynamic_isolation(const Spec& train, const Spec& eval, const Schema& schema,
                                    const IsolationOptions& options) {
  IsolationEvidence ev;
  ev.latent_spec_equal = train.latent_values(schema) == eval.latent_values(schema);
  const LowerResult lt = lower_spec(train), le = lower_spec(eval);
  if (!lt.ok() || !le.ok()) {
    ev.problems.push_back("lowering failed: " + lt.error_text() + le.error_text());
    return ev;
  }
  const std::string st = generate_latent_section(lt.config->latent), se = generate_latent_section(le.config->latent);
  ev.train_latent_hash = sha256_hex(st);
  ev.eval_latent_hash = sha256_hex(se);
  ev.dynamics_source_identical = st == se;

  EnvironmentOptions eo;
  eo.num_envs = static_cast<int32_t>(options.seeds.size());
  EnvironmentResult rt = Environment::from_lowered(*lt.config, eo), re = Environment::from_lowered(*le.config, eo);
  if (!rt.ok() || !re.ok()) {
    ev.problems.push_back("cannot build the environments: " + rt.error + re.error);
    return ev;
  }
  CpuEnv& a = rt.env->env();
  CpuEnv& b = re.env->env();
  const size_t n = options.seeds.size();
  const bool same_size = a.frame_bytes() == b.frame_bytes();
  a.reset(options.seeds.data());
  b.reset(options.seeds.data());
  uint64_t diff_sum = 0, diff_count = 0;
  auto compare = [&](int32_t step) {
    for (size_t e = 0; e < n; ++e) {
      const auto env = static_cast<int32_t>(e);
      if (ev.first_divergent_step < 0 && std::memcmp(&a.latent_state(env), &b.latent_state(env), sizeof(LatentState)) != 0)
        ev.first_divergent_step = step;
    }
    if (!same_size) return;
    const uint8_t* pa = a.observations();
    const uint8_t* pb = b.observations();
    const size_t bytes = n * a.frame_bytes();
    for (size_t i = 0; i < bytes; ++i) diff_sum += static_cast<uint64_t>(pa[i] > pb[i] ? pa[i] - pb[i] : pb[i] - pa[i]);
    diff_count += bytes;
  };
  compare(0);
  // A fixed action sequence (mostly right, some jumps), the same for both sides.
  std::vector<int32_t> actions(n);
  uint32_t lcg = 2024u;
  for (int32_t t = 1; t <= options.steps; ++t) {
    for (int32_t& act : actions) {
      lcg = lcg * 1664525u + 1013904223u;
      const uint32_t r = lcg >> 24;
      act = r < 160 ? 2 : r < 210 ? 6 : static_cast<int32_t>(r & 7u);
    }
    a.step(actions.data());
    b.step(actions.data());
    compare(t);
  }
  ev.trajectories_identical = ev.first_divergent_step < 0;
  ev.mean_abs_pixel_diff = diff_count ? static_cast<double>(diff_sum) / static_cast<double>(diff_count) : 0.0;
  ev.frames_differ = !same_size || diff_sum > 0;

  if (!options.latent_pair) {
    if (!ev.latent_spec_equal) ev.problems.push_back("the latent parts of the two Specs differ");
    if (!ev.dynamics_source_identical) ev.problems.push_back("the generated dynamics sections differ");
    if (!ev.trajectories_identical)
      ev.problems.push_back("latent trajectories diverge at step " + std::to_string(ev.first_divergent_step));
  }
  if (!ev.frames_differ) ev.problems.push_back("eval frames never differ from train frames");
  return ev;
}

}  // namespace kage
