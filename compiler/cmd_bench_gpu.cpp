// kagec bench --gpu (compiler/bench_gpu.h): configs compiled by NVRTC, timed by bench/gpu_measure.h.
#include <cstdio>
#include <set>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "bench/gpu_measure.h"
#include "compiler/bench_gpu.h"
#include "compiler/build.h"
#include "compiler/codegen.h"
#include "compiler/lower.h"
#include "compiler/suite.h"
#include "runtime/host/asset_pack.h"

namespace kage {

namespace {

/// A manifest names its suite at the top level; a config never has that key.
bool is_suite_manifest(const std::string& path) {
  try {
    const YAML::Node doc = YAML::LoadFile(path);
    return doc.IsMap() && doc["suite"];
  } catch (const YAML::Exception&) {
    return false;  // the config path reports the error with its diagnostics
  }
}

/// The configs to bench, by label, each Spec once (a suite repeats its train configs across pairs).
bool collect_specs(const GpuBenchOptions& o, CommandIo& io, std::vector<std::pair<std::string, Spec>>* out,
                   int* exit_code) {
  if (!is_suite_manifest(o.file)) {
    std::optional<Spec> spec = resolve_file("bench", o.file, o.diag, io, exit_code);
    if (!spec) return false;
    out->emplace_back(o.file, std::move(*spec));
    return true;
  }
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  const auto suite = load_suite(o.file, sources, reader, diags);
  if (!suite || diags.has_errors()) {
    print_text(diags, io.err, io.err_is_terminal);
    *exit_code = kExitErrors;
    return false;
  }
  const SuiteReport report = run_suite(*suite, o.diag.resolve_options(), sources, reader, diags, nullptr);
  diags.disable_warnings();
  print_text(diags, io.err, io.err_is_terminal);
  std::set<std::string> seen;
  for (const PairResult& r : report.results) {
    for (const auto& [ref, spec] : {std::pair{&r.pair->train, &r.train}, std::pair{&r.pair->eval, &r.eval}}) {
      if (!*spec) {
        io.err << "kagec bench: " << ref->label() << ": does not resolve\n";
        *exit_code = kExitErrors;
        return false;
      }
      if (!seen.insert((*spec)->sha256()).second) continue;
      out->emplace_back(ref->label(), **spec);
    }
  }
  return true;
}

/// One config ready to run: its kernels (NVRTC or the kernel cache) and host copies of its assets.
struct Prepared {
  std::string label;
  CudaModule module;
  LoweredConfig config;
  AssetPack pack;
};

std::optional<Prepared> prepare(const std::string& label, const Spec& spec, std::string* error) {
  const LowerResult lowered = lower_spec(spec);
  if (!lowered.ok()) {
    *error = "the runtime cannot hold this config (kagec lint says why)";
    return std::nullopt;
  }
  AssetPackResult assets = load_asset_pack(lowered.config->assets);
  if (!assets.ok()) {
    *error = assets.error;
    return std::nullopt;
  }
  const GeneratedSource gen = generate_source({spec.sha256(), lowered.config->latent, lowered.config->visual});
  NvrtcOptions no;
  no.include_dir = runtime_include_dir();
  no.generator_version = std::to_string(kCodegenVersion);
  std::optional<CudaModule> m = CudaModule::compile(gen.text, gen.file_name, no, error);
  if (!m) return std::nullopt;
  return Prepared{label, std::move(*m), *lowered.config, std::move(*assets.pack)};
}

std::string rate_text(double steps_per_s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", steps_per_s);
  return buf;
}

std::string fixed(double v, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

}  // namespace

int bench_gpu(const GpuBenchOptions& o, CommandIo& io) {
  // The device first: without one there is nothing to compile for.
  std::string error;
  CUcontext ctx = cuda_primary_context(&error);
  if (!ctx) {
    io.err << "kagec bench --gpu: " << error << '\n';  // says there is no usable driver or GPU
    return kExitErrors;
  }
  int exit_code = kExitOk;
  std::vector<std::pair<std::string, Spec>> specs;
  if (!collect_specs(o, io, &specs, &exit_code)) return exit_code;
  std::vector<Prepared> configs;
  for (const auto& [label, spec] : specs) {
    std::optional<Prepared> p = prepare(label, spec, &error);
    if (!p) {
      io.err << "kagec bench: " << label << ": " << error << '\n';
      return kExitErrors;
    }
    configs.push_back(std::move(*p));
  }
  CUdevice dev;
  char name[256] = "?";
  if (cuCtxGetDevice(&dev) == CUDA_SUCCESS) cuDeviceGetName(name, sizeof name, dev);
  try {
    const double roof = bench::measure_roofline();
    io.out << "kagec bench --gpu on " << name << ": roofline (device-to-device copy, read + write) " << fixed(roof, 1)
           << " GB/s\n\n| config | envs | steps/s with obs | obs GB/s | % of roofline | steps/s no render |\n"
              "|---|---|---|---|---|---|\n";
    for (const Prepared& c : configs) {
      const bench::MeasureTarget target{&c.module, c.config.latent, c.config.visual, c.pack.view()};
      const double frame_bytes = 3.0 * c.config.visual.H * c.config.visual.W;
      for (int k = o.min_log2; k <= o.max_log2; ++k) {
        const bench::Timing t = bench::time_config(target, 1 << k, !o.no_render, true);
        const double gbs = t.render_steps_per_s * frame_bytes / 1e9;
        io.out << "| " << c.label << " | 2^" << k << " | ";
        if (o.no_render) {
          io.out << "- | - | - | ";
        } else {
          io.out << rate_text(t.render_steps_per_s) << " | " << fixed(gbs, 0) << " | " << fixed(100.0 * gbs / roof, 1)
                 << " | ";
        }
        io.out << rate_text(t.state_steps_per_s) << " |\n" << std::flush;
      }
    }
  } catch (const bench::MeasureError& e) {
    io.err << "kagec bench --gpu: " << e.what() << '\n';
    return kExitErrors;
  }
  return kExitOk;
}

}  // namespace kage
