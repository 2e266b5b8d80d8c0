// The kagec commands built on the environment: golden check over ../shared/golden, render outputs.
#include <catch2/catch.hpp>

#include <filesystem>
#include <sstream>

#include "driver/commands.h"
#include "fileio/image_io.h"
#include "tests/integration/integration_support.h"

namespace {

using kage::test::kRoot;

int kagec(const std::vector<std::string>& args, std::string& out, std::string& err) {
  std::ostringstream o, e;
  kage::CommandIo io{o, e};
  const int code = kage::run_kagec(args, io);
  out = o.str();
  err = e.str();
  return code;
}

}  // namespace

TEST_CASE("kagec golden check passes on every recorded golden", "[integration][golden]") {
  std::string out, err;
  const int code = kagec({"golden", "check", kRoot + "/../shared/golden", "--configs", kRoot + "/configs/golden",
                          "--compat", kRoot + "/tests/compat/original", "--shared", kRoot + "/../shared"},
                         out, err);
  INFO(out << err);
  CHECK(code == kage::kExitOk);
  CHECK(out.find("FAIL") == std::string::npos);
  // Every kind of golden was compared: physics fields, render frames, filters and effects.
  for (const char* what : {"physics_default.json x", "physics_variant.json reward", "render_sprite_image/seed0_t499.png",
                           "render_line_black/seed0_t10.png", "filters/preset_noir.png", "effects/config2_seed1_lit.png"})
    CHECK(out.find(std::string("PASS  ") + what) != std::string::npos);
}

TEST_CASE("kagec golden check fails on a folder without goldens", "[integration][golden]") {
  std::string out, err;
  CHECK(kagec({"golden", "check", kRoot + "/configs/golden"}, out, err) == kage::kExitErrors);
  CHECK(out.find("FAIL") != std::string::npos);
}

TEST_CASE("kagec render writes frames, a GIF and a contact sheet", "[integration][render]") {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "kage-integration-render";
  std::filesystem::remove_all(dir);
  std::string out, err;
  const int code = kagec({"render", kRoot + "/configs/golden/default.yaml", "--seed", "2", "--steps", "20", "--every",
                          "5", "--gif", (dir / "run.gif").string(), "--sheet", (dir / "sheet.png").string(), "-o",
                          (dir / "frames").string()},
                         out, err);
  INFO(err);
  REQUIRE(code == kage::kExitOk);
  for (int t : {0, 5, 10, 15, 20}) CHECK(std::filesystem::exists(dir / "frames" / ("frame_" + std::to_string(t) + ".png")));
  CHECK_FALSE(std::filesystem::exists(dir / "frames" / "frame_3.png"));
  CHECK(std::filesystem::file_size(dir / "run.gif") > 100);
  kage::ImageResult sheet = kage::load_image((dir / "sheet.png").string(), 3);
  REQUIRE(sheet.ok());
  CHECK(sheet.image->width > 5 * 128);
  kage::ImageResult f0 = kage::load_image((dir / "frames" / "frame_0.png").string(), 3);
  REQUIRE(f0.ok());
  CHECK(f0.image->width == 128);
  std::filesystem::remove_all(dir);
}

TEST_CASE("render and bench refuse what cannot fit, and report writes that fail", "[integration][render][hostile]") {
  const std::string config = kRoot + "/configs/throughput/simplest.yaml";
  std::string out, err;
  CHECK(kagec({"render", config, "--steps", "100000000", "--sheet", "/tmp/never.png"}, out, err) == 2);
  CHECK(err.find("a contact sheet holds at most 1024 frames") != std::string::npos);
  // 2e9 frames of 48 KiB: more than any disk here; refused before the first step.
  CHECK(kagec({"render", config, "--steps", "2000000000", "--every", "1", "-o", "/tmp/kage_never_frames"}, out, err) == 1);
  CHECK(err.find("would take up to") != std::string::npos);
  CHECK(err.find("add --force") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists("/tmp/kage_never_frames"));
  CHECK(kagec({"render", config, "--steps", "20", "--gif", "/dev/full"}, out, err) == 1);
  CHECK(err.find("kagec render: /dev/full: write failed") != std::string::npos);
  CHECK(kagec({"render", config, "--steps", "20", "--sheet", "/dev/full"}, out, err) == 1);
  CHECK(err.find("kagec render: /dev/full: write failed") != std::string::npos);
  CHECK(kagec({"bench", config, "--cpu", "--envs", "100000000", "--steps", "1"}, out, err) == 1);
  CHECK(err.find("cannot build 100000000 environments of 128x128 observations on ") != std::string::npos);
  CHECK(err.find(" threads: they need 9") != std::string::npos);
  CHECK(err.find("use fewer environments or smaller observations") != std::string::npos);
}
