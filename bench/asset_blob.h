// A flat binary file holding a loaded asset pack (backgrounds and sprite sets), so that programs built
// with the CUDA toolkit alone (no image decoders) can use the project's assets. Written by
// kage_asset_blob from decoded images; read by the GPU benchmark.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runtime/visual/asset_view.h"

namespace kage::bench {

/// Host copies of every asset buffer; view() points into them.
struct AssetBlob {
  std::vector<uint8_t> bg;  ///< [bg_count][bg_h][bg_w][3]
  int32_t bg_count = 0;
  int32_t bg_h = 0;
  int32_t bg_w = 0;
  std::vector<uint8_t> sprite_pixels;
  std::vector<SpriteFrame> frames;
  std::vector<SpriteSet> agent_skins;
  std::vector<SpriteSet> npc_types;
  std::vector<SpriteSet> sticky_types;

  AssetView view() const;
};

/// Format: "KAGEASSETS1\n", eight int32 counts (bg_count, bg_h, bg_w, frames, pixel bytes, agent,
/// npc and sticky set counts), then the background bytes, the pixel bytes, the frames and the three
/// set tables, all little-endian as in memory.
bool write_asset_blob(const std::string& path, const AssetBlob& blob, std::string* error);
std::optional<AssetBlob> read_asset_blob(const std::string& path, std::string* error);

}  // namespace kage::bench
