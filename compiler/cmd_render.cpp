// kagec render: run one environment with a fixed policy and write PNG frames, an animated GIF and/or a
// contact sheet of the observations.
#include <filesystem>
#include <ostream>

#include "compiler/cli_common.h"
#include "compiler/environment.h"
#include "runtime/host/gif_writer.h"
#include "runtime/host/image_io.h"
#include "runtime/rng.h"

namespace kage {

namespace {

constexpr int32_t kActionRight = 2;
constexpr int32_t kActionCount = 8;
constexpr int kSheetColumns = 8;
constexpr int kSheetGap = 2;
constexpr int kGifDelayCs = 5;  // 20 frames per second of GIF time

Image frame_image(const CpuEnv& env) {
  Image img;
  img.width = env.width();
  img.height = env.height();
  img.channels = 3;
  img.pixels.assign(env.observation(0), env.observation(0) + env.frame_bytes());
  return img;
}

/// The frames laid out left to right, top to bottom, on a grey grid.
Image contact_sheet(const std::vector<Image>& frames) {
  Image sheet;
  if (frames.empty()) return sheet;
  const int w = frames[0].width, h = frames[0].height;
  const int cols = std::min<int>(kSheetColumns, static_cast<int>(frames.size()));
  const int rows = (static_cast<int>(frames.size()) + cols - 1) / cols;
  sheet.width = cols * w + (cols + 1) * kSheetGap;
  sheet.height = rows * h + (rows + 1) * kSheetGap;
  sheet.channels = 3;
  sheet.pixels.assign(static_cast<size_t>(sheet.width) * sheet.height * 3, 64);
  for (size_t i = 0; i < frames.size(); ++i) {
    const int x0 = kSheetGap + static_cast<int>(i % cols) * (w + kSheetGap);
    const int y0 = kSheetGap + static_cast<int>(i / cols) * (h + kSheetGap);
    for (int y = 0; y < h; ++y) std::copy_n(frames[i].at(0, y), w * 3, sheet.at(x0, y0 + y));
  }
  return sheet;
}

bool report(const IoStatus& st, CommandIo& io) {
  if (!st.ok()) io.err << "kagec render: " << st.error << "\n";
  return st.ok();
}

}  // namespace

int cmd_render(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("Run one environment with a fixed policy and write its observations as images.", "render");
  std::string config, policy = "right", gif, sheet, out_dir, asset_root;
  uint64_t seed = 0;
  int steps = 100, every = 10;
  app.add_option("config", config, "config file")->required();
  app.add_option("--seed", seed, "environment seed");
  app.add_option("--steps", steps, "steps to run after the reset")->check(CLI::NonNegativeNumber);
  app.add_option("--policy", policy, "right: always move right; random: uniform actions from the seed")
      ->check(CLI::IsMember({"right", "random"}));
  app.add_option("--every", every, "keep every K-th frame (frame 0 is the reset observation)")->check(CLI::PositiveNumber);
  app.add_option("--gif", gif, "write the kept frames as an animated GIF");
  app.add_option("--sheet", sheet, "write the kept frames as one contact sheet PNG");
  app.add_option("-o,--output-dir", out_dir, "write each kept frame as frame_<t>.png into this directory");
  app.add_option("--asset-root", asset_root, "resolve asset paths against this directory");
  if (auto code = parse_args(app, args, io)) return *code;
  if (gif.empty() && sheet.empty() && out_dir.empty()) {
    io.err << "kagec render: nothing to write; give --gif FILE, --sheet FILE and/or -o DIR\n";
    return kExitUsage;
  }
  EnvironmentOptions options;
  if (!asset_root.empty()) options.asset_root = asset_root;
  EnvironmentResult opened = Environment::open(config, options);
  io.err << opened.warnings;
  if (!opened.ok()) {
    io.err << opened.error;
    return kExitErrors;
  }
  CpuEnv& env = opened.env->env();
  if (!out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec) {
      io.err << "kagec render: cannot create '" << out_dir << "': " << ec.message() << "\n";
      return kExitErrors;
    }
  }
  env.reset(&seed);
  std::vector<Image> kept;
  const Key policy_key = fold(seed_key(seed), 0x706F6C69u);  // the policy's own stream, apart from the env's
  float total = 0.0f;
  for (int t = 0; t <= steps; ++t) {
    if (t > 0) {
      const int32_t action = policy == "right" ? kActionRight : randint(policy_key, static_cast<uint32_t>(t), 0, kActionCount);
      env.step(&action);
      total += env.info().reward[0];
    }
    if (t % every != 0) continue;
    kept.push_back(frame_image(env));
    if (!out_dir.empty() &&
        !report(write_png((std::filesystem::path(out_dir) / ("frame_" + std::to_string(t) + ".png")).string(), kept.back()), io))
      return kExitErrors;
  }
  if (!gif.empty() && !report(write_gif(gif, kept, kGifDelayCs), io)) return kExitErrors;
  if (!sheet.empty() && !report(write_png(sheet, contact_sheet(kept)), io)) return kExitErrors;
  io.out << "rendered " << kept.size() << " frames of " << config << " (seed " << seed << ", " << steps
         << " steps, policy " << policy << "): x " << env.info().x[0] << ", return " << total << "\n";
  return kExitOk;
}

}  // namespace kage
