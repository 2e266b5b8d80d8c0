// kagec compile CONFIG -o DIR: Spec -> lowered params -> generated source -> fatbin (nvcc) and host
// library (c++), with params.bin, assets.bin, spec.json and a manifest naming every file's SHA-256.
// Everything is built in a staging directory beside DIR that replaces DIR only when the compile
// succeeded, so DIR never mixes the files of two compiles.
#include <filesystem>
#include <ostream>

#include "compiler/basic/file_out.h"
#include "compiler/codegen/build.h"
#include "compiler/codegen/codegen.h"
#include "compiler/codegen/compiled_dir.h"
#include "driver/cli_common.h"
#include "runtime/io/specialized_assets.h"

namespace kage {

namespace fs = std::filesystem;

namespace {

/// The last lines of a tool's output, for a failure message.
std::string tail(const std::string& s, size_t lines) {
  size_t at = s.size();
  for (size_t n = 0; n <= lines && at > 0; ++n) at = s.rfind('\n', at - 1) == std::string::npos ? 0 : s.rfind('\n', at - 1);
  return s.substr(at);
}

}  // namespace

int cmd_compile(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("Generate a config's specialized source and build its GPU and CPU kernels.", "compile");
  std::string file, out_dir, source_name;
  bool no_build = false, no_gpu = false, no_host = false;
  DiagOptions opts;
  app.add_option("file", file, "config file")->required();
  app.add_option("-o,--output", out_dir, "output directory")->required();
  app.add_flag("--no-build", no_build, "only generate the source, params, Spec and manifest (no builds, no assets.bin)");
  app.add_option("--source-name", source_name, "file name of the generated source (default kage_<spec hash>.cu)");
  app.add_flag("--no-gpu", no_gpu, "skip nvcc (kernels.fatbin)");
  app.add_flag("--no-host", no_host, "skip the host compiler (kernels_host.so)");
  opts.add_to(app, false);
  if (auto code = parse_args(app, args, io)) return *code;
  int exit_code = kExitOk;
  const std::optional<LoweredFile> loaded = lower_file("compile", file, opts, io, &exit_code);
  if (!loaded) return exit_code;
  const Spec& spec = *loaded->spec;
  const LoweredConfig& lowered = *loaded->config;
  GeneratedSource gen = generate_source({spec.sha256(), lowered.latent, lowered.visual});

  if (!source_name.empty()) {
    if (const auto problem = source_name_problem(source_name)) {
      io.err << "kagec compile: " << *problem << '\n';
      return kExitUsage;
    }
    gen.file_name = source_name;
  }
  if (const auto problem = output_dir_problem(out_dir)) {
    io.err << "kagec compile: " << *problem << '\n';
    return kExitUsage;
  }
  std::string error;
  const std::optional<fs::path> staging = make_staging_dir(out_dir, &error);
  if (!staging) {
    io.err << "kagec compile: " << error << '\n';
    return kExitErrors;
  }
  const fs::path& dir = *staging;
  // Removes the staging directory on every early return; disarmed once it has been published.
  struct Cleanup {
    fs::path path;
    ~Cleanup() {
      std::error_code ec;
      if (!path.empty()) fs::remove_all(path, ec);
    }
  } cleanup{dir};
  auto write = [&](const std::string& name, const std::string& bytes) {
    if (write_file((dir / name).string(), bytes, &error)) return true;
    io.err << "kagec compile: " << error << '\n';
    return false;
  };
  if (!write(gen.file_name, gen.text) ||
      !write(kParamsFile, params_blob(param_words(lowered.latent), param_words(lowered.visual))) ||
      !write(kSpecFile, spec.canonical_text()))
    return kExitErrors;
  std::vector<std::string> files = {gen.file_name, kParamsFile, kSpecFile};
  if (!no_build) {
    AssetPackResult assets = load_asset_pack(lowered.assets);
    if (!assets.ok()) {
      io.err << "kagec compile: " << assets.error << '\n';
      return kExitErrors;
    }
    for (const std::string& w : assets.warnings) io.err << "kagec compile: warning: " << w << '\n';
    if (!write(kAssetsFile, serialize_asset_pack(*assets.pack))) return kExitErrors;
    files.push_back(kAssetsFile);
  }

  Json builds = Json::object();
  const std::string include_dir = runtime_include_dir();
  const std::string nvcc = find_nvcc(), cxx = find_host_cxx();
  auto build = [&](const char* name, const char* out_name, bool skip, const std::string& tool, const char* missing,
                   auto&& run) {
    Json b = {{"output", out_name}};
    if (no_build || skip) {
      b["status"] = "skipped";
      b["note"] = no_build ? "--no-build" : "disabled on the command line";
    } else if (tool.empty()) {
      b["status"] = "skipped";
      b["note"] = missing;
    } else {
      const ToolRun r = run(tool, (dir / gen.file_name).string(), (dir / out_name).string(), include_dir);
      io.err << "kagec compile: " << name << ": " << (r.ok() ? "built" : "FAILED") << " in " << r.seconds << " s\n";
      if (r.ok()) {
        b["status"] = "built";
        files.push_back(out_name);
      } else {
        b["status"] = "failed";
        b["note"] = tail(r.output, 20);
        io.err << r.output;
      }
    }
    builds[name] = b;
  };
  build("gpu", kFatbinFile, no_gpu, nvcc, "nvcc not found ($CUDACXX, $CUDA_HOME/bin, /usr/local/cuda/bin, PATH)",
        build_fatbin);
  build("host", kHostLibraryFile, no_host, cxx, "no host C++ compiler ($KAGE_HOST_CXX, $CXX, c++)",
        build_host_library);

  const std::string nvrtc = nvrtc_version();
  ManifestRecord record{spec.sha256(), kCodegenVersion, gen.template_hash, gen.latent_hash, gen.config_name,
                        gen.file_name, kCudaArch,
                        {{"nvcc", nvcc.empty() ? Json(nullptr) : Json(tool_version(nvcc))},
                         {"nvrtc", nvrtc.empty() ? Json(nullptr) : Json(nvrtc)},
                         {"host_cxx", cxx.empty() ? Json(nullptr) : Json(tool_version(cxx))}},
                        {{"nvcc", nvcc_flags()}, {"host", host_flags()}}, builds, files};
  bool failed = false;
  for (const auto& [name, b] : builds.items()) failed |= b.at("status") == "failed";
  if (failed) {
    io.err << "kagec compile: a build failed; '" << out_dir << "' is left as it was\n";
    return kExitErrors;
  }
  const std::optional<std::string> manifest = manifest_text(dir, record, &error);
  if (!manifest) {
    io.err << "kagec compile: " << error << '\n';
    return kExitErrors;
  }
  if (!write(kManifestFile, *manifest)) return kExitErrors;
  if (!publish_staging_dir(dir, out_dir, &error)) {
    io.err << "kagec compile: " << error << '\n';
    return kExitErrors;
  }
  cleanup.path.clear();
  io.out << (fs::path(out_dir) / gen.file_name).string() << '\n';
  return kExitOk;
}

}  // namespace kage
