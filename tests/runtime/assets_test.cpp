// Tests for asset discovery and loading (spec 2.4, 3.5): the original's shipped
// assets, the project's own pack under assets/, and the error/warning paths.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "runtime/io/asset_pack.h"
#include "fileio/asset_scan.h"
#include "fileio/image_io.h"
#include "tests/skip.h"

namespace {

namespace fs = std::filesystem;

const std::string kSource = KAGE_SOURCE_DIR;
const std::string kOriginal = kSource + "/../shared/kage-assets";
const std::string kOurs = kSource + "/assets";

const char* const kSkinNames[] = {
    "boy", "chibi", "clown", "cowboy", "cowboy_2", "dark_knight", "dark_knight_2", "dark_skeleton", "dog",
    "elder_skeleton", "elf", "enchanter", "farmer", "girl", "girl_2", "girl_3", "knight", "man", "robot",
    "scientist", "skeleton", "spy", "thief", "warrior", "woman", "woman_2", "woman_wizard"};

std::string fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "kage_assets_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

kage::Image solid(int w, int h, int channels, uint8_t v) {
  return kage::Image{w, h, channels, std::vector<uint8_t>(size_t(w) * h * channels, v)};
}

bool contains(const std::vector<std::string>& list, const std::string& needle) {
  return std::any_of(list.begin(), list.end(), [&](const std::string& s) { return s.find(needle) != std::string::npos; });
}

kage::AssetPackResult load_all(const std::string& root) {
  kage::AssetSources src;
  src.backgrounds = *kage::scan_background_dir(root + "/backgrounds");
  src.agent_skins = *kage::scan_skin_parent(root + "/sprites");
  src.npc_types = {root + "/sprites/dog"};
  src.sticky_types = {root + "/sprites/robot", root + "/sprites/spy"};
  src.height = 128;
  return kage::load_asset_pack(src);
}

}  // namespace

TEST_CASE("the original's shipped assets reproduce spec 3.5", "[assets]") {
  if (!fs::is_directory(kOriginal)) KAGE_SKIP("the original's assets are not at " << kOriginal);
  const auto bgs = kage::scan_background_dir(kOriginal + "/backgrounds");
  REQUIRE(bgs);
  REQUIRE(bgs->size() == 128);
  CHECK(fs::path((*bgs)[0]).filename() == "bg-1.jpeg");
  CHECK(fs::path((*bgs)[1]).filename() == "bg-10.jpeg");
  CHECK(fs::path((*bgs)[2]).filename() == "bg-100.jpeg");
  CHECK(fs::path((*bgs)[127]).filename() == "bg-99.jpeg");

  const kage::AssetPackResult r = load_all(kOriginal);
  REQUIRE(r.ok());
  CHECK(r.warnings.empty());
  const kage::AssetView v = r.pack->view();
  CHECK(v.bg_count == 128);
  CHECK(v.bg_w == 128);
  CHECK(v.bg_h == 128);
  REQUIRE(v.agent_skins.count == 27);
  CHECK(v.agent_skins.max_frames == 3);

  // Spec 3.5 table, frames in sorted file order: "WxH" per frame.
  const std::vector<std::vector<std::string>> kTable = {
      {"16x24", "16x24"}, {"16x23", "16x24"}, {"16x24", "16x24"}, {"16x24", "16x24"}, {"14x24", "16x24"},
      {"16x24", "16x24", "16x24"}, {"16x24", "16x24"}, {"16x24", "16x24", "16x24"}, {"14x15", "16x24"},
      {"15x24", "16x24", "16x24"}, {"15x24", "16x23"}, {"11x24", "15x24"}, {"16x24", "16x24"},
      {"16x24", "16x24"}, {"16x24", "16x24", "16x24"}, {"10x23", "13x24"}, {"12x24", "14x23"},
      {"14x24", "16x24"}, {"16x24", "16x24"}, {"14x24", "16x24"}, {"16x24", "16x24"}, {"10x23", "16x22"},
      {"14x23", "16x24"}, {"16x24", "16x24"}, {"10x24", "15x23"}, {"12x24", "16x24", "16x24"},
      {"14x24", "16x24"}};
  int total = 0;
  for (int s = 0; s < 27; ++s) {
    INFO("skin " << kSkinNames[s]);
    const kage::SpriteSet& set = kage::sprite_set_at(v.agent_skins, s);
    REQUIRE(set.frame_count == int(kTable[s].size()));
    for (int f = 0; f < set.frame_count; ++f) {
      const kage::SpriteFrame& fr = kage::sprite_frame_at(v, set, f);
      CHECK(std::to_string(fr.width) + "x" + std::to_string(fr.height) == kTable[s][f]);
    }
    CHECK(fs::path(r.pack->frame_paths[set.first_frame]).parent_path().filename() == kSkinNames[s]);
    total += set.frame_count;
  }
  CHECK(total == 59);
  // The NPC tables share the frame buffer: dog's first frame is 14x15.
  REQUIRE(v.npc_types.count == 1);
  const kage::SpriteFrame& dog = kage::sprite_frame_at(v, kage::sprite_set_at(v.npc_types, 0), 0);
  CHECK(dog.width == 14);
  CHECK(dog.height == 15);
  CHECK(v.sticky_types.count == 2);
  CHECK(kage::sprite_set_at(v.sticky_types, 99).first_frame == kage::sprite_set_at(v.sticky_types, 1).first_frame);
}

