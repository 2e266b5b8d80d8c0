// Fuzz target of the front end: arbitrary bytes as a config file, through
// load (extends), check and resolve with an in-memory FileReader.
//
// Properties: no crash or hang; every diagnostic range lies inside its
// buffer; printing works; and when the input resolves without errors, the
// canonical JSON is a fixpoint (canonical -> spec_from_json -> canonical) and
// a second run gives the same bytes. The config sits (in memory) among the shipped configs, so its
// `extends:` and asset paths reach real files; the inputs that reach the fixpoint are counted, and the
// callers require some (a run where every input failed to resolve would prove nothing).
//
// Built as a libFuzzer target with -DKAGE_FUZZ_MAIN (tests/fuzz/run_fuzz.sh);
// kage_compiler_tests calls kage::fuzz_front_end_one without the fuzzer runtime.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>
#include <string>

#include "compiler/basic/diag.h"
#include "compiler/parse/compose.h"
#include "compiler/sema/resolve.h"

namespace kage {

namespace {

namespace fs = std::filesystem;

const std::string kConfigs = fs::path(KAGE_SOURCE_DIR "/configs").lexically_normal().string();
// Beside the KAGE-Bench pairs, whose `extends: ../bases/...` and `../../../assets/...` then resolve.
const std::string kDir = kConfigs + "/kage_bench/fuzz";

// The config under test and a base it may name with `extends: base.yaml`, in memory; any other file
// under configs/ from the disk, so that the shipped bases can be extended.
class FuzzReader final : public FileReader {
 public:
  std::map<std::string, std::string> files;
  std::optional<std::string> read(const std::string& path, std::string* err) override {
    const std::string key = fs::path(path).lexically_normal().string();
    if (const auto it = files.find(key); it != files.end()) return it->second;
    if (key.rfind(kConfigs + "/", 0) == 0 && key.find("/..") == std::string::npos) return disk_.read(key, err);
    if (err) *err = "no such file";
    return std::nullopt;
  }

 private:
  DiskFileReader disk_;
};

constexpr const char* kBase =
    "H: 64\nW: 64\nphysics:\n  gravity: 0.75\n  move_speed: 2\nbackground:\n  mode: color\n"
    "  color_names: [purple, teal]\ncharacter:\n  use_shape: true\n  use_sprites: false\n";

struct Outcome {
  std::string canonical;  // empty when there were errors
  std::string problem;
};

Outcome run_once(const std::string& text) {
  FuzzReader reader;
  reader.files[kDir + "/config.yaml"] = text;
  reader.files[kDir + "/base.yaml"] = kBase;
  SourceManager sources;
  DiagEngine diags(sources);
  const ResolveOptions options;
  std::optional<Spec> spec;
  if (auto config = load_config(kDir + "/config.yaml", sources, reader, diags))
    spec = analyze_composed(*config, options, sources, diags);
  Outcome out;
  for (const Diagnostic& d : diags.sorted()) {
    if (!d.range.begin.valid()) continue;
    const size_t size = sources.text(d.range.begin.file).size();
    if (d.range.begin.offset > size || d.range.end > size || d.range.end < d.range.begin.offset) {
      out.problem = "diagnostic range outside its buffer: [" + std::to_string(d.range.begin.offset) + ", " +
                    std::to_string(d.range.end) + ") of " + std::to_string(size) + " bytes: " + d.message;
      return out;
    }
    for (const DiagNote& n : d.notes)
      if (n.loc.valid() && n.loc.offset > sources.text(n.loc.file).size())
        out.problem = "note outside its buffer: " + n.message;
  }
  std::ostringstream sink;
  print_text(diags, sink);
  print_json(diags, sink);
  if (spec && !diags.has_errors()) out.canonical = spec->canonical_text();
  return out;
}

}  // namespace

/// One input; returns a description of the first violated property, or "". `fixpoint`, if given, says
/// whether the input resolved and went through the whole parse -> resolve -> dump fixpoint check.
std::string fuzz_front_end_one(const uint8_t* data, size_t size, bool* fixpoint) {
  if (fixpoint) *fixpoint = false;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const Outcome first = run_once(text);
  if (!first.problem.empty() || first.canonical.empty()) return first.problem;
  const Json parsed = Json::parse(first.canonical, nullptr, false);
  if (parsed.is_discarded()) return "canonical text is not JSON";
  const auto back = spec_from_json(parsed);
  if (!back) return "spec_from_json rejects the canonical JSON";
  if (back->canonical_text() != first.canonical) return "canonical JSON is not a fixpoint";
  if (parsed.at("sha256") != back->sha256()) return "hash of the re-read Spec differs";
  const Outcome second = run_once(text);
  if (second.canonical != first.canonical) return "two runs give different canonical JSON";
  if (fixpoint) *fixpoint = true;
  return {};
}

}  // namespace kage

#ifdef KAGE_FUZZ_MAIN
namespace {
size_t g_fixpoints = 0;
// run_fuzz.sh reads this line and fails when no input reached the fixpoint.
void report_fixpoints() { std::fprintf(stderr, "fuzz_front_end: %zu inputs reached the fixpoint\n", g_fixpoints); }
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::atexit(report_fixpoints);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  bool fixpoint = false;
  const std::string problem = kage::fuzz_front_end_one(data, size, &fixpoint);
  g_fixpoints += fixpoint;
  if (!problem.empty()) {
    std::fprintf(stderr, "fuzz_front_end: %s\n", problem.c_str());
    std::abort();
  }
  return 0;
}
#endif
