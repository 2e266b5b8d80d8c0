// The asset pack blob of a compiled config dir (assets.bin): the loaded background stack and sprite
// sets, so a compiled config runs without the original image files. Versioned; numbers are written
// in the writing machine's byte order (memcpy), so the blob is read back on machines of that order.
#pragma once

#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/io/asset_pack.h"

namespace kage {

inline constexpr char kAssetBlobMagic[8] = {'K', 'A', 'G', 'E', 'A', 'S', 'T', '1'};

namespace asset_blob_detail {

inline void put_i32(std::string& out, int32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }

template <class T>
void put_vec(std::string& out, const std::vector<T>& v) {
  static_assert(__is_trivially_copyable(T));
  put_i32(out, static_cast<int32_t>(v.size()));
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

struct Reader {
  std::string_view in;
  size_t at = 0;
  bool ok = true;
  int32_t i32() {
    int32_t v = 0;
    if (at + 4 > in.size()) return ok = false, 0;
    std::memcpy(&v, in.data() + at, 4);
    at += 4;
    return v;
  }
  template <class T>
  std::vector<T> vec() {
    const int32_t n = i32();
    if (!ok || n < 0 || at + static_cast<size_t>(n) * sizeof(T) > in.size()) return ok = false, std::vector<T>{};
    std::vector<T> v(static_cast<size_t>(n));
    if (n > 0) std::memcpy(v.data(), in.data() + at, v.size() * sizeof(T));
    at += v.size() * sizeof(T);
    return v;
  }
};

}  // namespace asset_blob_detail

/// The blob of `pack` (frame source paths are not kept).
inline std::string serialize_asset_pack(const AssetPack& pack) {
  using namespace asset_blob_detail;
  std::string out(kAssetBlobMagic, sizeof kAssetBlobMagic);
  put_i32(out, pack.bg_count);
  put_i32(out, pack.bg_h);
  put_i32(out, pack.bg_w);
  put_vec(out, pack.bg);
  put_vec(out, pack.sprite_pixels);
  put_vec(out, pack.frames);
  put_vec(out, pack.agent_skins);
  put_vec(out, pack.npc_types);
  put_vec(out, pack.sticky_types);
  return out;
}

/// Reads a blob back; nothing if it is not one (or is truncated).
inline std::optional<AssetPack> deserialize_asset_pack(std::string_view blob) {
  using namespace asset_blob_detail;
  if (blob.size() < sizeof kAssetBlobMagic || std::memcmp(blob.data(), kAssetBlobMagic, sizeof kAssetBlobMagic) != 0)
    return std::nullopt;
  Reader r{blob, sizeof kAssetBlobMagic};
  AssetPack p;
  p.bg_count = r.i32();
  p.bg_h = r.i32();
  p.bg_w = r.i32();
  p.bg = r.vec<uint8_t>();
  p.sprite_pixels = r.vec<uint8_t>();
  p.frames = r.vec<SpriteFrame>();
  p.agent_skins = r.vec<SpriteSet>();
  p.npc_types = r.vec<SpriteSet>();
  p.sticky_types = r.vec<SpriteSet>();
  p.frame_paths.assign(p.frames.size(), std::string());
  if (!r.ok || r.at != blob.size()) return std::nullopt;
  return p;
}

}  // namespace kage