TEST_CASE("our asset pack is complete and our own", "[assets]") {
  const auto bgs = kage::scan_background_dir(kOurs + "/backgrounds");
  REQUIRE(bgs);
  REQUIRE(bgs->size() == 128);
  const auto skins = kage::scan_skin_parent(kOurs + "/sprites");
  REQUIRE(skins);
  REQUIRE(skins->size() == 27);
  for (size_t i = 0; i < 27; ++i) CHECK(fs::path((*skins)[i]).filename() == kSkinNames[i]);
  CHECK(fs::exists(kOurs + "/LICENSE"));
  CHECK(fs::exists(kOurs + "/README.md"));

  const kage::AssetPackResult r = load_all(kOurs);
  REQUIRE(r.ok());
  CHECK(r.warnings.empty());
  const kage::AssetView v = r.pack->view();
  CHECK(v.bg_count == 128);
  CHECK(v.bg_w == 128);
  CHECK(v.bg_h == 128);
  // Backgrounds differ from each other.
  std::set<std::vector<uint8_t>> distinct;
  const size_t bg_bytes = size_t(v.bg_w) * v.bg_h * 3;
  for (int i = 0; i < v.bg_count; ++i) distinct.emplace(v.bg + i * bg_bytes, v.bg + (i + 1) * bg_bytes);
  CHECK(distinct.size() == 128);

  int three = 0, narrow = 0, semi = 0;
  for (int s = 0; s < v.agent_skins.count; ++s) {
    INFO("skin " << kSkinNames[s]);
    const kage::SpriteSet& set = v.agent_skins.sets[s];
    CHECK(set.frame_count >= 2);
    CHECK(set.frame_count <= 3);
    three += set.frame_count == 3;
    for (int f = 0; f < set.frame_count; ++f) {
      const kage::SpriteFrame& fr = v.frames[set.first_frame + f];
      CHECK(fr.width <= 16);
      CHECK(fr.height <= 24);
      narrow += fr.width < 16;
      int opaque = 0, clear = 0;
      for (int p = 0; p < fr.width * fr.height; ++p) {
        const uint8_t a = v.sprite_pixels[fr.offset + p * 4 + 3];
        opaque += a == 255;
        clear += a == 0;
        semi += a != 0 && a != 255;
      }
      CHECK(opaque > 20);
      CHECK(clear > 20);
    }
  }
  CHECK(three >= 3);
  CHECK(narrow >= 3);
  CHECK(semi > 0);

  if (!fs::is_directory(kOriginal)) KAGE_SKIP("byte comparison: the original's assets are not at " << kOriginal);
  std::set<std::string> theirs;
  for (const auto& e : fs::recursive_directory_iterator(kOriginal)) {
    if (e.is_regular_file()) theirs.insert(read_bytes(e.path().string()));
  }
  REQUIRE(theirs.size() > 100);
  int compared = 0;
  for (const auto& e : fs::recursive_directory_iterator(kOurs)) {
    if (!e.is_regular_file()) continue;
    INFO(e.path().string());
    CHECK(theirs.count(read_bytes(e.path().string())) == 0);
    ++compared;
  }
  CHECK(compared > 180);
}

TEST_CASE("background scan: patterns, case, order, non-recursive", "[assets]") {
  const std::string dir = fresh_dir("scan_bg");
  for (const char* name : {"b.png", "a.jpg", "c.jpeg", "A.bmp", "x.JPG", "notes.txt", "bg-10.jpeg", "bg-2.jpeg"}) {
    write_bytes(dir + "/" + name, "x");
  }
  fs::create_directories(dir + "/sub");
  write_bytes(dir + "/sub/z.jpg", "x");
  const auto got = kage::scan_background_dir(dir + "/");
  REQUIRE(got);
  std::vector<std::string> names;
  for (const std::string& p : *got) {
    CHECK(p.rfind(dir + "/", 0) == 0);
    names.push_back(fs::path(p).filename().string());
  }
  CHECK(names == std::vector<std::string>{"A.bmp", "a.jpg", "b.png", "bg-10.jpeg", "bg-2.jpeg", "c.jpeg"});
  CHECK_FALSE(kage::scan_background_dir(dir + "/missing"));
  CHECK(kage::scan_background_dir(dir + "/sub")->size() == 1);
}

