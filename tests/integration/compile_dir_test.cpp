// Output directories: `kagec compile`'s built aside and renamed into place, unsafe targets and source
// names refused, only a directory kagec wrote replaced (also `kagec suite`'s), and kage::open refusing
// a directory whose files no longer match their manifest.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <sstream>
#include <vector>

#include <unistd.h>

#include "driver/commands.h"
#include "kage/kage.h"
#include "tests/integration/integration_support.h"

namespace {

namespace fs = std::filesystem;
using kage::test::kRoot;

struct Run {
  int code;
  std::string out, err;
};

Run kagec(const std::vector<std::string>& args) {
  std::ostringstream o, e;
  kage::CommandIo io{o, e};
  const int code = kage::run_kagec(args, io);
  return {code, o.str(), e.str()};
}

fs::path fresh(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("kage_compile_dir_test_" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  fs::create_directories(p.parent_path());
  return p;
}

const std::string kConfig = kRoot + "/configs/throughput/simplest.yaml";

}  // namespace

TEST_CASE("compile replaces an earlier compile whole, and leaves nothing beside it", "[integration][compile]") {
  const fs::path out = fresh("replace");
  REQUIRE(kagec({"compile", kConfig, "-o", out.string(), "--no-build", "--source-name", "first.cu"}).code == 0);
  CHECK(fs::exists(out / "manifest.json"));
  CHECK(fs::exists(out / "params.bin"));
  CHECK(fs::exists(out / "first.cu"));
  // A file of the earlier compile (here its generated source) must not survive the next compile.
  const Run again = kagec({"compile", kConfig, "-o", out.string(), "--no-build", "--source-name", "second.cu"});
  INFO(again.err);
  REQUIRE(again.code == 0);
  CHECK_FALSE(fs::exists(out / "first.cu"));
  CHECK(fs::exists(out / "second.cu"));
  CHECK(fs::exists(out / "manifest.json"));
  int siblings = 0;
  for (const auto& e : fs::directory_iterator(out.parent_path())) siblings += e.path().filename().string().find("replace") != std::string::npos;
  CHECK(siblings == 1);  // no staging or old directory left behind
  // An empty directory is taken too.
  const fs::path empty = fresh("empty");
  fs::create_directories(empty);
  CHECK(kagec({"compile", kConfig, "-o", empty.string(), "--no-build"}).code == 0);
  CHECK(fs::exists(empty / "manifest.json"));
}

TEST_CASE("compile refuses unsafe output directories and source names", "[integration][compile]") {
  Run r = kagec({"compile", kConfig, "-o", "/", "--no-build"});
  CHECK(r.code == 2);
  CHECK(r.err.find("'/' is the root directory") != std::string::npos);

  const fs::path other = fresh("not_a_compile");
  fs::create_directories(other);
  std::ofstream(other / "notes.txt") << "mine";
  r = kagec({"compile", kConfig, "-o", other.string(), "--no-build"});
  CHECK(r.code == 2);
  CHECK(r.err.find("holds files that kagec did not write (it has no manifest.json)") != std::string::npos);
  CHECK(fs::exists(other / "notes.txt"));

  const fs::path out = fresh("names");
  for (const char* bad : {"manifest.json", "../escape.cu", "sub/dir.cu", "params.bin", ".hidden.cu", "x.txt"}) {
    INFO(bad);
    r = kagec({"compile", kConfig, "-o", out.string(), "--no-build", "--source-name", bad});
    CHECK(r.code == 2);
    CHECK(r.err.find("--source-name") != std::string::npos);
    CHECK_FALSE(fs::exists(out));
  }
  CHECK_FALSE(fs::exists(out.parent_path() / "escape.cu"));
  CHECK(kagec({"compile", kConfig, "-o", out.string(), "--no-build", "--source-name", "my_config.cu"}).code == 0);
  CHECK(fs::exists(out / "my_config.cu"));
}

TEST_CASE("kage::open verifies every file of a compile against its manifest", "[integration][compile][api]") {
  const fs::path out = fresh("verify");
  REQUIRE(kagec({"compile", kConfig, "-o", out.string(), "--no-build"}).code == 0);
  kage::Options o;
  o.num_envs = 2;
  std::string error;
  // Intact, but built without the host library: a clear message, not a dlopen failure.
  CHECK(kage::open(out.string(), o, &error) == nullptr);
  CHECK(error.find("has no kernels_host.so") != std::string::npos);

  std::string params;
  {
    std::ifstream in(out / "params.bin", std::ios::binary);
    params.assign(std::istreambuf_iterator<char>(in), {});
  }
  REQUIRE(params.size() > 8);
  params[4] ^= 1;
  std::ofstream(out / "params.bin", std::ios::binary) << params;
  error.clear();
  CHECK(kage::open(out.string(), o, &error) == nullptr);
  CHECK(error.find("params.bin' does not match the SHA-256 its manifest states") != std::string::npos);

  REQUIRE(kagec({"compile", kConfig, "-o", out.string(), "--no-build"}).code == 0);
  fs::remove(out / "spec.json");
  error.clear();
  CHECK(kage::open(out.string(), o, &error) == nullptr);
  CHECK(error.find("spec.json', listed in the manifest, cannot be read") != std::string::npos);
}

namespace {

/// Every file under `dir` with its bytes, to show that a refused command left it as it was.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    std::string bytes = e.is_symlink() ? "-> " + fs::read_symlink(e.path()).string() : e.is_directory() ? "/" : "";
    if (e.is_regular_file() && !e.is_symlink()) {
      std::ifstream in(e.path(), std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    out[e.path().lexically_relative(dir).string()] = bytes;
  }
  return out;
}

void write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

}  // namespace

TEST_CASE("compile replaces only a directory that it wrote, and says why it refuses another", "[integration][compile]") {
  struct Case {
    const char* name;
    std::function<void(const fs::path&)> make;
    const char* says;
  };
  const fs::path earlier = fresh("earlier");
  REQUIRE(kagec({"compile", kConfig, "-o", earlier.string(), "--no-build"}).code == 0);
  const std::vector<Case> cases = {
      // A web project: someone else's manifest.json beside other files.
      {"web_manifest",
       [](const fs::path& d) {
         write(d / "manifest.json", R"({"name": "my app", "short_name": "app", "icons": []})");
         write(d / "index.html", "<html></html>");
       },
       "manifest.json' is not a kagec compile manifest, so kagec did not write"},
      {"web_manifest_alone",
       [](const fs::path& d) { write(d / "manifest.json", R"({"name": "my app", "files": []})"); },
       "is not a kagec compile manifest"},
      // An earlier compile with a file the manifest does not list.
      {"extra_file",
       [&](const fs::path& d) {
         fs::copy(earlier, d);
         write(d / "notes.txt", "my notes");
       },
       "holds 'notes.txt', which its manifest.json does not list (kagec did not write it); move such files out"},
      {"extra_folder",
       [&](const fs::path& d) {
         fs::copy(earlier, d);
         write(d / "data" / "keep.bin", "precious");
       },
       "holds 'data', which its manifest.json does not list"},
      // A listed name that is a link to someone else's file.
      {"listed_name_is_a_link",
       [&](const fs::path& d) {
         fs::copy(earlier, d);
         fs::remove(d / "spec.json");
         write(d.parent_path() / (d.filename().string() + "_target") / "spec.json", "theirs");
         fs::create_symlink(d.parent_path() / (d.filename().string() + "_target") / "spec.json", d / "spec.json");
       },
       "holds 'spec.json', which its manifest.json does not list"},
      // A manifest that is a link (to a real kagec manifest elsewhere) is not this directory's.
      {"manifest_is_a_link",
       [&](const fs::path& d) {
         write(d / "index.html", "<html></html>");
         fs::create_symlink(earlier / "manifest.json", d / "manifest.json");
       },
       "is not a kagec compile manifest"},
      {"a_file",
       [](const fs::path& d) { write(d, "a file, not a directory"); },
       "exists and is not a directory; name a new directory, or move the file away"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    const fs::path dir = fresh(c.name);
    c.make(dir);
    const auto before = fs::is_directory(dir) ? snapshot(dir) : std::map<std::string, std::string>{};
    const Run r = kagec({"compile", kConfig, "-o", dir.string(), "--no-build"});
    INFO(r.err);
    CHECK(r.code == 2);
    CHECK(r.err.find(c.says) != std::string::npos);
    CHECK(r.err.find("kagec compile: '" + dir.string()) != std::string::npos);
    if (fs::is_directory(dir)) CHECK(snapshot(dir) == before);
  }
  // A symbolic link to an earlier compile, with or without a trailing '/': the link is not replaced.
  const fs::path link = fresh("link");
  fs::create_directory_symlink(earlier, link);
  const auto before = snapshot(earlier);
  for (const std::string& name : {link.string(), link.string() + "/"}) {
    const Run r = kagec({"compile", kConfig, "-o", name, "--no-build"});
    INFO(r.err);
    CHECK(r.code == 2);
    CHECK(r.err.find("is a symbolic link, which this command will not replace") != std::string::npos);
    CHECK(fs::is_symlink(link));
    CHECK(snapshot(earlier) == before);
  }
}

namespace {

/// A suite manifest of `pairs` pairs (background/1, background/2, ...) in a fresh folder.
fs::path tiny_suite(const std::string& name, int pairs) {
  const fs::path dir = fresh(name + "_manifest");
  std::string text = "suite: tiny\npairs:\n";
  for (int i = 1; i <= pairs; ++i)
    text += "  - name: background/" + std::to_string(i) + "\n    axis: background\n    train: " + kRoot +
            "/configs/kage_bench/bases/shape_black.yaml\n    eval: " + kRoot + "/configs/kage_bench/background/" +
            std::to_string(i) + "-eval.yaml\n";
  write(dir / "suite.yaml", text);
  return dir / "suite.yaml";
}

}  // namespace

TEST_CASE("suite -o replaces only an earlier report, whole", "[integration][suite]") {
  const fs::path two = tiny_suite("two", 2), one = tiny_suite("one", 1);
  const fs::path out = fresh("suite_out");
  Run r = kagec({"suite", two.string(), "-o", out.string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(fs::exists(out / "certificates" / "background_2.json"));
  // The same directory again, from a suite without background/2: its certificate does not linger.
  r = kagec({"suite", one.string(), "-o", out.string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(fs::exists(out / "report.json"));
  CHECK(fs::exists(out / "certificates" / "background_1.json"));
  CHECK_FALSE(fs::exists(out / "certificates" / "background_2.json"));

  struct Case {
    const char* name;
    std::function<void(const fs::path&)> make;
    const char* says;
  };
  const std::vector<Case> cases = {
      {"someone_elses_report",
       [](const fs::path& d) {
         write(d / "report.json", R"({"coverage": 0.93})");
         write(d / "index.html", "<html></html>");
       },
       "report.json' is not a kagec suite report, so kagec did not write"},
      {"other_files",
       [](const fs::path& d) { write(d / "notes.txt", "mine"); },
       "holds files that kagec did not write (it has no report.json)"},
      {"extra_certificate",
       [&](const fs::path& d) {
         fs::copy(out, d, fs::copy_options::recursive);
         write(d / "certificates" / "mine.json", "{}");
       },
       "holds 'certificates/mine.json', which its report.json does not account for"},
      {"extra_file",
       [&](const fs::path& d) {
         fs::copy(out, d, fs::copy_options::recursive);
         write(d / "README.md", "notes");
       },
       "holds 'README.md', which its report.json does not account for"},
      {"a_file", [](const fs::path& d) { write(d, "text"); }, "exists and is not a directory"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    const fs::path dir = fresh(c.name);
    c.make(dir);
    const auto before = fs::is_directory(dir) ? snapshot(dir) : std::map<std::string, std::string>{};
    r = kagec({"suite", one.string(), "-o", dir.string()});
    INFO(r.err);
    CHECK(r.code == 2);
    CHECK(r.err.find(c.says) != std::string::npos);
    if (fs::is_directory(dir)) CHECK(snapshot(dir) == before);
  }
  const fs::path link = fresh("suite_link");
  fs::create_directory_symlink(out, link);
  r = kagec({"suite", one.string(), "-o", link.string()});
  CHECK(r.code == 2);
  CHECK(r.err.find("is a symbolic link") != std::string::npos);
  CHECK(fs::is_symlink(link));
}
