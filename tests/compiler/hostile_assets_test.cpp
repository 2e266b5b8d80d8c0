// Hostile and careless asset paths and image files: special files, huge files, images that claim a
// huge size in a few header bytes, absolute paths, folders that are files. Each ends in a located
// error that says what the path is and how to fix it, read without loading what it need not load.
#include <catch2/catch.hpp>

#include <sys/resource.h>
#include <sys/stat.h>

#include "compiler/basic/diag.h"
#include "test_support.h"

namespace kage::test {
namespace {

/// The text diagnostics of the front end on `config` (a file on disk).
std::string lint_text(const fs::path& config, Analysis& a) {
  DiskFileReader reader;
  analyze(a, config.string(), reader);
  std::ostringstream text;
  print_text(a.diags, text);
  return text.str();
}

/// A PNG of nothing but its signature, an IHDR chunk claiming `w` x `h` RGB pixels, and IEND.
std::string png_header(uint32_t w, uint32_t h) {
  auto be32 = [](uint32_t v) {
    return std::string{char(v >> 24), char((v >> 16) & 255), char((v >> 8) & 255), char(v & 255)};
  };
  std::string png("\x89PNG\r\n\x1a\n", 8);
  png += be32(13) + "IHDR" + be32(w) + be32(h) + std::string("\x08\x02\x00\x00\x00", 5) + be32(0);
  png += be32(0) + "IEND" + be32(0xAE426082u);
  return png;
}

/// The peak resident memory of this process so far, in bytes.
uint64_t peak_rss() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return uint64_t(u.ru_maxrss) * 1024;
}

}  // namespace

TEST_CASE("an image path that is a directory or a special file says what it is", "[hostile][assets]") {
  TempDir tmp("hostile_image_kinds");
  fs::create_directories(tmp.path() / "folder.png");
  REQUIRE(::mkfifo((tmp.path() / "pipe.png").c_str(), 0600) == 0);
  write_text(tmp.path() / "c.yaml",
             "background:\n  mode: image\n  image_paths: [folder.png, pipe.png, /dev/zero]\n");
  Analysis a;
  const std::string text = lint_text(tmp.path() / "c.yaml", a);
  INFO(text);
  CHECK(text.find("c.yaml:3:17: error: asset file '" + (tmp.path() / "folder.png").string() +
                  "' (from 'background.image_paths') is a directory, not an image file; name an image file") !=
        std::string::npos);
  CHECK(text.find("c.yaml:3:29: error: asset file '" + (tmp.path() / "pipe.png").string() +
                  "' (from 'background.image_paths') is not a regular file (a FIFO, device or socket); name an image "
                  "file") != std::string::npos);
  CHECK(text.find("'/dev/zero' (from 'background.image_paths') is not a regular file") != std::string::npos);
  CHECK(text.find("does not exist") == std::string::npos);
}

TEST_CASE("an asset folder that is a file says so", "[hostile][assets]") {
  TempDir tmp("hostile_folder_kinds");
  write_text(tmp.path() / "bgs", "a file");
  write_text(tmp.path() / "skins", "a file");
  write_text(tmp.path() / "one_skin", "a file");
  write_text(tmp.path() / "c.yaml",
             "background: {mode: image, image_dir: bgs}\n"
             "character: {use_sprites: true, use_shape: false, sprite_dir: skins}\n"
             "npc: {enabled: true, sprite_paths: [one_skin]}\n");
  Analysis a;
  const std::string text = lint_text(tmp.path() / "c.yaml", a);
  INFO(text);
  CHECK(text.find("background folder '" + (tmp.path() / "bgs").string() + "' is a file, not a folder; name a folder") !=
        std::string::npos);
  CHECK(text.find("sprite folder '" + (tmp.path() / "skins").string() + "' is a file, not a folder; name a folder") !=
        std::string::npos);
  CHECK(text.find("sprite folder '" + (tmp.path() / "one_skin").string() + "' is a file, not a folder") !=
        std::string::npos);
  CHECK(text.find("does not exist") == std::string::npos);
}

