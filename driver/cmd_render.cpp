// kagec render: run one environment with a fixed policy and write PNG frames, an animated GIF and/or a
// contact sheet of the observations. Frames go to disk as they are rendered (only a contact sheet keeps
// its frames, and it holds a bounded number); a run whose output would not fit the disk is refused.
#include <algorithm>
#include <filesystem>
#include <optional>
#include <ostream>
#include <utility>

#include "api/environment.h"
#include "driver/cli_common.h"
#include "runtime/io/gif_writer.h"
#include "fileio/image_io.h"
#include "runtime/rng.h"

namespace kage {

namespace {

constexpr int32_t kActionRight = 2;
constexpr int32_t kActionCount = 8;
constexpr int kSheetColumns = 8;
constexpr int kSheetGap = 2;
constexpr int kGifDelayCs = 5;  // 20 frames per second of GIF time
constexpr int64_t kMaxSheetFrames = 1024;  // the sheet is built in memory

/// Free bytes on the file system that would hold `path` (its directory, or the nearest existing parent).
std::optional<uint64_t> free_bytes(const std::filesystem::path& path) {
  std::filesystem::path dir = std::filesystem::absolute(path);
  std::error_code ec;
  while (!dir.empty() && !std::filesystem::is_directory(dir, ec)) {
    if (dir == dir.parent_path()) break;
    dir = dir.parent_path();
  }
  const std::filesystem::space_info s = std::filesystem::space(dir, ec);
  if (ec) return std::nullopt;
  return s.available;
}

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
  int64_t steps = 100, every = 10;
  bool force = false;
  app.option_defaults()->always_capture_default();  // --help shows --seed 0, --steps 100, --every 10, --policy right
  app.add_option("config", config, "config file")->required();
  app.add_option("--seed", seed, "environment seed");
  app.add_option("--steps", steps, "steps to run after the reset")->check(CLI::NonNegativeNumber);
  app.add_option("--policy", policy, "right: always move right; random: uniform actions from the seed")
      ->check(CLI::IsMember({"right", "random"}));
  app.add_option("--every", every, "keep every K-th frame (frame 0 is the reset observation)")->check(CLI::PositiveNumber);
  app.add_option("--gif", gif, "write the kept frames as an animated GIF");
  app.add_option("--sheet", sheet, "write the kept frames as one contact sheet PNG (at most 1024 frames)");
  app.add_option("-o,--output-dir", out_dir, "write each kept frame as frame_<t>.png into this directory");
  app.add_option("--asset-root", asset_root, "resolve asset paths against this directory");
  app.add_flag("--force", force, "write even when the estimated output exceeds the free disk space");
  if (auto code = parse_args(app, args, io)) return *code;
  if (gif.empty() && sheet.empty() && out_dir.empty()) {
    io.err << "kagec render: nothing to write; give --gif FILE, --sheet FILE and/or -o DIR\n";
    return kExitUsage;
  }
  const int64_t kept_frames = steps / every + 1;
  if (!sheet.empty() && kept_frames > kMaxSheetFrames) {
    io.err << "kagec render: a contact sheet holds at most " << kMaxSheetFrames << " frames, and --steps " << steps
           << " --every " << every << " keeps " << kept_frames << "; raise --every or lower --steps\n";
    return kExitUsage;
  }
  EnvironmentOptions options;
  if (!asset_root.empty()) options.asset_root = asset_root;
  EnvironmentResult opened = Environment::open(config, options);
  io.err << opened.warnings;
  if (!opened.ok()) {
    io.err << opened.error;
    hint_shipped("render", "configs", config, io);
    return kExitErrors;
  }
  CpuEnv& env = opened.env->env();
  // What each output will take at most: PNGs and GIF frames are at most about their raw size.
  const uint64_t frame_bytes = env.frame_bytes() + 1024;
  const std::pair<const std::string*, uint64_t> outputs[] = {
      {&out_dir, uint64_t(kept_frames) * frame_bytes},
      {&gif, uint64_t(kept_frames) * (frame_bytes / 3 * 2)},
      {&sheet, uint64_t(std::min(kept_frames, kMaxSheetFrames)) * frame_bytes}};
  for (const auto& [path, need] : outputs) {
    if (path->empty() || force) continue;
    const std::optional<uint64_t> free = free_bytes(*path);
    if (free && need > *free) {
      io.err << "kagec render: '" << *path << "' would take up to " << gib_text(need) << " for " << kept_frames
             << " frames, but its disk has " << gib_text(*free) << " free; raise --every, lower --steps, or add --force\n";
      return kExitErrors;
    }
  }
  if (!out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec) {
      io.err << "kagec render: cannot create '" << out_dir << "': " << ec.message() << "\n";
      return kExitErrors;
    }
  }
  GifStream gif_stream;
  if (!gif.empty() && !report(gif_stream.open(gif, env.width(), env.height(), kGifDelayCs), io)) return kExitErrors;
  env.reset(&seed);
  std::vector<Image> sheet_frames;
  const Key policy_key = fold(seed_key(seed), 0x706F6C69u);  // the policy's own stream, apart from the env's
  float total = 0.0f;
  for (int64_t t = 0; t <= steps; ++t) {
    if (t > 0) {
      const int32_t action = policy == "right" ? kActionRight : randint(policy_key, static_cast<uint32_t>(t), 0, kActionCount);
      env.step(&action);
      total += env.info().reward[0];
    }
    if (t % every != 0) continue;
    const Image frame = frame_image(env);
    if (!out_dir.empty() &&
        !report(write_png((std::filesystem::path(out_dir) / ("frame_" + std::to_string(t) + ".png")).string(), frame), io))
      return kExitErrors;
    if (!gif.empty() && !report(gif_stream.add(frame), io)) return kExitErrors;
    if (!sheet.empty()) sheet_frames.push_back(frame);
  }
  if (!gif.empty() && !report(gif_stream.finish(), io)) return kExitErrors;
  if (!sheet.empty() && !report(write_png(sheet, contact_sheet(sheet_frames)), io)) return kExitErrors;
  io.out << "rendered " << kept_frames << " frames of " << config << " (seed " << seed << ", " << steps
         << " steps, policy " << policy << "): x " << env.info().x[0] << ", return " << total << "\n";
  return kExitOk;
}

}  // namespace kage
