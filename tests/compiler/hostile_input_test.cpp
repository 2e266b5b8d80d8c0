// Hostile and careless input to the front end: files that are not regular files, oversized files,
// `extends` chains thousands of files long. Each ends in a located error, never a hang or a crash.
#include <catch2/catch.hpp>

#include <sys/stat.h>

#include "compiler/basic/diag.h"
#include "compiler/parse/compose.h"
#include "test_support.h"

namespace kage::test {
namespace {

/// "rule: message" of the front end run on a file of the disk.
std::string analyze_disk(const std::string& path, Analysis& a) {
  DiskFileReader reader;
  analyze(a, path, reader);
  return a.dump();
}

}  // namespace

TEST_CASE("only regular files are read as configs", "[hostile]") {
  TempDir tmp("hostile_files");
  const std::string fifo = (tmp.path() / "pipe.yaml").string();
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  write_text(tmp.path() / "child.yaml", "extends: pipe.yaml\n");
  {
    Analysis a;  // a FIFO named by extends: refused at once (reading it would wait for a writer)
    const std::string d = analyze_disk((tmp.path() / "child.yaml").string(), a);
    INFO(d);
    CHECK(a.diags.has_errors());
    CHECK(d.find("extends-missing: cannot read base config '" + fifo + "': is not a regular file") != std::string::npos);
  }
  for (const char* special : {"/dev/zero", "/dev/null"}) {
    Analysis a;
    const std::string d = analyze_disk(special, a);
    INFO(d);
    CHECK(a.diags.has_errors());
    CHECK(d.find(std::string("file-unreadable: cannot read '") + special + "': is not a regular file") !=
          std::string::npos);
  }
  {
    Analysis a;  // states size 0, then fails to read: not an empty config
    const std::string d = analyze_disk("/proc/self/mem", a);
    INFO(d);
    CHECK(a.diags.has_errors());
    CHECK(a.count("file-unreadable") == 1);
  }
  {
    Analysis a;  // states size 0, then holds text
    const std::string d = analyze_disk("/proc/self/status", a);
    INFO(d);
    CHECK(a.diags.has_errors());
    CHECK(d.find("does not hold the 0 bytes its size states") != std::string::npos);
  }
  {
    Analysis a;
    const std::string d = analyze_disk(tmp.path().string(), a);
    CHECK(d.find("is a directory, not a file") != std::string::npos);
  }
}

TEST_CASE("a config larger than 16 MiB is refused before it is read", "[hostile]") {
  TempDir tmp("hostile_size");
  const fs::path big = tmp.path() / "big.yaml";
  write_text(big, "H: 64\n");
  fs::resize_file(big, kMaxConfigBytes + 1);  // sparse: no disk used
  Analysis a;
  const std::string d = analyze_disk(big.string(), a);
  INFO(d);
  CHECK(a.diags.has_errors());
  CHECK(d.find("is 16777217 bytes; a config may be at most 16 MiB") != std::string::npos);
}

TEST_CASE("a deep extends chain ends in an error at its limit, without recursion", "[hostile][extends]") {
  MemoryFileReader reader;
  const int depth = 7000;  // deep enough to overflow the stack of a recursive loader
  for (int i = 0; i < depth; ++i)
    reader.files["c/" + std::to_string(i) + ".yaml"] = "extends: " + std::to_string(i + 1) + ".yaml\n";
  reader.files["c/" + std::to_string(depth) + ".yaml"] = "H: 64\n";
  Analysis a;
  analyze(a, "c/0.yaml", reader);
  INFO(a.dump());
  CHECK(a.diags.has_errors());
  REQUIRE(a.count("extends-too-deep") == 1);
  CHECK(a.dump().find("'extends' chain is longer than 64 files at 'c/64.yaml'; merge some of its bases") !=
        std::string::npos);

  // A chain of exactly 64 files is fine, and its deepest base's values arrive.
  MemoryFileReader ok;
  for (int i = 0; i < 63; ++i) ok.files["c/" + std::to_string(i) + ".yaml"] = "extends: " + std::to_string(i + 1) + ".yaml\n";
  ok.files["c/63.yaml"] = "H: 64\nW: 64\nlayout: {length: 1024}\n";
  Analysis b;
  analyze(b, "c/0.yaml", ok);
  INFO(b.dump());
  REQUIRE(b.spec);
  CHECK(b.spec->values.at("H") == 64);
}

}  // namespace kage::test

namespace kage::test {

TEST_CASE("control characters in file names are escaped in diagnostics", "[hostile][assets]") {
  TempDir tmp("hostile_names");
  const std::string name = "bg\x1b[31mred\n.png";
  write_text(tmp.path() / name, "not an image");
  write_text(tmp.path() / "c.yaml", "background:\n  mode: image\n  image_path: \"bg\\e[31mred\\n.png\"\n");
  Analysis a;
  DiskFileReader reader;
  analyze(a, (tmp.path() / "c.yaml").string(), reader);
  REQUIRE(a.count("asset-unreadable") == 1);
  std::ostringstream text;
  print_text(a.diags, text);
  INFO(text.str());
  CHECK(text.str().find("bg\\x1b[31mred\\n.png") != std::string::npos);
  CHECK(text.str().find('\x1b') == std::string::npos);
}

TEST_CASE("asset scans stop at their bounds with an error", "[hostile][assets]") {
  TempDir tmp("hostile_scan");
  fs::path deep = tmp.path() / "deep" / "skin";
  for (int i = 0; i < 10; ++i) deep /= "d";
  fs::create_directories(deep);
  write_text(deep / "frame.png", "x");
  fs::create_directories(tmp.path() / "wide");
  for (int i = 0; i <= 10000; ++i) std::ofstream(tmp.path() / "wide" / (std::to_string(i) + ".png"));
  write_text(tmp.path() / "c.yaml",
             "background: {mode: image, image_dir: wide}\n"
             "character: {use_sprites: true, use_shape: false, sprite_dir: deep}\n");
  Analysis a;
  DiskFileReader reader;
  analyze(a, (tmp.path() / "c.yaml").string(), reader);
  INFO(a.dump());
  CHECK(a.dump().find("/wide' holds more than 10000 entries; point at a folder of assets") != std::string::npos);
  CHECK(a.dump().find("/deep/skin' is nested deeper than 8 levels; point at a folder of assets") != std::string::npos);
}

}  // namespace kage::test
