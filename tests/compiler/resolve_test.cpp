// Resolve: equivalent files give identical canonical Specs, the original
// loader's absent-key rules, aliases, inert marks, the canonical fixpoint and
// a committed golden.
#include <catch2/catch.hpp>
#include <cstdlib>

#include "compiler/sema/assets.h"
#include "test_support.h"

namespace kage::test {
namespace {

// Resolves in-memory files; fails the test on any error.
Spec resolve_memory(MemoryFileReader& reader, const std::string& path, size_t* warnings = nullptr) {
  Analysis a;
  analyze(a, path, reader);
  INFO(a.dump());
  REQUIRE(a.spec);
  REQUIRE_FALSE(a.diags.has_errors());
  if (warnings) *warnings = a.diags.warning_count();
  return *a.spec;
}

Spec resolve_text(const std::string& text, size_t* warnings = nullptr) {
  MemoryFileReader reader;
  reader.files["cfg/a.yaml"] = text;
  return resolve_memory(reader, "cfg/a.yaml", warnings);
}

void require_same(const std::string& a, const std::string& b) {
  const Spec sa = resolve_text(a), sb = resolve_text(b);
  CHECK(sa.canonical_text() == sb.canonical_text());
  CHECK(sa.sha256() == sb.sha256());
}

}  // namespace

TEST_CASE("semantically equal files resolve to identical bytes and hashes", "[resolve]") {
  SECTION("reordered keys and sections") {
    require_same("H: 96\nphysics:\n  gravity: 0.6\n  air_accel: 0.3\nfilters: {gamma: 1.5}\n",
                 "filters: {gamma: 1.5}\nphysics:\n  air_accel: 0.3\n  gravity: 0.6\nH: 96\n");
  }
  SECTION("a name or a one-element list for string-or-list keys") {
    require_same("character: {use_shape: true, shape_types: star, shape_colors: teal}\n",
                 "character: {use_shape: true, shape_types: [star], shape_colors: [teal]}\n");
    require_same("layout: {length: 2048, layout_colors: cyan}\n", "layout: {length: 2048, layout_colors: [cyan]}\n");
  }
  SECTION("integer or float for float keys") {
    require_same("physics: {gravity: 1}\neffects: {point_light_falloff: 2}\n",
                 "physics: {gravity: 1.0}\neffects: {point_light_falloff: 2.0}\n");
  }
  SECTION("the dataclass default written out or left absent") {
    require_same("physics: {gravity: 0.5, max_speed_x: 3.0}\n", "physics: {}\n");
  }
  SECTION("an extends chain and the equivalent flat file") {
    MemoryFileReader reader;
    reader.files["base/root.yaml"] = "H: 96\nphysics: {gravity: 0.6, air_accel: 0.3}\nfilters: {gamma: 1.5}\n";
    reader.files["base/mid.yaml"] = "extends: root.yaml\nphysics: {gravity: 0.7}\nbackground: {mode: noise}\n";
    reader.files["leaf/top.yaml"] = "extends: ../base/mid.yaml\nfilters: {contrast: 2.0}\n";
    reader.files["flat.yaml"] =
        "H: 96\nphysics: {gravity: 0.7, air_accel: 0.3}\nfilters: {gamma: 1.5, contrast: 2.0}\n"
        "background: {mode: noise}\n";
    const Spec chained = resolve_memory(reader, "leaf/top.yaml");
    const Spec flat = resolve_memory(reader, "flat.yaml");
    CHECK(chained.canonical_text() == flat.canonical_text());
    CHECK(chained.value("physics.gravity") == 0.7);
    CHECK(chained.value("physics.air_accel") == 0.3);
  }
}

TEST_CASE("configs in different directories naming the same asset resolve identically", "[resolve][assets]") {
  fs::path image;
  for (const auto& e : fs::recursive_directory_iterator(source_dir() / "assets"))
    if (e.is_regular_file() && (e.path().extension() == ".png" || e.path().extension() == ".jpg")) {
      image = e.path();
      break;
    }
  REQUIRE(!image.empty());
  TempDir tmp("same_asset");
  fs::create_directories(tmp.path() / "assets");
  fs::copy_file(image, tmp.path() / "assets" / ("bg" + image.extension().string()));
  const std::string name = "bg" + image.extension().string();
  write_text(tmp.path() / "a/x.yaml", "background: {mode: image, image_path: ../assets/" + name + "}\n");
  write_text(tmp.path() / "b/c/y.yaml", "background:\n  mode: image\n  image_path: ../../assets/./" + name + "\n");
  DiskFileReader reader;
  Analysis a, b;
  analyze(a, (tmp.path() / "a/x.yaml").string(), reader);
  analyze(b, (tmp.path() / "b/c/y.yaml").string(), reader);
  INFO(a.dump() << b.dump());
  REQUIRE(a.spec);
  REQUIRE(b.spec);
  CHECK_FALSE(a.diags.has_errors());
  CHECK(a.spec->canonical_text() == b.spec->canonical_text());
  REQUIRE(a.spec->assets.backgrounds.size() == 1);
  CHECK(a.spec->assets.backgrounds[0].sha256.size() == 64);
  CHECK(a.spec->assets.backgrounds[0].width > 0);
}

TEST_CASE("an asset file or sprite folder whose name is not UTF-8 is an error, not a crash", "[resolve][assets]") {
  TempDir tmp("non_utf8_asset");
  write_text(tmp.path() / "bgs" / "bad\xFF.png", "not read: the name is refused first");
  fs::create_directories(tmp.path() / "skins" / "skin\xFE");
  write_text(tmp.path() / "c.yaml",
             "background: {mode: image, image_dir: bgs}\n"
             "character: {use_shape: false, use_sprites: true, sprite_dir: skins}\n");
  DiskFileReader reader;
  Analysis a;
  analyze(a, (tmp.path() / "c.yaml").string(), reader);
  INFO(a.dump());
  CHECK(a.count("asset-unreadable") == 2);
  for (const Diagnostic& d : a.diags.sorted())
    if (std::string(rule_info(d.rule).id) == "asset-unreadable") CHECK(d.message.find("not valid UTF-8") != std::string::npos);
}

TEST_CASE("absent keys take the dataclass default, not the YAML value", "[resolve]") {
  const Spec s = resolve_text("physics: {gravity: 0.9}\n");
  CHECK(s.value("physics.gravity") == 0.9);
  CHECK(s.value("physics.max_speed_x") == 3.0);     // default_config.yaml says move_speed: 1
  CHECK(s.value("physics.jump_velocity") == -6.0);  // YAML: jump_force -7.5
  CHECK(s.value("physics.terminal_velocity") == 8.0);
  CHECK(s.value("physics.air_resistance") == 0.98);  // YAML: 0.95
  CHECK(s.value("physics.coyote_time") == 3);
  CHECK(s.value("background.mode") == "black");      // YAML: image
  CHECK(s.value("background.color_names") == Json::array({"black"}));
  CHECK(s.value("character.use_sprites") == false);  // YAML: true
  CHECK(s.value("character.animation_fps") == 10.0);  // YAML: 12.0
  CHECK(s.value("character.shape_types") == Json::array({"circle"}));  // a string default becomes a list
  CHECK(s.value("character.fallback_color") == Json::array({255, 0, 0}));
  CHECK(s.value("npc.max_npc_count") == 5);           // YAML: 20
  CHECK(s.value("npc.sticky_x_offsets") == Json::array({-40, 40}));
  CHECK(s.value("npc.sticky_x_min").is_null());
  CHECK(s.value("effects.point_light_intensity") == 3.0);  // YAML: 1.0
  CHECK(s.value("filters.radial_light_color") == Json::array({255, 255, 200}));
  CHECK(s.value("distractors.max_rotation_speed") == 10.0);  // YAML: 0.3
  CHECK(s.value("episode_length") == 500);
  CHECK(s.value("camera.left_margin") == 40);
  // Legacy names never appear in the Spec; 118 names - 3 aliases = 115 values.
  CHECK(s.value("physics.move_speed").is_null());
  size_t leaves = 0;
  for (auto& [k, v] : s.values.items()) leaves += v.is_object() ? v.size() : 1;
  CHECK(leaves == 115);
  // Float keys are floats even when the default is written as an integer.
  CHECK(s.value("physics.gravity").is_number_float());
  CHECK(s.value("physics.max_speed_x").is_number_float());
  CHECK(s.value("H").is_number_integer());
}

TEST_CASE("a whole absent layout section is 16*W long; a partial one 128", "[resolve][layout]") {
  CHECK(resolve_text("H: 96\n").value("layout.length") == 2048);
  CHECK(resolve_text("H: 96\n").value("layout.height_px") == 96);
  CHECK(resolve_text("W: 64\n").value("layout.length") == 1024);
  CHECK(resolve_text("layout:\n").value("layout.length") == 2048);  // a null section is absent
  size_t warnings = 0;
  const Spec partial = resolve_text("W: 64\nH: 96\nlayout: {run_width: 25}\n", &warnings);
  CHECK(partial.value("layout.length") == 128);
  CHECK(partial.value("layout.height_px") == 128);
  CHECK(partial.value("layout.run_width") == 25);
  CHECK(warnings == 2);  // quirk-partial-layout for length (1024 vs 128) and height_px (96 vs 128)
  CHECK(resolve_text("layout: {length: 300}\n").value("layout.length") == 300);
}

TEST_CASE("legacy physics aliases feed their modern key; the modern key wins", "[resolve][alias]") {
  size_t warnings = 0;
  const Spec legacy = resolve_text("physics: {move_speed: 2, jump_force: -7.5, max_fall_speed: 9}\n", &warnings);
  CHECK(warnings == 0);
  CHECK(legacy.value("physics.max_speed_x") == 2.0);
  CHECK(legacy.value("physics.max_speed_x").is_number_float());
  CHECK(legacy.value("physics.jump_velocity") == -7.5);
  CHECK(legacy.value("physics.terminal_velocity") == 9.0);
  CHECK(legacy.canonical_text() ==
        resolve_text("physics: {max_speed_x: 2.0, jump_velocity: -7.5, terminal_velocity: 9.0}\n").canonical_text());

  const Spec both = resolve_text("physics: {move_speed: 2, max_speed_x: 4.5}\n", &warnings);
  CHECK(both.value("physics.max_speed_x") == 4.5);
  CHECK(warnings == 1);  // schema-alias-shadowed
}

TEST_CASE("inert settings are marked in the Spec", "[resolve][inert]") {
  const Spec s = resolve_text("background: {mode: black}\ncharacter: {use_shape: true, use_sprites: false}\n");
  CHECK(s.inert.count("background.parallax_factor"));
  CHECK(s.inert.count("background.image_dir"));
  CHECK(s.inert.count("filters.jpeg_quality"));  // never used
  CHECK(s.inert.count("distractors.min_speed"));
  CHECK(s.inert.count("effects.point_light_intensity"));  // lights off
  CHECK(s.inert.count("filters.brightness"));              // 0 is the identity
  CHECK(s.inert.count("character.shape_rotation_speed"));  // shape_rotate false
  CHECK_FALSE(s.inert.count("character.shape_types"));
  CHECK_FALSE(s.inert.count("physics.gravity"));
  CHECK_FALSE(s.inert.count("layout.length"));
  CHECK_FALSE(s.inert.count("physics.move_speed"));  // legacy names are not in the Spec

  const Spec img = resolve_text("background: {mode: noise}\nfilters: {brightness: 0.5}\n");
  CHECK_FALSE(img.inert.count("filters.brightness"));
  CHECK(img.inert.count("background.parallax_factor"));  // only image mode scrolls
  const Json canonical = Json::parse(s.canonical_text());
  CHECK(canonical.at("inert").is_array());
  CHECK(std::is_sorted(canonical.at("inert").begin(), canonical.at("inert").end()));
}

TEST_CASE("files with errors give no Spec", "[resolve]") {
  MemoryFileReader reader;
  reader.files["bad.yaml"] = "physics: {gravity: fast}\n";
  Analysis a;
  analyze(a, "bad.yaml", reader);
  CHECK_FALSE(a.spec);
  CHECK(a.count("schema-type") == 1);
}

TEST_CASE("canonical JSON -> spec_from_json -> canonical JSON is a fixpoint for every config", "[resolve][fixpoint]") {
  fs::current_path(source_dir());
  DiskFileReader reader;
  size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator("configs")) {
    if (!e.is_regular_file() || e.path().extension() != ".yaml") continue;
    Analysis a;
    analyze(a, e.path().string(), reader);
    INFO(e.path().string() << "\n" << a.dump());
    REQUIRE(a.spec);
    REQUIRE_FALSE(a.diags.has_errors());
    const std::string text = a.spec->canonical_text();
    const auto back = spec_from_json(Json::parse(text));
    REQUIRE(back);
    CHECK(back->canonical_text() == text);
    CHECK(back->sha256() == a.spec->sha256());
    CHECK(Json::parse(text).at("sha256") == a.spec->sha256());
    ++n;
  }
  CHECK(n >= 40);
  CHECK_FALSE(spec_from_json(Json::parse(R"({"kagec_spec": 2, "config": {}})")));
  CHECK_FALSE(spec_from_json(Json::parse(R"({"kagec_spec": 1, "config": {}, "inert": [], "assets": 3})")));
}

TEST_CASE("golden: configs/throughput/simplest.yaml", "[resolve][golden]") {
  fs::current_path(source_dir());  // asset paths print relative to the working directory
  DiskFileReader reader;
  Analysis a;
  analyze(a, "configs/throughput/simplest.yaml", reader);
  INFO(a.dump());
  REQUIRE(a.spec);
  REQUIRE_FALSE(a.diags.has_errors());
  const std::string actual = a.spec->canonical_text();
  const fs::path golden = source_dir() / "tests/resolve/simplest.expected.json";
  const fs::path actual_file = source_dir() / "tests/resolve/simplest.expected.json.actual";
  const char* update = std::getenv("KAGE_UPDATE_GOLDENS");
  if (update && std::string(update) == "1") {
    write_text(golden, actual);
    fs::remove(actual_file);
    SUCCEED("golden rewritten");
    return;
  }
  REQUIRE(fs::exists(golden));
  const std::string expected = read_text(golden);
  if (expected != actual) write_text(actual_file, actual);
  else fs::remove(actual_file);
  CHECK(expected == actual);
}

}  // namespace kage::test
