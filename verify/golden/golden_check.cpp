// Golden replay and comparison for `kagec golden check`.
#include "verify/golden/golden_check.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "runtime/latent/latent_step.h"
#include "runtime/visual/filters.h"
#include "runtime/visual/lights.h"
#include "runtime/visual/render.h"
#include "runtime/visual/visual_update.h"

namespace kage {

namespace {

using nlohmann::json;

constexpr double kFloatTolerance = 1e-4;  // golden/README.md, physics

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// The worst deviation of one field, accumulated over steps and episodes.
struct FieldWorst {
  bool exact = true;
  double worst = 0;
  std::string first_failure;
  void add(double got, double want, bool exact_field, const std::string& where) {
    exact = exact && exact_field;
    const double d = std::fabs(got - want);
    worst = std::max(worst, d);
    const bool ok = exact_field ? d == 0 : d <= kFloatTolerance;
    if (!ok && first_failure.empty()) first_failure = where + ": expected " + num(want) + ", got " + num(got);
  }
  GoldenLine line(const std::string& name) const {
    GoldenLine l{name, "max |diff|", worst, exact ? "0 (exact)" : num(kFloatTolerance), first_failure.empty(),
                 first_failure};
    return l;
  }
};

double as_number(const json& v) { return v.is_boolean() ? (v.get<bool>() ? 1.0 : 0.0) : v.get<double>(); }
bool is_exact(const json& v) { return v.is_boolean() || v.is_number_integer(); }

/// A recorded state or step field of ours, by the recording's name; false if the name is unknown.
bool field_value(const std::string& f, const LatentState& s, const StepOutcome& o, double& out) {
  const std::map<std::string, double> values = {
      {"x", s.x}, {"y", s.y}, {"vx", s.vx}, {"vy", s.vy}, {"grounded", s.grounded}, {"coyote_timer", s.coyote_timer},
      {"camera_x", s.camera_x}, {"x_max", s.x_max}, {"jump_count", s.jump_count}, {"episode_return", s.episode_return},
      {"t", s.t}, {"success_once", s.success_once}, {"reward", o.reward}, {"passed_distance", o.passed_distance},
      {"progress", o.progress}, {"success", o.success}, {"truncated", o.truncated}};
  const auto it = values.find(f);
  if (it == values.end()) return false;
  out = it->second;
  return true;
}

/// Segment heights of a recorded ground_top; empty when it does not fit `p`.
std::vector<uint8_t> install_layout(const LatentParams& p, const json& ground_top) {
  const std::vector<int32_t> gt = ground_top.get<std::vector<int32_t>>();
  std::vector<uint8_t> segments(layout_segment_count(p));
  if (static_cast<int32_t>(gt.size()) != p.length || !layout_from_ground_top(p, gt.data(), segments.data())) return {};
  return segments;
}

std::optional<json> read_json(const std::string& path, std::string& error) {
  std::ifstream in(path);
  if (!in) {
    error = path + ": cannot read";
    return std::nullopt;
  }
  json j = json::parse(in, nullptr, false);
  if (j.is_discarded()) {
    error = path + ": not valid JSON";
    return std::nullopt;
  }
  return j;
}

GoldenLine failure(const std::string& name, const std::string& why) {
  return GoldenLine{name, "-", 0, "-", false, why};
}

}  // namespace

GoldenLine compare_image(const std::string& name, const uint8_t* got, const Image& expected, const ImageTolerance& tol) {
  const ImageDiff d = image_diff(got, expected.pixels.data(), static_cast<int64_t>(expected.pixels.size()));
  GoldenLine l;
  l.name = name;
  l.measure = "max |diff|";
  l.worst = d.max_abs;
  if (tol.max_abs == 0) {
    l.limit = "0, every value equal";
  } else {
    l.limit = std::to_string(tol.max_abs);
    if (tol.min_equal > 0) l.limit += ", equal >= " + num(tol.min_equal * 100) + " %";
    if (tol.max_mean < 255) l.limit += ", mean < " + num(tol.max_mean);
  }
  l.pass = d.max_abs <= tol.max_abs && d.equal_fraction() >= tol.min_equal &&
           (tol.max_mean >= 255 || d.mean_abs() < tol.max_mean || d.max_abs == 0);
  l.detail = "equal " + num(d.equal_fraction() * 100) + " %, mean " + num(d.mean_abs());
  return l;
}

std::vector<GoldenLine> check_physics(const std::string& name, const LatentParams& p, const json& file) {
  std::vector<GoldenLine> out;
  if (file.value("episode_length", -1) != p.episode_length)  // a field of the recording: not-a-config-key
    return {failure(name, "episode_length of the recording differs from the config's " + std::to_string(p.episode_length))};
  const std::vector<std::string> fields = file.at("fields").get<std::vector<std::string>>();
  std::map<std::string, FieldWorst> worst;
  FieldWorst layout, initial;
  for (const json& ep : file.at("episodes")) {
    const std::string where = "seed " + std::to_string(ep.at("seed").get<int64_t>());
    const std::vector<uint8_t> segments = install_layout(p, ep.at("ground_top"));
    if (segments.empty()) {
      layout.add(1, 0, true, where + " ground_top is not a layout of this config");
      continue;
    }
    const LayoutView v{segments.data()};
    if (ep.contains("solid_mask_rows") && ep["solid_mask_rows"].is_array()) {
      const json& rows = ep["solid_mask_rows"];
      for (int32_t r = 0; r < static_cast<int32_t>(rows.size()); ++r) {
        const std::string row = rows[r].get<std::string>();
        for (int32_t c = 0; c < static_cast<int32_t>(row.size()); ++c)
          layout.add(solid(p, v, r, c), row[c] == '1', true, where + " solid mask row " + std::to_string(r) + " column " + std::to_string(c));
      }
    }
    LatentState s;
    latent_reset_on_layout(p, v, 0, s);
    for (const auto& [f, want] : ep.at("initial").items()) {
      double got = 0;
      if (field_value(f, s, StepOutcome{}, got)) initial.add(got, as_number(want), is_exact(want), where + " initial " + f);
    }
    const std::vector<int32_t> actions = ep.at("actions").get<std::vector<int32_t>>();
    const json& traj = ep.at("trajectory");
    for (size_t i = 0; i < actions.size(); ++i) {
      const StepOutcome o = latent_step(p, v, s, actions[i]);
      for (const std::string& f : fields) {
        double got = 0;
        const json& want = traj.at(f).at(i);
        if (!field_value(f, s, o, got)) {
          worst[f].add(1, 0, true, "unknown field");
          continue;
        }
        worst[f].add(got, as_number(want), is_exact(want), where + " step " + std::to_string(i + 1));
      }
    }
  }
  out.push_back(layout.line(name + " layout"));
  out.push_back(initial.line(name + " initial"));
  for (const std::string& f : fields) out.push_back(worst[f].line(name + " " + f));
  return out;
}

std::vector<GoldenLine> check_render(const std::string& dir, const LatentParams& lp, const VisualParams& vp,
                                     const AssetView& assets, const ImageTolerance& tol) {
  std::string error;
  const std::optional<json> meta = read_json(dir + "/meta.json", error);
  if (!meta) return {failure(dir, error)};
  std::vector<GoldenLine> out;
  FieldWorst state;
  std::vector<uint8_t> frame(static_cast<size_t>(vp.H) * vp.W * 3);
  std::vector<float> scratch(render_scratch_floats(vp));
  const std::string base = std::filesystem::path(dir).filename().string();
  for (const json& ep : meta->at("episodes")) {
    const std::string seed = std::to_string(ep.at("seed").get<int64_t>());
    const std::vector<uint8_t> segments = install_layout(lp, ep.at("ground_top"));
    if (segments.empty()) {
      out.push_back(failure(base + " seed " + seed, "ground_top is not a layout of this config"));
      continue;
    }
    const LayoutView v{segments.data()};
    auto solid_at = [&](int32_t r, int32_t c) { return solid(lp, v, r, c); };
    // Our own replay of the actions, to compare the recorded state with.
    LatentState s;
    latent_reset_on_layout(lp, v, 0, s);
    VisualState vs;
    visual_reset(vp, assets, Key{0, 0}, [&](int32_t c) { return ground_top(lp, v, c); }, vs);
    const std::vector<int32_t> actions = ep.at("actions").get<std::vector<int32_t>>();
    const json& frames = ep.at("frames");
    for (int32_t t = 0; t <= static_cast<int32_t>(actions.size()); ++t) {
      if (t > 0) {
        latent_step(lp, v, s, actions[t - 1]);
        visual_step(vp, assets, Key{0, 0}, static_cast<uint32_t>(t), s.vx, vs);
      }
      const std::string key = std::to_string(t);
      if (!frames.contains(key)) continue;
      const json& fr = frames[key];
      const std::string where = "seed " + seed + " t " + key;
      state.add(s.x, fr.at("x").get<double>(), false, where + " x");
      state.add(s.y, fr.at("y").get<double>(), false, where + " y");
      state.add(s.camera_x, fr.at("camera_x").get<double>(), false, where + " camera_x");
      state.add(vs.sprite_idx, fr.at("sprite_idx").get<double>(), false, where + " sprite_idx");
      state.add(vs.animation_timer, fr.at("animation_timer").get<double>(), false, where + " animation_timer");
      state.add(vs.shape_angle, fr.at("shape_angle").get<double>(), false, where + " shape_angle");
      // The frame is rendered from the recorded state, so that image and state are judged apart.
      VisualState rec = vs;
      rec.sprite_idx = fr.at("sprite_idx").get<int32_t>();
      rec.animation_timer = fr.at("animation_timer").get<float>();
      rec.shape_angle = fr.at("shape_angle").get<float>();
      const AgentView agent{fr.at("x").get<float>(), fr.at("y").get<float>(), fr.at("camera_x").get<float>()};
      render_frame(vp, assets, agent, solid_at, rec, Key{0, 0}, static_cast<uint32_t>(t), frame.data(), scratch.data());
      const std::string png = "seed" + seed + "_t" + key + ".png";
      ImageResult expected = load_image(dir + "/" + png, 3);
      if (!expected.ok()) {
        out.push_back(failure(base + "/" + png, expected.error));
      } else if (expected.image->width != vp.W || expected.image->height != vp.H) {
        out.push_back(failure(base + "/" + png, "size differs from the config's W x H"));
      } else {
        out.push_back(compare_image(base + "/" + png, frame.data(), *expected.image, tol));
      }
    }
  }
  out.insert(out.begin(), state.line(base + " replayed state"));
  return out;
}

void apply_filter_chain(const VisualParams& p, Image& image) {
  const size_t n = image.pixels.size();
  std::vector<float> f(n), tmp(n);
  apply_filters(p, Preset::kNone, filter_keys(Key{0, 0}, 0), image.pixels.data(), f.data(), tmp.data());
}

void apply_point_lights(const VisualParams& p, const float (&x)[kMaxLights], const float (&y)[kMaxLights], Image& image) {
  VisualState s{};
  std::copy(x, x + kMaxLights, s.light_x);
  std::copy(y, y + kMaxLights, s.light_y);
  for (int32_t r = 0; r < image.height; ++r)
    for (int32_t c = 0; c < image.width; ++c) light_pixel(p, s, r, c, image.at(c, r));
}

}  // namespace kage
