// compile_jobs: several sources compiled side by side give each the cubin that compiling it alone gives, fill
// the kernel cache (a second pass takes every cubin from it), and report a source that does not compile as its
// own failure. NVRTC is a library: this runs without a GPU, for sm_90.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <unistd.h>

#include "runtime/cuda/parallel_compile.h"

namespace kage {
namespace {

namespace fs = std::filesystem;

std::string kernel_source(int i) {
  return "extern \"C\" __global__ void kage_job_" + std::to_string(i) + "(int* out) { out[0] = " +
         std::to_string(i * 7 + 1) + "; }\n";
}

std::vector<KernelJob> jobs_of(const std::vector<std::string>& sources) {
  std::vector<KernelJob> jobs;
  for (size_t i = 0; i < sources.size(); ++i) {
    KernelJob j;
    j.source = sources[i];
    j.name = "job_" + std::to_string(i) + ".cu";
    jobs.push_back(std::move(j));
  }
  return jobs;
}

/// A kernel cache of this test's own, removed at the end.
struct TemporaryCache {
  fs::path dir = fs::temp_directory_path() / ("kage_parallel_compile_" + std::to_string(::getpid()));
  TemporaryCache() { ::setenv("KAGE_CACHE_DIR", dir.c_str(), 1); }
  ~TemporaryCache() {
    ::unsetenv("KAGE_CACHE_DIR");
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

TEST_CASE("compile_jobs compiles each source as alone, caches it, and names a failure", "[cuda][nvrtc]") {
  const TemporaryCache cache;
  NvrtcOptions options;
  options.include_dir = KAGE_SOURCE_DIR;
  options.generator_version = "parallel-compile-test";
  std::vector<std::string> sources;
  for (int i = 0; i < 5; ++i) sources.push_back(kernel_source(i));
  sources.push_back("extern \"C\" __global__ void broken(int* out) { out[0] = undeclared_name; }\n");

  std::vector<KernelJob> jobs = jobs_of(sources);
  std::multiset<size_t> reported;
  compile_jobs(jobs, options, "sm_90", 3, [&](const KernelJob&, size_t done) { reported.insert(done); });
  CHECK(reported == std::multiset<size_t>{1, 2, 3, 4, 5, 6});
  for (size_t i = 0; i < 5; ++i) {
    INFO("job " << i << ": " << jobs[i].error);
    REQUIRE(jobs[i].cubin);
    CHECK_FALSE(jobs[i].cached);
    CHECK(jobs[i].cubin->find("kage_job_" + std::to_string(i)) != std::string::npos);
    std::string error;
    const std::optional<std::string> alone =
        nvrtc_compile(sources[i], jobs[i].name, nvrtc_option_list("sm_90", options), &error);
    REQUIRE(alone);
    CHECK(*alone == *jobs[i].cubin);
  }
  CHECK_FALSE(jobs[5].cubin);
  CHECK(jobs[5].error.find("undeclared_name") != std::string::npos);

  std::vector<KernelJob> again = jobs_of(sources);
  compile_jobs(again, options, "sm_90", 2);
  for (size_t i = 0; i < 5; ++i) {
    REQUIRE(again[i].cubin);
    CHECK(again[i].cached);
    CHECK(*again[i].cubin == *jobs[i].cubin);
  }
  CHECK_FALSE(again[5].cubin);  // a failure is not cached
}

TEST_CASE("compile_threads: one per core, at most one per job and 16", "[cuda]") {
  CHECK(compile_threads(0) == 1);
  CHECK(compile_threads(1) == 1);
  CHECK(compile_threads(1000) <= 16);
  CHECK(compile_threads(1000) >= 1);
  CHECK(compile_threads(2) <= 2);
}

}  // namespace
}  // namespace kage
