// Build: runs nvcc and the host compiler on a generated source (posix_spawn, no shell) and probes
// their versions for the manifest.
#include "compiler/codegen/build.h"

#include <dlfcn.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <mutex>

#include "runtime/cuda/nvrtc_search.h"

extern char** environ;

namespace kage {

namespace fs = std::filesystem;

#ifndef KAGE_SOURCE_ROOT
#define KAGE_SOURCE_ROOT "."
#endif

const std::vector<std::string>& nvcc_flags() {
  static const std::vector<std::string> flags = {
      "-std=c++20", "-O3", "--fmad=false", "-gencode", "arch=compute_90,code=[sm_90,compute_90]", "-fatbin"};
  return flags;
}

const std::vector<std::string>& host_flags() {
  static const std::vector<std::string> flags = {"-std=c++20", "-O2", "-ffp-contract=off", "-fPIC", "-shared"};
  return flags;
}

std::string join_flags(const std::vector<std::string>& flags) {
  std::string s;
  for (const std::string& f : flags) s += (s.empty() ? "" : " ") + f;
  return s;
}

namespace {

bool executable(const fs::path& p) {
  std::error_code ec;
  return !p.empty() && fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0;
}

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

/// `name` itself if it has a slash, else its first executable match on PATH.
std::string which(const std::string& name) {
  if (name.empty()) return "";
  if (name.find('/') != std::string::npos) return executable(name) ? name : "";
  const std::string path = env("PATH");
  size_t i = 0;
  while (i <= path.size()) {
    const size_t j = std::min(path.find(':', i), path.size());
    const fs::path dir = path.substr(i, j - i);
    if (!dir.empty() && executable(dir / name)) return (dir / name).string();
    i = j + 1;
  }
  return "";
}

}  // namespace

std::string find_nvcc() {
  for (const std::string& c : {env("CUDACXX"), env("CUDA_HOME").empty() ? std::string() : env("CUDA_HOME") + "/bin/nvcc",
                               std::string("/usr/local/cuda/bin/nvcc")}) {
    if (!c.empty() && executable(c)) return c;
  }
  return which("nvcc");
}

std::string find_host_cxx() {
  for (const std::string& c : {env("KAGE_HOST_CXX"), env("CXX"), std::string("c++")}) {
    if (const std::string w = which(c); !w.empty()) return w;
  }
  return "";
}

namespace {
std::mutex& runtime_dir_mutex() {
  static std::mutex m;
  return m;
}
std::string& runtime_dir_set() {
  static std::string d;
  return d;
}
}  // namespace

void set_runtime_include_dir(const std::string& dir) {
  std::lock_guard<std::mutex> lock(runtime_dir_mutex());
  runtime_dir_set() = dir;
}

std::string runtime_include_dir() {
  const std::string root = env("KAGE_ROOT");
  if (!root.empty()) return root;
  {
    std::lock_guard<std::mutex> lock(runtime_dir_mutex());
    if (!runtime_dir_set().empty()) return runtime_dir_set();
  }
  // An installed binary (kagec, or a library linked into a program) finds the headers that
  // `cmake --install` put beside it: <prefix>/bin/kagec -> <prefix>/share/kagec/runtime.
  // The binary is the running program, or the shared object this code was linked into.
  std::vector<std::string> binaries = {"/proc/self/exe"};
  Dl_info info{};
  if (::dladdr(reinterpret_cast<const void*>(&runtime_include_dir), &info) && info.dli_fname && *info.dli_fname)
    binaries.push_back(info.dli_fname);
  for (const std::string& b : binaries) {
    std::error_code ec;
    const fs::path binary = fs::canonical(b, ec);
    if (ec) continue;
    const fs::path installed = binary.parent_path().parent_path() / "share" / "kagec";
    if (fs::is_regular_file(installed / "runtime" / "kage_hd.h", ec)) return installed.string();
  }
  return KAGE_SOURCE_ROOT;  // the source tree of a build that was not installed
}

ToolRun run_tool(const std::vector<std::string>& argv) {
  ToolRun r;
  r.argv = argv;
  int pipe_fd[2];
  if (argv.empty() || ::pipe(pipe_fd) != 0) return r;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fd[1], 1);
  posix_spawn_file_actions_adddup2(&actions, pipe_fd[1], 2);
  posix_spawn_file_actions_addclose(&actions, pipe_fd[0]);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const auto t0 = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), ::environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fd[1]);
  if (rc == 0) {
    char buf[4096];
    ssize_t n;
    while ((n = ::read(pipe_fd[0], buf, sizeof buf)) > 0) r.output.append(buf, static_cast<size_t>(n));
    int status = 0;
    ::waitpid(pid, &status, 0);
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  } else {
    r.output = "cannot run '" + argv[0] + "'";
  }
  ::close(pipe_fd[0]);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

std::string tool_version(const std::string& tool) {
  if (tool.empty()) return "";
  const ToolRun r = run_tool({tool, "--version"});
  if (!r.ok()) return "";
  // nvcc prints a banner; its last line names the release. Other compilers name it on the first.
  std::vector<std::string> lines;
  size_t i = 0;
  while (i < r.output.size()) {
    const size_t j = std::min(r.output.find('\n', i), r.output.size());
    if (j > i) lines.push_back(r.output.substr(i, j - i));
    i = j + 1;
  }
  if (lines.empty()) return "";
  for (const std::string& l : lines)
    if (l.rfind("Cuda compilation tools", 0) == 0) return l;
  return lines.front();
}

std::string nvrtc_version() {
  void* lib = open_nvrtc();
  if (!lib) return "";
  using VersionFn = int (*)(int*, int*);
  std::string v;
  if (auto fn = reinterpret_cast<VersionFn>(::dlsym(lib, "nvrtcVersion"))) {
    int major = 0, minor = 0;
    if (fn(&major, &minor) == 0) v = std::to_string(major) + "." + std::to_string(minor);
  }
  ::dlclose(lib);
  return v;
}

ToolRun build_fatbin(const std::string& nvcc, const std::string& source, const std::string& fatbin,
                     const std::string& include_dir) {
  std::vector<std::string> argv = {nvcc};
  argv.insert(argv.end(), nvcc_flags().begin(), nvcc_flags().end());
  argv.insert(argv.end(), {"-I", include_dir, "-o", fatbin, source});
  return run_tool(argv);
}

ToolRun build_host_library(const std::string& cxx, const std::string& source, const std::string& shared_object,
                           const std::string& include_dir) {
  std::vector<std::string> argv = {cxx};
  argv.insert(argv.end(), host_flags().begin(), host_flags().end());
  // The generated file is C++ whatever its extension says.
  argv.insert(argv.end(), {"-I", include_dir, "-x", "c++", source, "-x", "none", "-o", shared_object});
  return run_tool(argv);
}

}  // namespace kage
