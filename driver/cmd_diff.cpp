// kagec diff TRAIN EVAL [--certify] [--axis AXIS | --certify=AXIS] [-o CERT.json];
// kagec diff --mixture A B [C ...] [-o CERT.json].
#include <ostream>

#include "compiler/analysis/diff.h"
#include "compiler/analysis/mixture.h"
#include "compiler/basic/file_out.h"
#include "driver/cli_common.h"

namespace kage {
namespace {

// `--certify=AXIS` is `--certify --axis AXIS`. The axis never follows `--certify` as a separate word,
// which would make it indistinguishable from the TRAIN file.
std::vector<std::string> split_certify_axis(const std::vector<std::string>& args) {
  std::vector<std::string> out;
  for (const std::string& a : args) {
    if (a.rfind("--certify=", 0) == 0) {
      out.insert(out.end(), {"--certify", "--axis", a.substr(10)});
    } else {
      out.push_back(a);
    }
  }
  return out;
}

/// --mixture: the configs certified as one batch (they differ only on visual axes); 0 when they are.
int certify_mixture_files(const std::vector<std::string>& files, const std::string& output, const DiagOptions& opts,
                          CommandIo& io) {
  SourceManager sources;
  DiagEngine diags(sources);
  if (!opts.apply(diags, io)) return kExitUsage;
  DiskFileReader reader;
  const auto specs = analyze_mixture(files, opts.resolve_options(), sources, reader, diags);
  print_text(diags, io.err, io.err_is_terminal);
  if (!specs) {
    io.err << "kagec diff: not a mixture: fix the errors above first\n";
    return kExitErrors;
  }
  const Json cert = mixture_json(files, *specs, config_schema());
  if (!output.empty()) {
    std::string error;
    if (!write_file(output, json_file_text(cert), &error)) {
      io.err << "kagec diff: " << error << '\n';
      return kExitErrors;
    }
  }
  std::set<Axis> axes;
  for (const Json& a : cert.at("axes")) axes.insert(*parse_axis(a.get<std::string>()));
  io.out << "certified mixture: " << files.size() << " configs, one hidden game and one observation shape; they "
         << "differ on " << axes_text(axes) << "\n";
  return kExitOk;
}

}  // namespace

int cmd_diff(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("List the effective differences of a train/eval pair, grouped by axis.", "diff");
  std::vector<std::string> files;
  std::string output, certify_axis;
  bool certify_flag = false, mixture = false;
  DiagOptions opts;
  app.add_option("files", files, "TRAIN EVAL: the two configs (with --mixture, two or more)")->required()->expected(2, -1);
  app.add_flag("--certify", certify_flag,
               "exit 0 only if exactly one visual axis changes and nothing latent (--certify=AXIS names the axis)");
  app.add_option("--axis", certify_axis, "certify, requiring that the changing axis is this one");
  app.add_flag("--mixture", mixture,
               "certify the configs as a mixture (one batch): exit 0 only if they share every latent key, the "
               "observation shape included, and differ only on visual axes");
  app.add_option("-o,--output", output, "write the JSON certificate to this file");
  opts.add_to(app, false);
  if (auto code = parse_args(app, split_certify_axis(args), io)) return *code;
  if (mixture) {
    if (certify_flag || !certify_axis.empty()) {
      io.err << "kagec diff: --mixture certifies a mixture; --certify and --axis certify a train/eval pair\n";
      return kExitUsage;
    }
    return certify_mixture_files(files, output, opts, io);
  }
  if (files.size() != 2) {
    io.err << "kagec diff: expected two configs (TRAIN EVAL), got " << files.size();
    if (files.size() == 3)
      io.err << "; an axis to certify is written --axis " << files[0] << " or --certify=" << files[0]
             << " (also after the files)";
    io.err << "; configs batched together are certified with --mixture\n";
    return kExitUsage;
  }
  const std::string& train_file = files[0];
  const std::string& eval_file = files[1];
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
    hint_shipped("diff", "configs", train_file, io);
    hint_shipped("diff", "configs", eval_file, io);
    io.err << "kagec diff: fix the errors above first\n";
    return kExitErrors;
  }
  const SpecDiff diff = diff_specs(*train, *eval, config_schema());
  print_diff(diff, io.out);
  const bool certifying = certify_flag || !certify_axis.empty();
  const Certification cert = certify(diff, declared, {});
  if (!output.empty()) {
    std::string error;
    if (!write_file(output,
                    json_file_text(certificate_json({train_file, train->sha256()}, {eval_file, eval->sha256()}, diff, cert)),
                    &error)) {
      io.err << "kagec diff: " << error << '\n';
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
