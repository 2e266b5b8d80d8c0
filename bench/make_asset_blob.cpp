// kage_asset_blob: decodes the project's assets (every background of a directory, every skin of a sprite
// parent directory for the agent, world NPCs and sticky NPCs) into an asset blob for the GPU benchmark.
// Usage: kage_asset_blob BACKGROUND_DIR SPRITE_PARENT_DIR OUT.bin
#include <cstdio>

#include "bench/asset_blob.h"
#include "runtime/host/asset_pack.h"
#include "runtime/host/asset_scan.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s BACKGROUND_DIR SPRITE_PARENT_DIR OUT.bin\n", argv[0]);
    return 2;
  }
  const auto bgs = kage::scan_background_dir(argv[1]);
  const auto skins = kage::scan_skin_parent(argv[2]);
  if (!bgs || !skins) {
    std::fprintf(stderr, "cannot scan %s or %s\n", argv[1], argv[2]);
    return 1;
  }
  kage::AssetSources src;
  src.backgrounds = *bgs;
  src.agent_skins = *skins;
  src.npc_types = *skins;
  src.sticky_types = *skins;
  const kage::AssetPackResult r = kage::load_asset_pack(src);
  for (const std::string& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (!r.ok()) {
    std::fprintf(stderr, "error: %s\n", r.error.c_str());
    return 1;
  }
  const kage::AssetPack& p = *r.pack;
  kage::bench::AssetBlob b;
  b.bg = p.bg;
  b.bg_count = p.bg_count;
  b.bg_h = p.bg_h;
  b.bg_w = p.bg_w;
  b.sprite_pixels = p.sprite_pixels;
  b.frames = p.frames;
  b.agent_skins = p.agent_skins;
  b.npc_types = p.npc_types;
  b.sticky_types = p.sticky_types;
  std::string error;
  if (!kage::bench::write_asset_blob(argv[3], b, &error)) {
    std::fprintf(stderr, "error: %s\n", error.c_str());
    return 1;
  }
  std::printf("%s: %d backgrounds %dx%d, %zu frames, %zu skins\n", argv[3], b.bg_count, b.bg_w, b.bg_h,
              b.frames.size(), b.agent_skins.size());
  return 0;
}
