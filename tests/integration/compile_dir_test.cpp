// `kagec compile` output directories: built aside and renamed into place, unsafe targets and source
// names refused, and kage::open refusing a directory whose files no longer match their manifest.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

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
  REQUIRE(kagec({"compile", kConfig, "-o", out.string(), "--no-build"}).code == 0);
  CHECK(fs::exists(out / "manifest.json"));
  CHECK(fs::exists(out / "params.bin"));
  // A file of another compile (say a fatbin of a GPU build) must not survive the next compile.
  std::ofstream(out / "kernels.fatbin") << "stale";
  const Run again = kagec({"compile", kConfig, "-o", out.string(), "--no-build"});
  INFO(again.err);
  REQUIRE(again.code == 0);
  CHECK_FALSE(fs::exists(out / "kernels.fatbin"));
  CHECK(fs::exists(out / "manifest.json"));
  int siblings = 0;
  for (const auto& e : fs::directory_iterator(out.parent_path())) siblings += e.path().filename().string().find("replace") != std::string::npos;
  CHECK(siblings == 1);  // no staging or old directory left behind
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
  CHECK(r.err.find("holds other files (no manifest.json)") != std::string::npos);
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
