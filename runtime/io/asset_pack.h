// Asset loading (spec 2.4 steps 5-6 and skins step 4): background stack and
// sprite sets in contiguous host buffers, ready to copy to a device.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runtime/visual/asset_view.h"

namespace kage {

/// What to load, already resolved to ordered lists (see asset_scan.h).
struct AssetSources {
  /// Background image files; the first one fixes the stack width.
  std::vector<std::string> backgrounds;
  /// One directory per agent skin / world NPC type / sticky NPC type.
  std::vector<std::string> agent_skins;
  std::vector<std::string> npc_types;
  std::vector<std::string> sticky_types;
  /// Observation height H; backgrounds are brought to H rows.
  int height = 128;
};

/// Host-side asset storage. All buffers are contiguous; `view()` points into
/// them, so the pack must outlive (and not be modified under) the view.
struct AssetPack {
  /// uint8 RGB [bg_count][bg_h][bg_w][3].
  std::vector<uint8_t> bg;
  int32_t bg_count = 0;
  int32_t bg_h = 0;
  int32_t bg_w = 0;
  /// RGBA8 pixels of every frame, frame k at byte `frames[k].offset`.
  std::vector<uint8_t> sprite_pixels;
  std::vector<SpriteFrame> frames;
  /// Source file of each frame; empty for a dummy frame.
  std::vector<std::string> frame_paths;
  std::vector<SpriteSet> agent_skins;
  std::vector<SpriteSet> npc_types;
  std::vector<SpriteSet> sticky_types;

  /// A pointer view over this pack's host buffers.
  AssetView view() const;
};

/// Result of load_asset_pack. On error `pack` is empty and `error` names the
/// file ("path: reason"). `warnings` are the messages the original prints and
/// continues after (a skin dir without PNGs, a PNG that fails to load).
struct [[nodiscard]] AssetPackResult {
  std::optional<AssetPack> pack;
  std::string error;
  std::vector<std::string> warnings;
  bool ok() const { return pack.has_value(); }
};

/// Loads every source. Backgrounds: converted to RGB; the first sets
/// `bg_w = int(H * w0 / h0)`; each image whose size differs from (bg_w, H) is
/// resized with Pillow's Lanczos. Any background failure is an error.
/// Sprites: each PNG converted to RGBA at native size; one that fails is
/// skipped with a warning; a dir with no loadable PNG gives one transparent
/// 16x16 dummy frame and a warning (spec 2.4 skins step 4).
AssetPackResult load_asset_pack(const AssetSources& sources);

/// Loads one skin directory's frames into `pack`, appending a set; used by
/// load_asset_pack for each of the three tables. Returns the new set.
SpriteSet load_sprite_set(AssetPack& pack, const std::string& dir, std::vector<std::string>* warnings);

}  // namespace kage
