// kagec bench --gpu (cmd_bench_gpu.h): configs compiled by NVRTC, timed by verify/throughput/gpu_measure.h.
#include <algorithm>
#include <cstdio>
#include <set>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "compiler/analysis/suite.h"
#include "compiler/codegen/build.h"
#include "compiler/codegen/codegen.h"
#include "compiler/codegen/nvrtc_options.h"
#include "driver/cmd_bench_gpu.h"
#include "compiler/lower/lower.h"
#include "runtime/io/asset_pack.h"
#include "runtime/cuda/parallel_compile.h"
#include "verify/throughput/gpu_measure.h"

namespace kage {

namespace {

/// A manifest names its suite at the top level; a config never has that key.
bool is_suite_manifest(const std::string& path) {
  DiskFileReader reader;  // regular files only: a FIFO or device must not hang or flood this probe
  std::string error;
  const std::optional<std::string> text = reader.read(path, &error);
  if (!text) return false;  // the config path reports the error with its diagnostics
  try {
    const YAML::Node doc = YAML::Load(*text);
    return doc.IsMap() && doc["suite"];
  } catch (const YAML::Exception&) {
    return false;
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

/// One config to bench: its lowered parameters, its generated source and, once compiled, its cubin.
struct Job {
  std::string label;
  LoweredConfig config;
  KernelJob kernels;
};

std::optional<Job> make_job(const std::string& label, const Spec& spec, std::string* error) {
  const LowerResult lowered = lower_spec(spec);
  if (!lowered.ok()) {
    *error = "the runtime cannot hold this config (kagec lint says why)";
    return std::nullopt;
  }
  GeneratedSource source = generate_source({spec.sha256(), lowered.config->latent, lowered.config->visual});
  Job j{label, *lowered.config, KernelJob{}};
  j.kernels.source = std::move(source.text);
  j.kernels.name = std::move(source.file_name);
  return j;
}

/// Fills every job's cubin for `arch`, from the kernel cache or NVRTC, configs side by side; one line on
/// `progress` per finished config.
void compile_all(std::vector<Job>& jobs, const std::string& arch, std::ostream& progress) {
  std::vector<KernelJob> kernels;
  for (Job& j : jobs) kernels.push_back(std::move(j.kernels));
  const auto report = [&](const KernelJob& k, size_t done) {
    progress << "kagec bench: config " << done << " of " << jobs.size() << ", "
             << jobs[static_cast<size_t>(&k - kernels.data())].label << ": "
             << (!k.cubin ? "FAILED" : k.cached ? "cached" : "compiled in " + fixed(k.seconds, 1) + " s") << '\n'
             << std::flush;
  };
  compile_jobs(kernels, generated_source_options(), arch, compile_threads(kernels.size()), report);
  for (size_t i = 0; i < jobs.size(); ++i) jobs[i].kernels = std::move(kernels[i]);
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
  std::vector<Job> jobs;
  for (const auto& [label, spec] : specs) {
    std::optional<Job> j = make_job(label, spec, &error);
    if (!j) {
      io.err << "kagec bench --gpu: " << label << ": " << error << '\n';
      return kExitErrors;
    }
    jobs.push_back(std::move(*j));
  }
  const std::optional<std::string> arch = device_arch(&error);
  if (!arch) {
    io.err << "kagec bench --gpu: " << error << '\n';
    return kExitErrors;
  }
  compile_all(jobs, *arch, io.err);
  size_t failed = 0;
  for (const Job& j : jobs) {
    if (j.kernels.cubin) continue;
    io.err << "kagec bench --gpu: " << j.label << ": " << j.kernels.error << '\n';
    ++failed;
  }
  if (failed) {
    io.err << "kagec bench --gpu: " << failed << " of " << jobs.size() << " configs did not compile\n";
    return kExitErrors;
  }
  CUdevice dev;
  char name[256] = "?";
  if (cuCtxGetDevice(&dev) == CUDA_SUCCESS) cuDeviceGetName(name, sizeof name, dev);
  // One config at a time on the device (its module and assets are freed before the next), each row
  // printed and flushed as soon as it is measured; any failure ends the run with a message and exit 1.
  try {
    const double roof = throughput::measure_roofline();
    io.out << "kagec bench --gpu on " << name << ": roofline (device-to-device copy, read + write) " << fixed(roof, 1)
           << " GB/s\n\n| config | envs | steps/s with obs | obs GB/s | % of roofline | steps/s no render |\n"
              "|---|---|---|---|---|---|\n"
           << std::flush;
    for (const Job& j : jobs) {
      std::optional<CudaModule> module = CudaModule::load_image(j.kernels.cubin->data(), &error);
      if (!module) throw throughput::MeasureError(j.label + ": " + error);
      AssetPackResult assets = load_asset_pack(j.config.assets);
      if (!assets.ok()) throw throughput::MeasureError(j.label + ": " + assets.error);
      const throughput::MeasureTarget target{&*module, j.config.latent, j.config.visual, assets.pack->view()};
      const double frame_bytes = 3.0 * j.config.visual.H * j.config.visual.W;
      for (int k = o.min_log2; k <= o.max_log2; ++k) {
        const throughput::Timing t = throughput::time_config(target, 1 << k, !o.no_render, true);
        const double gbs = t.render_steps_per_s * frame_bytes / 1e9;
        io.out << "| " << j.label << " | 2^" << k << " | ";
        if (o.no_render) {
          io.out << "- | - | - | ";
        } else {
          io.out << rate_text(t.render_steps_per_s) << " | " << fixed(gbs, 0) << " | " << fixed(100.0 * gbs / roof, 1)
                 << " | ";
        }
        io.out << rate_text(t.state_steps_per_s) << " |\n" << std::flush;
      }
    }
  } catch (const std::exception& e) {  // MeasureError, and anything else (e.g. bad_alloc) the same way
    io.out << std::flush;
    io.err << "kagec bench --gpu: " << e.what() << '\n';
    return kExitErrors;
  }
  if (!io.out) {
    io.err << "kagec bench --gpu: cannot write the table\n";
    return kExitErrors;
  }
  return kExitOk;
}

}  // namespace kage
