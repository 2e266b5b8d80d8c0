// kagec diff TRAIN EVAL [--certify [AXIS]].
#include <fstream>
#include <ostream>

#include "compiler/cli_common.h"
#include "compiler/diff.h"

namespace kage {

int cmd_diff(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("List the effective differences of a train/eval pair, grouped by axis.", "diff");
  std::string train_file, eval_file, output;
  std::string certify_axis;
  DiagOptions opts;
  app.add_option("train", train_file, "train config")->required();
  app.add_option("eval", eval_file, "eval config")->required();
  CLI::Option* certify_opt =
      app.add_option("--certify", certify_axis,
                     "exit 0 only if exactly one visual axis changes (optionally the named one) and nothing latent")
          ->expected(0, 1);
  app.add_option("-o,--output", output, "write the JSON certificate to this file");
  opts.add_to(app, false);
  if (auto code = parse_args(app, args, io)) return *code;
  std::optional<Axis> declared;
  if (!certify_axis.empty()) {
    declared = parse_axis(certify_axis);
    if (!declared || *declared == Axis::Latent) {
      io.err << "kagec diff: unknown axis '" << certify_axis
             << "'; use background, agent, distractors, filters, effects or layout\n";
      return kExitUsage;
    }
  }
  SourceManager sources;
  DiagEngine diags(sources);
  if (!opts.apply(diags, io)) return kExitUsage;
  DiskFileReader reader;
  const auto train = analyze_file(train_file, opts.resolve_options(), sources, reader, diags);
  const auto eval = analyze_file(eval_file, opts.resolve_options(), sources, reader, diags);
  print_text(diags, io.err, io.err_is_terminal);
  if (!train || !eval || diags.has_errors()) {
    io.err << "kagec diff: fix the errors above first\n";
    return kExitErrors;
  }
  const SpecDiff diff = diff_specs(*train, *eval, config_schema());
  print_diff(diff, io.out);
  const bool certifying = certify_opt->count() > 0;
  const Certification cert = certify(diff, declared, {});
  if (!output.empty()) {
    std::ofstream f(output, std::ios::binary);
    f << json_file_text(certificate_json({train_file, train->sha256()}, {eval_file, eval->sha256()}, diff, cert));
    if (!f) {
      io.err << "kagec diff: cannot write '" << output << "'\n";
      return kExitErrors;
    }
  }
  if (!certifying) return kExitOk;
  if (cert.certified) {
    io.out << "certified: exactly one visual axis changes (" << axes_text(cert.measured) << "), nothing latent\n";
    return kExitOk;
  }
  for (const std::string& p : cert.problems) io.out << "not certified: " << p << '\n';
  return kExitErrors;
}

}  // namespace kage