TEST_CASE("skin scans: sorted subdirectories, recursive PNGs", "[assets]") {
  const std::string dir = fresh_dir("scan_skins");
  fs::create_directories(dir + "/b_skin/deeper");
  fs::create_directories(dir + "/a_skin");
  write_bytes(dir + "/loose.png", "x");
  write_bytes(dir + "/b_skin/2.png", "x");
  write_bytes(dir + "/b_skin/deeper/1.png", "x");
  write_bytes(dir + "/b_skin/3.PNG", "x");
  const auto parents = kage::scan_skin_parent(dir);
  REQUIRE(parents);
  CHECK(*parents == std::vector<std::string>{dir + "/a_skin", dir + "/b_skin"});
  CHECK_FALSE(kage::scan_skin_parent(dir + "/nope"));
  CHECK(kage::scan_skin_frames(dir + "/b_skin") ==
        std::vector<std::string>{dir + "/b_skin/2.png", dir + "/b_skin/deeper/1.png"});
  CHECK(kage::scan_skin_frames(dir + "/a_skin").empty());
}

TEST_CASE("sprite errors become warnings and dummy frames", "[assets]") {
  const std::string dir = fresh_dir("bad_skins");
  fs::create_directories(dir + "/empty");
  fs::create_directories(dir + "/broken");
  fs::create_directories(dir + "/mixed");
  write_bytes(dir + "/broken/broken-1.png", "\x89PNG\r\n\x1a\ngarbage garbage garbage IEND....");
  write_bytes(dir + "/mixed/mixed-1.png", "garbage");
  REQUIRE(kage::write_png(dir + "/mixed/mixed-2.png", solid(5, 7, 4, 200)).ok());

  kage::AssetSources src;
  src.agent_skins = {dir + "/empty", dir + "/missing", dir + "/broken", dir + "/mixed"};
  const kage::AssetPackResult r = kage::load_asset_pack(src);
  REQUIRE(r.ok());
  const kage::AssetView v = r.pack->view();
  CHECK(v.bg_count == 0);
  CHECK(v.bg == nullptr);
  REQUIRE(v.agent_skins.count == 4);
  for (int s = 0; s < 3; ++s) {
    const kage::SpriteSet& set = v.agent_skins.sets[s];
    REQUIRE(set.frame_count == 1);
    const kage::SpriteFrame& fr = v.frames[set.first_frame];
    CHECK(fr.width == 16);
    CHECK(fr.height == 16);
    for (int p = 0; p < 16 * 16 * 4; ++p) REQUIRE(v.sprite_pixels[fr.offset + p] == 0);
  }
  const kage::SpriteFrame& ok = v.frames[v.agent_skins.sets[3].first_frame];
  CHECK(v.agent_skins.sets[3].frame_count == 1);
  CHECK(ok.width == 5);
  CHECK(ok.height == 7);
  CHECK(v.sprite_pixels[ok.offset + 3] == 200);
  CHECK(v.npc_types.count == 0);
  CHECK(v.npc_types.sets == nullptr);

  CHECK(contains(r.warnings, dir + "/empty: no *.png files"));
  CHECK(contains(r.warnings, dir + "/missing: directory does not exist"));
  CHECK(contains(r.warnings, dir + "/broken/broken-1.png: corrupt PNG"));
  CHECK(contains(r.warnings, dir + "/broken: no loadable *.png files"));
  CHECK(contains(r.warnings, dir + "/mixed/mixed-1.png: unsupported"));
  CHECK(r.warnings.size() == 5);
}

TEST_CASE("background errors name the file; sizes follow the first image", "[assets]") {
  const std::string dir = fresh_dir("bgs");
  REQUIRE(kage::write_png(dir + "/wide.png", solid(100, 50, 3, 40)).ok());
  REQUIRE(kage::write_png(dir + "/square.png", solid(30, 30, 3, 90)).ok());
  REQUIRE(kage::write_jpeg(dir + "/photo.jpeg", solid(64, 64, 3, 120), 90).ok());
  write_bytes(dir + "/cut.jpeg", read_bytes(dir + "/photo.jpeg").substr(0, 200));

  kage::AssetSources src;
  src.height = 64;
  src.backgrounds = {dir + "/wide.png", dir + "/square.png"};
  kage::AssetPackResult r = kage::load_asset_pack(src);
  REQUIRE(r.ok());
  kage::AssetView v = r.pack->view();
  CHECK(v.bg_count == 2);
  CHECK(v.bg_h == 64);
  CHECK(v.bg_w == 128);  // int(64 * 100 / 50)
  REQUIRE(r.pack->bg.size() == 2u * 64 * 128 * 3);
  CHECK(int(v.bg[0]) == 40);
  CHECK(int(v.bg[64 * 128 * 3 + 500]) == 90);

  src.height = 33;  // int(33 * 2.0) = 66; odd target sizes
  src.backgrounds = {dir + "/wide.png"};
  r = kage::load_asset_pack(src);
  REQUIRE(r.ok());
  CHECK(r.pack->bg_w == 66);

  src.backgrounds = {dir + "/wide.png", dir + "/gone.jpeg"};
  r = kage::load_asset_pack(src);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error.rfind(dir + "/gone.jpeg: no such file", 0) == 0);

  src.backgrounds = {dir + "/cut.jpeg"};
  r = kage::load_asset_pack(src);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error.rfind(dir + "/cut.jpeg: corrupt JPEG", 0) == 0);
}
