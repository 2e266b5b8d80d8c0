// Asset blob reading and writing (format in asset_blob.h).
#include "bench/asset_blob.h"

#include <cstring>
#include <fstream>

namespace kage::bench {
namespace {

constexpr char kMagic[] = "KAGEASSETS1\n";
constexpr size_t kMagicLen = sizeof(kMagic) - 1;

SpriteSetTable table(const std::vector<SpriteSet>& sets) {
  int32_t max_frames = 0;
  for (const SpriteSet& s : sets) max_frames = s.frame_count > max_frames ? s.frame_count : max_frames;
  return SpriteSetTable{sets.empty() ? nullptr : sets.data(), static_cast<int32_t>(sets.size()), max_frames};
}

template <class T>
bool read_vec(std::ifstream& in, std::vector<T>& v, int64_t count) {
  if (count < 0) return false;
  v.resize(static_cast<size_t>(count));
  in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
  return static_cast<bool>(in);
}

template <class T>
void write_vec(std::ofstream& out, const std::vector<T>& v) {
  out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
}

}  // namespace

AssetView AssetBlob::view() const {
  AssetView v{};
  v.bg = bg.empty() ? nullptr : bg.data();
  v.bg_count = bg_count;
  v.bg_h = bg_h;
  v.bg_w = bg_w;
  v.sprite_pixels = sprite_pixels.empty() ? nullptr : sprite_pixels.data();
  v.frames = frames.empty() ? nullptr : frames.data();
  v.agent_skins = table(agent_skins);
  v.npc_types = table(npc_types);
  v.sticky_types = table(sticky_types);
  return v;
}

bool write_asset_blob(const std::string& path, const AssetBlob& b, std::string* error) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  const int32_t counts[8] = {b.bg_count,
                             b.bg_h,
                             b.bg_w,
                             static_cast<int32_t>(b.frames.size()),
                             static_cast<int32_t>(b.sprite_pixels.size()),
                             static_cast<int32_t>(b.agent_skins.size()),
                             static_cast<int32_t>(b.npc_types.size()),
                             static_cast<int32_t>(b.sticky_types.size())};
  out.write(kMagic, kMagicLen);
  out.write(reinterpret_cast<const char*>(counts), sizeof counts);
  write_vec(out, b.bg);
  write_vec(out, b.sprite_pixels);
  write_vec(out, b.frames);
  write_vec(out, b.agent_skins);
  write_vec(out, b.npc_types);
  write_vec(out, b.sticky_types);
  if (!out) *error = path + ": cannot write";
  return static_cast<bool>(out);
}

std::optional<AssetBlob> read_asset_blob(const std::string& path, std::string* error) {
  std::ifstream in(path, std::ios::binary);
  char magic[kMagicLen];
  int32_t c[8];
  in.read(magic, kMagicLen);
  in.read(reinterpret_cast<char*>(c), sizeof c);
  if (!in || std::memcmp(magic, kMagic, kMagicLen) != 0) {
    *error = path + ": not an asset blob";
    return std::nullopt;
  }
  AssetBlob b;
  b.bg_count = c[0];
  b.bg_h = c[1];
  b.bg_w = c[2];
  const bool ok = read_vec(in, b.bg, int64_t{c[0]} * c[1] * c[2] * 3) && read_vec(in, b.sprite_pixels, c[4]) &&
                  read_vec(in, b.frames, c[3]) && read_vec(in, b.agent_skins, c[5]) &&
                  read_vec(in, b.npc_types, c[6]) && read_vec(in, b.sticky_types, c[7]);
  if (!ok) {
    *error = path + ": truncated asset blob";
    return std::nullopt;
  }
  return b;
}

}  // namespace kage::bench