TEST_CASE("absolute asset paths are printed as given", "[hostile][assets]") {
  TempDir tmp("hostile_absolute");
  const std::string missing = (tmp.path() / "gone" / "bg.png").string();
  const std::string no_dir = (tmp.path() / "no_skins").string();
  write_text(tmp.path() / "c.yaml", "background: {mode: image, image_path: " + missing +
                                        "}\ncharacter: {use_sprites: true, use_shape: false, sprite_dir: " + no_dir +
                                        "}\n");
  fs::current_path(source_dir());  // a working directory elsewhere: no ../../ rewriting
  Analysis a;
  const std::string text = lint_text(tmp.path() / "c.yaml", a);
  INFO(text);
  CHECK(text.find("asset file '" + missing + "' (from 'background.image_path') does not exist; fix the path") !=
        std::string::npos);
  CHECK(text.find("sprite folder '" + no_dir + "' does not exist") != std::string::npos);
  CHECK(text.find("../") == std::string::npos);
}

TEST_CASE("a small file claiming a huge image is too large, not of an unknown type", "[hostile][assets]") {
  TempDir tmp("hostile_huge_header");
  write_text(tmp.path() / "huge.png", png_header(50000, 50000));
  write_text(tmp.path() / "wide.png", png_header(1u << 30, 1));
  write_text(tmp.path() / "skin" / "frame.png", png_header(8000, 8000));
  write_text(tmp.path() / "c.yaml",
             "background: {mode: image, image_paths: [huge.png, wide.png]}\n"
             "character: {use_sprites: true, use_shape: false, sprite_path: skin}\n");
  Analysis a;
  const std::string text = lint_text(tmp.path() / "c.yaml", a);
  INFO(text);
  CHECK(text.find("huge.png' cannot be decoded: image too large: 50000x50000 pixels, more than 16777216 (4096x4096); "
                  "use a smaller image") != std::string::npos);
  CHECK(text.find("wide.png' cannot be decoded: image too large: 1073741824x1 pixels") != std::string::npos);
  CHECK(text.find("frame.png' cannot be decoded: image too large: 8000x8000 pixels") != std::string::npos);
  CHECK(text.find("unknown image type") == std::string::npos);
}

TEST_CASE("a huge image file is refused by its size before it is read", "[hostile][assets]") {
  TempDir tmp("hostile_huge_file");
  const uint64_t gib = uint64_t(1) << 30;
  for (const char* name : {"big.png", "skin/frame.png"}) {
    write_text(tmp.path() / name, png_header(64, 64));
    fs::resize_file(tmp.path() / name, gib);  // sparse: no disk used
  }
  write_text(tmp.path() / "c.yaml",
             "background: {mode: image, image_path: big.png}\n"
             "character: {use_sprites: true, use_shape: false, sprite_path: skin}\n");
  const uint64_t rss_before = peak_rss();
  Analysis a;
  const std::string text = lint_text(tmp.path() / "c.yaml", a);
  INFO(text);
  CHECK(text.find("big.png' (from 'background.image_path') is 1073741824 bytes, more than an image file may be "
                  "(256 MiB); use a smaller image") != std::string::npos);
  CHECK(text.find("frame.png' (from 'character.sprite_path') is 1073741824 bytes, more than an image file may be") !=
        std::string::npos);
  CHECK(peak_rss() < rss_before + (uint64_t(256) << 20));  // never read whole (that took 2 GB)
}

TEST_CASE("control bytes in keys and values are printed visibly", "[hostile]") {
  TempDir tmp("hostile_control_keys");
  write_text(tmp.path() / "c.yaml", "physics:\n  \"gra\\0vity\": 0.5\n  \"a\\tb\\x01\": 1\nbackground: {mode: \"x\\ey\"}\n");
  Analysis a;
  const std::string text = lint_text(tmp.path() / "c.yaml", a);
  INFO(text);
  CHECK(text.find("unknown key 'gra\\0vity' in 'physics'") != std::string::npos);
  CHECK(text.find("unknown key 'a\\tb\\x01' in 'physics'") != std::string::npos);
  CHECK(text.find("'x\\x1by'") != std::string::npos);
  for (char c : text) CHECK((c == '\n' || static_cast<unsigned char>(c) >= 0x20));
}

}  // namespace kage::test
