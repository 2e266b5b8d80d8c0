// The config compiler's front end for the Python package (see front_end.h).
#include "api/python/front_end.h"

#include "compiler/analysis/diff.h"
#include "compiler/analysis/mixture.h"
#include "compiler/analysis/suite.h"
#include "compiler/basic/file_out.h"
#include "compiler/codegen/build.h"

namespace kage::python {
namespace {

ResolveOptions options_for(const std::string& asset_root) {
  ResolveOptions o;
  if (!asset_root.empty()) o.asset_root = asset_root;
  return o;
}

}  // namespace

FrontEndResult resolve_config_json(const std::string& path, const std::string& asset_root) {
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  const auto spec = analyze_file(path, options_for(asset_root), sources, reader, diags);
  if (!spec || diags.has_errors()) return {"", diagnostics_text(diags) + "kage: no Spec for '" + path + "'"};
  return {spec->canonical_text(), ""};
}

std::string lint_text(const std::string& path, const std::string& asset_root) {
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  analyze_file(path, options_for(asset_root), sources, reader, diags);
  return diagnostics_text(diags);
}

FrontEndResult certify_pair_json(const std::string& train, const std::string& eval, const std::string& asset_root) {
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  const auto t = analyze_file(train, options_for(asset_root), sources, reader, diags);
  const auto e = analyze_file(eval, options_for(asset_root), sources, reader, diags);
  if (!t || !e || diags.has_errors()) return {"", diagnostics_text(diags) + "kage: cannot certify '" + train + "' / '" + eval + "'"};
  const SpecDiff diff = diff_specs(*t, *e, config_schema());
  const Certification cert = certify(diff, std::nullopt, {});
  return {json_file_text(certificate_json({train, t->sha256()}, {eval, e->sha256()}, diff, cert)), ""};
}

FrontEndResult certify_mixture_json(const std::vector<std::string>& paths, const std::string& asset_root) {
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  const auto specs = analyze_mixture(paths, options_for(asset_root), sources, reader, diags);
  if (!specs) return {"", diagnostics_text(diags) + "kage: not a mixture of these configs"};
  return {json_file_text(mixture_json(paths, *specs, config_schema())), ""};
}

std::string mixture_hash(const std::vector<std::pair<std::string, int32_t>>& parts) { return mixture_sha256(parts); }

FrontEndResult suite_report(const std::string& manifest) {
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  const auto suite = load_suite(manifest, sources, reader, diags, runtime_include_dir() + "/configs");
  if (!suite || diags.has_errors()) return {"", diagnostics_text(diags) + "kage: suite '" + manifest + "' has errors (above)"};
  const SuiteReport report = run_suite(*suite, ResolveOptions{}, sources, reader, diags, nullptr);
  diags.disable_warnings();
  for (const PairResult& r : report.results)
    if (!r.lint_ok) return {"", diagnostics_text(diags) + "kage: suite '" + manifest + "' has configs with errors"};
  return {json_file_text(suite_report_json(*suite, report)), ""};
}

}  // namespace kage::python
