// Builds an AssetPack from ordered source lists, following the original
// environment constructor's loading rules (spec 2.4).
#include "runtime/io/asset_pack.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "fileio/asset_scan.h"
#include "fileio/image_io.h"

namespace kage {
namespace {

constexpr int kDummySize = 16;

SpriteSetTable table_of(const std::vector<SpriteSet>& sets) {
  SpriteSetTable t{};
  t.sets = sets.empty() ? nullptr : sets.data();
  t.count = int32_t(sets.size());
  t.max_frames = 0;
  for (const SpriteSet& s : sets) t.max_frames = std::max(t.max_frames, s.frame_count);
  return t;
}

void append_frame(AssetPack& pack, int w, int h, const uint8_t* rgba, const std::string& path) {
  SpriteFrame f{int32_t(pack.sprite_pixels.size()), int32_t(w), int32_t(h)};
  const size_t n = size_t(w) * h * 4;
  if (rgba) {
    pack.sprite_pixels.insert(pack.sprite_pixels.end(), rgba, rgba + n);
  } else {
    pack.sprite_pixels.resize(pack.sprite_pixels.size() + n, 0);
  }
  pack.frames.push_back(f);
  pack.frame_paths.push_back(path);
}

}  // namespace

AssetView AssetPack::view() const {
  AssetView v{};
  v.bg = bg.empty() ? nullptr : bg.data();
  v.bg_count = bg_count;
  v.bg_h = bg_h;
  v.bg_w = bg_w;
  v.sprite_pixels = sprite_pixels.empty() ? nullptr : sprite_pixels.data();
  v.frames = frames.empty() ? nullptr : frames.data();
  v.agent_skins = table_of(agent_skins);
  v.npc_types = table_of(npc_types);
  v.sticky_types = table_of(sticky_types);
  return v;
}

SpriteSet load_sprite_set(AssetPack& pack, const std::string& dir, std::vector<std::string>* warnings) {
  SpriteSet set{int32_t(pack.frames.size()), 0};
  auto warn = [&](std::string msg) {
    if (warnings) warnings->push_back(std::move(msg));
  };
  std::error_code ec;
  const bool exists = std::filesystem::is_directory(dir, ec);
  const std::vector<std::string> files = scan_skin_frames(dir);
  for (const std::string& file : files) {
    ImageResult r = load_image(file, 4);
    if (!r.ok()) {
      // The original prints the error and skips the file (spec 2.4 skins step 4).
      warn(fmt::format("{} (frame skipped)", r.error));
      continue;
    }
    append_frame(pack, r.image->width, r.image->height, r.image->pixels.data(), file);
    ++set.frame_count;
  }
  if (set.frame_count == 0) {
    const char* why = !exists ? "directory does not exist" : files.empty() ? "no *.png files" : "no loadable *.png files";
    warn(fmt::format("{}: {}; using a transparent {}x{} dummy frame", dir, why, kDummySize, kDummySize));
    append_frame(pack, kDummySize, kDummySize, nullptr, "");
    set.frame_count = 1;
  }
  return set;
}

AssetPackResult load_asset_pack(const AssetSources& sources) {
  AssetPackResult result;
  AssetPack pack;
  const int H = sources.height;
  if (H <= 0 && !sources.backgrounds.empty()) {
    result.error = fmt::format("invalid observation height {}", H);
    return result;
  }
  for (size_t i = 0; i < sources.backgrounds.size(); ++i) {
    const std::string& path = sources.backgrounds[i];
    ImageResult r = load_image(path, 3);
    if (!r.ok()) {
      result.error = r.error;
      return result;
    }
    Image img = std::move(*r.image);
    if (i == 0) {
      // new_w = int(H * w0 / h0): Python float division, then truncation.
      const double w = double(H) * double(img.width) / double(img.height);
      pack.bg_w = int32_t(w);
      pack.bg_h = H;
      if (pack.bg_w <= 0) {
        result.error = fmt::format("{}: {}x{} image gives a background width of 0 at height {}", path,
                                   img.width, img.height, H);
        return result;
      }
      pack.bg.reserve(sources.backgrounds.size() * size_t(pack.bg_w) * H * 3);
    }
    if (img.width != pack.bg_w || img.height != pack.bg_h) img = resize_lanczos(img, pack.bg_w, pack.bg_h);
    pack.bg.insert(pack.bg.end(), img.pixels.begin(), img.pixels.end());
    ++pack.bg_count;
  }
  for (const std::string& dir : sources.agent_skins) {
    pack.agent_skins.push_back(load_sprite_set(pack, dir, &result.warnings));
  }
  for (const std::string& dir : sources.npc_types) {
    pack.npc_types.push_back(load_sprite_set(pack, dir, &result.warnings));
  }
  for (const std::string& dir : sources.sticky_types) {
    pack.sticky_types.push_back(load_sprite_set(pack, dir, &result.warnings));
  }
  result.pack = std::move(pack);
  return result;
}

}  // namespace kage
