// load_lowered: analyze_file, then lower_spec when the front end found no error (see load_lowered.h).
#include "compiler/lower/load_lowered.h"

namespace kage {

LoweredFile load_lowered(const std::string& path, const ResolveOptions& options, SourceManager& sources,
                         FileReader& reader, DiagEngine& diags) {
  LoweredFile out;
  std::optional<Spec> spec = analyze_file(path, options, sources, reader, diags);
  if (!spec || diags.has_errors()) return out;
  out.spec = std::move(spec);
  LowerResult lowered = lower_spec(*out.spec);
  if (lowered.ok())
    out.config = std::move(lowered.config);
  else
    out.lower_errors = lowered.error_text();
  return out;
}

}  // namespace kage
