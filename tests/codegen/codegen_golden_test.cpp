// Codegen goldens and properties: the committed simplest.expected.cu, byte-identical reruns, and a
// latent section that depends on the latent parameters only.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <optional>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "compiler/codegen/codegen.h"
#include "compiler/lower/lower.h"
#include "compiler/sema/resolve.h"
#include "verify/isolation/isolation.h"

namespace {

const std::string kRoot = std::string(KAGE_SOURCE_DIR) + "/";

std::optional<kage::Spec> spec_of(const std::string& rel) {
  kage::SourceManager sources;
  kage::DiagEngine diags(sources);
  kage::DiskFileReader reader;
  return kage::analyze_file(kRoot + rel, kage::ResolveOptions{}, sources, reader, diags);
}

struct Lowered {
  std::string hash;
  kage::LoweredConfig config;
};

/// Front end + lowering of a config under the source tree (asset paths as `kagec compile` run from the root).
Lowered lower_file(const std::string& rel) {
  kage::SourceManager sources;
  kage::DiagEngine diags(sources);
  kage::DiskFileReader reader;
  kage::ResolveOptions options;
  const auto spec = kage::analyze_file(kRoot + rel, options, sources, reader, diags);
  INFO(rel);
  REQUIRE(spec.has_value());
  REQUIRE(!diags.has_errors());
  kage::LowerResult lowered = kage::lower_spec(*spec);
  INFO(lowered.error_text());
  REQUIRE(lowered.ok());
  return {spec->sha256(), *lowered.config};
}

kage::GeneratedSource generate_file(const std::string& rel) {
  const Lowered l = lower_file(rel);
  return kage::generate_source({l.hash, l.config.latent, l.config.visual});
}

std::string read(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

/// One member's line of a generated parameter initialiser, split into its literal and its note.
struct Named {
  std::string value;  ///< the initialiser as written, without the trailing comma
  std::string note;   ///< the text of the trailing `// ` comment, if any
};

/// The line `.name = value,  // note` of the initialiser that follows `marker` in a generated source.
std::optional<Named> named(const std::string& text, const std::string& marker, const std::string& name) {
  const size_t begin = text.find(marker);
  if (begin == std::string::npos) return std::nullopt;
  const size_t end = text.find("\n    };", begin);
  const std::string key = "\n      ." + name + " = ";
  const size_t at = text.find(key, begin);
  if (at == std::string::npos || at > end) return std::nullopt;
  const size_t from = at + key.size();
  const std::string line = text.substr(from, text.find('\n', from) - from);
  const size_t note_at = line.find(",  // ");
  if (note_at != std::string::npos) return Named{line.substr(0, note_at), line.substr(note_at + 6)};
  if (!line.ends_with(',')) return std::nullopt;
  return Named{line.substr(0, line.size() - 1), ""};
}

}  // namespace

TEST_CASE("the committed golden holds the values of simplest.yaml, by name", "[codegen][golden]") {
  // Written by hand from configs/default.yaml and configs/kage_bench/bases/shape_black.yaml (which
  // simplest.yaml extends), so the golden's lines are checked against the config and not against the
  // generator that wrote them.
  const std::string golden = read(kRoot + "tests/codegen/simplest.expected.cu");
  const auto latent = [&](const std::string& name) {
    INFO("LatentParams::" << name);
    const auto n = named(golden, "LatentParams latent()", name);
    REQUIRE(n);
    return *n;
  };
  const auto visual = [&](const std::string& name) {
    INFO("VisualParams::" << name);
    const auto n = named(golden, "VisualParams visual()", name);
    REQUIRE(n);
    return *n;
  };
  CHECK(latent("screen_h").value == "128");             // H: 128
  CHECK(latent("screen_w").value == "128");             // W: 128
  CHECK(latent("char_width").value == "16");            // character.width: 16
  CHECK(latent("length").value == "2048");              // layout.length: 2048
  CHECK(latent("gravity").value == "0.75f");            // physics.gravity: 0.75
  CHECK(latent("jump_velocity").value == "-7.5f");      // physics.jump_force: -7.5
  CHECK(latent("max_speed_x").value == "1.0f");         // physics.move_speed: 1
  CHECK(latent("episode_length").value == "500");       // episode_length: 500
  CHECK(latent("dist_to_success").value == "490.0f");   // dist_to_success: 490
  // layout.p_change: 0.7, so 1 - 0.7 in double, rounded to float: written exactly in hex, noted in decimal.
  CHECK(std::strtof(latent("layout_t_flat").value.c_str(), nullptr) == 0.3f);
  CHECK(latent("layout_t_flat").note == "0.3");
  CHECK(visual("H").value == "128");
  CHECK(visual("W").value == "128");
  CHECK(visual("bg_mode").value == "BackgroundMode(0)");  // background.mode: "black"
  CHECK(visual("bg_mode").note == "black");
  CHECK(visual("use_sprites").value == "false");          // character.use_sprites: false
  CHECK(visual("use_shape").value == "true");             // character.use_shape: true
  CHECK(visual("shape_color_count").value == "1");        // character.shape_colors: ["teal"]
  CHECK(visual("shape_colors").value == "{{0, 128, 128}}");
  CHECK(visual("shape_types").value == "{ShapeType(0)}");  // character.shape_types: ["circle"]
  CHECK(visual("shape_types").note == "circle");
  CHECK(visual("shape_rotate").value == "false");         // character.shape_rotate: false
  CHECK(visual("npc_enabled").value == "false");          // npc.enabled: false
  CHECK(visual("distractors_enabled").value == "false");  // distractors.enabled: false
}

TEST_CASE("the generated source of simplest.yaml matches its golden", "[codegen][golden]") {
  const kage::GeneratedSource g = generate_file("configs/throughput/simplest.yaml");
  const std::string golden = kRoot + "tests/codegen/simplest.expected.cu";
  const char* update = std::getenv("KAGE_UPDATE_GOLDENS");
  if (update && std::string(update) == "1") {
    std::ofstream(golden, std::ios::binary) << g.text;
    WARN("rewrote " << golden);
  }
  const std::string expected = read(golden);
  if (g.text != expected) {
    std::ofstream(golden + ".actual", std::ios::binary) << g.text;
    FAIL("generated source differs from " << golden << "; see " << golden
                                          << ".actual (KAGE_UPDATE_GOLDENS=1 ctest rewrites the golden)");
  }
  // Thin and self-describing: no absolute paths, the hashes in the header, the instantiations present.
  CHECK(g.text.find(KAGE_SOURCE_DIR) == std::string::npos);
  CHECK(g.text.find("// spec: sha256:" + g.file_name.substr(5, 16)) != std::string::npos);
  CHECK(g.text.find("KAGE_INSTANTIATE_KERNELS(kage::generated::" + g.config_name + ")") != std::string::npos);
  CHECK(g.text.find("KAGE_INSTANTIATE_HOST(kage::generated::" + g.config_name + ")") != std::string::npos);
  CHECK(g.text.find(g.latent_section) != std::string::npos);
}

TEST_CASE("codegen is deterministic", "[codegen]") {
  for (const char* rel : {"configs/throughput/simplest.yaml", "configs/throughput/hardest.yaml"}) {
    const kage::GeneratedSource a = generate_file(rel);
    const kage::GeneratedSource b = generate_file(rel);
    INFO(rel);
    CHECK(a.text == b.text);
    CHECK(a.latent_hash == b.latent_hash);
    CHECK(a.text.size() > 2000);
  }
}

TEST_CASE("the latent section depends only on the latent parameters", "[codegen][isolation]") {
  Lowered base = lower_file("configs/throughput/simplest.yaml");
  const std::string section = kage::generate_latent_section(base.config.latent);
  // Any visual change leaves it byte-identical; a latent change does not.
  kage::VisualParams v = base.config.visual;
  v.brightness = 0.25f;
  v.bg_mode = kage::BackgroundMode::kNoise;
  const kage::GeneratedSource a = kage::generate_source({base.hash, base.config.latent, base.config.visual});
  const kage::GeneratedSource b = kage::generate_source({base.hash, base.config.latent, v});
  CHECK(a.latent_section == section);
  CHECK(b.latent_section == section);
  CHECK(a.text != b.text);
  kage::LatentParams l = base.config.latent;
  l.gravity *= 2.0f;
  CHECK(kage::generate_latent_section(l) != section);
}

TEST_CASE("float parameters are written so that they read back bit for bit", "[codegen]") {
  kage::LatentParams p{};
  p.gravity = 0.75f;                                         // short exact decimal
  p.jump_velocity = -0.3f;                                   // hex, with its shortest decimal
  p.max_speed_x = -0.0f;                                     // the sign of zero is kept
  p.terminal_velocity = 1e20f;                               // long exact expansion: hex
  p.ground_friction = std::numeric_limits<float>::denorm_min();
  p.air_resistance = std::numeric_limits<float>::infinity();  // spelled by its bits
  const std::string section = kage::generate_latent_section(p);
  const auto value = [&](const std::string& name) {
    const auto n = named(section, "LatentParams latent()", name);
    REQUIRE(n);
    return *n;
  };
  CHECK(value("gravity").value == "0.75f");
  CHECK(value("jump_velocity").value == "-0x1.333334p-2f");
  CHECK(value("jump_velocity").note == "-0.3");
  CHECK(value("max_speed_x").value == "-0.0f");
  for (const char* name : {"terminal_velocity", "ground_friction"}) {
    INFO(name);
    CHECK(value(name).value.starts_with("0x1"));
  }
  CHECK(std::strtof(value("terminal_velocity").value.c_str(), nullptr) == 1e20f);
  CHECK(std::strtof(value("ground_friction").value.c_str(), nullptr) == std::numeric_limits<float>::denorm_min());
  CHECK(value("air_resistance").value == "__builtin_bit_cast(float, 0x7f800000u)");
  CHECK(value("air_resistance").note == "inf");
}

TEST_CASE("param words round-trip the lowered structs", "[codegen]") {
  const Lowered l = lower_file("configs/throughput/hardest.yaml");
  const std::vector<uint32_t> w = kage::param_words(l.config.latent);
  REQUIRE(w.size() * 4 == sizeof(kage::LatentParams));
  kage::LatentParams back{};
  std::memcpy(&back, w.data(), sizeof back);
  CHECK(back.gravity == l.config.latent.gravity);
  CHECK(back.length == l.config.latent.length);
  CHECK(back.dist_to_success == l.config.latent.dist_to_success);
}

TEST_CASE("param words keep every byte of the colour lists", "[codegen]") {
  // Regression: GCC 12's __builtin_clear_padding zeroed bytes of bg_colors[2] in VisualParams.
  kage::VisualParams v = kage::identity_visual_params(64, 64);
  for (int i = 0; i < kage::kMaxListEntries; ++i) v.bg_colors[i] = kage::Rgb{uint8_t(200 + i), uint8_t(10 + i), uint8_t(60 + i)};
  const std::vector<uint32_t> w = kage::param_words(v);
  kage::VisualParams back{};
  std::memcpy(&back, w.data(), sizeof back);
  for (int i = 0; i < kage::kMaxListEntries; ++i) {
    INFO(i);
    CHECK(back.bg_colors[i].r == v.bg_colors[i].r);
    CHECK(back.bg_colors[i].g == v.bg_colors[i].g);
    CHECK(back.bg_colors[i].b == v.bg_colors[i].b);
  }
}

TEST_CASE("isolation evidence holds for a visual pair and fails for a latent change", "[codegen][isolation]") {
  const auto simplest = spec_of("configs/throughput/simplest.yaml");
  const auto hardest = spec_of("configs/throughput/hardest.yaml");
  const auto variant = spec_of("configs/golden/variant.yaml");
  REQUIRE(simplest);
  REQUIRE(hardest);
  REQUIRE(variant);
  kage::IsolationOptions options;
  options.steps = 60;
  // simplest -> hardest changes every visual axis and nothing latent.
  const kage::IsolationEvidence visual = kage::dynamic_isolation(*simplest, *hardest, kage::config_schema(), options);
  INFO(visual.to_json(options).dump());
  CHECK(visual.ok());
  CHECK(visual.dynamics_source_identical);
  CHECK(visual.trajectories_identical);
  CHECK(visual.mean_abs_pixel_diff > 1.0);
  // The golden variant changes physics: every dynamic check must notice.
  const kage::IsolationEvidence latent = kage::dynamic_isolation(*simplest, *variant, kage::config_schema(), options);
  CHECK_FALSE(latent.ok());
  CHECK_FALSE(latent.latent_spec_equal);
  CHECK_FALSE(latent.dynamics_source_identical);
  CHECK(latent.first_divergent_step >= 0);
  // The same config on both sides: identical frames are reported as a failure.
  const kage::IsolationEvidence same = kage::dynamic_isolation(*simplest, *simplest, kage::config_schema(), options);
  CHECK_FALSE(same.frames_differ);
  CHECK_FALSE(same.ok());
}
