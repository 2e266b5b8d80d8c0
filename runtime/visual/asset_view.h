// Visual stage inputs: a flat, pointer-only view of the loaded asset pack
// (background stack and sprite sets), the same on host and device.
#pragma once

#include "runtime/kage_hd.h"

namespace kage {

/// One RGBA8 sprite frame inside `AssetView::sprite_pixels`.
/// `offset` is in bytes from the start of the pixel buffer; rows are tightly
/// packed (`width * 4` bytes per row), top row first.
struct SpriteFrame {
  int32_t offset;
  int32_t width;
  int32_t height;
};

/// One skin (or NPC type): frames `first_frame .. first_frame + frame_count - 1`
/// of `AssetView::frames`. `frame_count` is always >= 1 (spec 2.4 step 4 dummy).
struct SpriteSet {
  int32_t first_frame;
  int32_t frame_count;
};

/// A list of sprite sets. `count == 0` means "none loaded" (`sets` may be null).
/// `max_frames` is the largest `frame_count` in the table (0 when empty).
struct SpriteSetTable {
  const SpriteSet* sets;
  int32_t count;
  int32_t max_frames;
};

/// Everything the visual stage reads from assets. Plain pointers and ints only,
/// so it can be copied by value into a kernel argument. Pointers refer to host
/// or device memory depending on who built the view.
struct AssetView {
  /// Background stack, uint8 RGB, layout [bg_count][bg_h][bg_w][3]; null when
  /// bg_count == 0.
  const uint8_t* bg;
  int32_t bg_count;
  int32_t bg_h;
  int32_t bg_w;
  /// All sprite frames, RGBA8, addressed through `frames[k].offset`.
  const uint8_t* sprite_pixels;
  /// Frame table shared by the three set tables below.
  const SpriteFrame* frames;
  SpriteSetTable agent_skins;
  SpriteSetTable npc_types;
  SpriteSetTable sticky_types;
};

/// Sets are chosen with clipping (spec 6.4): `set = sets[clip(i, 0, n - 1)]`.
KAGE_HD const SpriteSet& sprite_set_at(const SpriteSetTable& table, int32_t i) {
  const int32_t last = table.count - 1;
  return table.sets[i < 0 ? 0 : (i > last ? last : i)];
}

/// Frames are chosen with clipping (spec 6.4): `frame = frames[clip(i, 0, len - 1)]`.
KAGE_HD const SpriteFrame& sprite_frame_at(const AssetView& view, const SpriteSet& set,
                                          int32_t i) {
  const int32_t last = set.frame_count - 1;
  return view.frames[set.first_frame + (i < 0 ? 0 : (i > last ? last : i))];
}

}  // namespace kage
