// Codegen: fills templates/*.in with the lowered parameters as named initialisers. The templates hold
// only includes, the config type and the instantiations; every decision was made by lowering.
#include "compiler/codegen/codegen.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <type_traits>

#include "compiler/basic/internal_error.h"
#include "compiler/codegen/build.h"
#include "compiler/lower/lower.h"
#include "fileio/sha256.h"

namespace kage {

namespace {

template <class T>
std::vector<uint32_t> words_of(T p) {
  static_assert(sizeof(T) % 4 == 0, "parameter structs are made of 4-byte words");
  // Padding bytes are whatever lowering left there: zero, since it value-initializes the structs and
  // only assigns members. __builtin_clear_padding is not used: GCC 12 clears bytes of
  // VisualParams::bg_colors[2] with it (3-byte Rgb array elements), turning red (220,20,60) into (0,0,60).
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &p, sizeof(T));
  std::vector<uint32_t> w(sizeof(T) / 4);
  for (size_t i = 0; i < w.size(); ++i) {
    w[i] = static_cast<uint32_t>(bytes[4 * i]) | static_cast<uint32_t>(bytes[4 * i + 1]) << 8 |
           static_cast<uint32_t>(bytes[4 * i + 2]) << 16 | static_cast<uint32_t>(bytes[4 * i + 3]) << 24;
  }
  return w;
}

/// A float as a literal that any conforming compiler reads back bit for bit: its exact decimal
/// expansion where that is short (0.5f, -7.5f, 490.0f), else hex (0x1.333334p-2f) with the shortest
/// decimal that rounds to it as the note (0.3). Non-finite values are spelled by their bits.
std::string float_literal(float v, std::string& note) {
  char buf[160];
  if (!std::isfinite(v)) {
    note = std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
    std::snprintf(buf, sizeof buf, "__builtin_bit_cast(float, 0x%08xu)", std::bit_cast<uint32_t>(v));
    return buf;
  }
  char exact[160];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  std::snprintf(exact, sizeof exact, "%.120g", v);  // glibc prints a float's expansion exactly
  std::string literal;
  if (std::strcmp(buf, exact) == 0) {
    literal = buf;
    if (literal.find_first_of(".e") == std::string::npos) literal += ".0";
  } else {
    std::snprintf(buf, sizeof buf, "%a", v);
    literal = buf;
    char shortest[32];
    const auto r = std::to_chars(shortest, shortest + sizeof shortest, v);
    note.assign(shortest, r.ptr);
  }
  literal += 'f';
  const float back = std::strtof(literal.c_str(), nullptr);
  KAGE_INTERNAL_ASSERT(std::bit_cast<uint32_t>(back) == std::bit_cast<uint32_t>(v),
                       "float literal " + literal + " does not read back as its value");
  return literal;
}

/// A value as a C++ initialiser; `type` is its spelling in the parameter list, `note` collects what the
/// literal alone does not say (a float's decimal, an enum value's config name).
std::string literal(const char*, int32_t v, std::string&) { return std::to_string(v); }
std::string literal(const char*, bool v, std::string&) { return v ? "true" : "false"; }
std::string literal(const char*, float v, std::string& note) { return float_literal(v, note); }
std::string literal(const char*, Rgb c, std::string&) {
  return "{" + std::to_string(c.r) + ", " + std::to_string(c.g) + ", " + std::to_string(c.b) + "}";
}
template <class E>
  requires std::is_enum_v<E>
std::string literal(const char* type, E v, std::string& note) {
  note = config_name(v);
  return std::string(type) + "(" + std::to_string(static_cast<int32_t>(v)) + ")";
}

/// A fixed-size list up to its last non-zero entry and at least its first (a zero entry can mean
/// something: ShapeType(0) is a circle); the rest is zero, as the initialiser leaves it.
template <class T, size_t N>
std::string literal(const char* type, const T (&list)[N], std::string& note) {
  size_t n = N;
  const T zero{};
  while (n > 1 && std::memcmp(&list[n - 1], &zero, sizeof(T)) == 0) --n;
  std::string out = "{";
  for (size_t i = 0; i < n; ++i) {
    std::string entry_note;
    out += (i ? ", " : "") + literal(type, list[i], entry_note);
    if (!entry_note.empty()) note += (note.empty() ? "" : ", ") + entry_note;
  }
  return out + "}";
}

/// One designated initialiser per member, in the order of the parameter list (.def), one per line:
/// `.gravity = 0.75f,` with a trailing `// note` where the literal needs one.
class Initialisers {
 public:
  template <class T>
  void add(const char* name, const char* type, const T& value) {
    std::string note;
    text_ += "      ." + std::string(name) + " = " + literal(type, value, note) + ",";
    if (!note.empty()) text_ += "  // " + note;
    text_ += '\n';
  }
  std::string text() const { return text_.substr(0, text_.size() - 1); }

 private:
  std::string text_;
};

std::string initialisers(const LatentParams& p) {
  Initialisers out;
#define KAGE_PARAM(type, name) out.add(#name, #type, p.name);
#include "runtime/latent/latent_params.def"
#undef KAGE_PARAM
  return out.text();
}

std::string initialisers(const VisualParams& p) {
  Initialisers out;
#define KAGE_PARAM(type, name) out.add(#name, #type, p.name);
#define KAGE_PARAM_ARRAY(type, name, count) out.add(#name, #type, p.name);
#include "runtime/visual/visual_params.def"
#undef KAGE_PARAM_ARRAY
#undef KAGE_PARAM
  return out.text();
}

/// Replaces every @NAME@ of `text`; a placeholder without a value is a compiler bug.
std::string fill(std::string_view text, const std::vector<std::pair<std::string, std::string>>& values) {
  std::string out;
  size_t i = 0;
  while (i < text.size()) {
    const size_t at = text.find('@', i);
    if (at == std::string_view::npos) break;
    const size_t end = text.find('@', at + 1);
    KAGE_INTERNAL_ASSERT(end != std::string_view::npos, "unterminated template placeholder");
    const std::string_view name = text.substr(at + 1, end - at - 1);
    const std::string* value = nullptr;
    for (const auto& [k, v] : values)
      if (k == name) value = &v;
    KAGE_INTERNAL_ASSERT(value != nullptr, "template placeholder without a value: " + std::string(name));
    out.append(text.substr(i, at - i));
    out += *value;
    i = end + 1;
  }
  out.append(text.substr(i));
  return out;
}

/// A template's text without its trailing newline (sections are spliced into a line of their own).
std::string_view chomp(std::string_view s) { return s.ends_with('\n') ? s.substr(0, s.size() - 1) : s; }

}  // namespace

std::vector<uint32_t> param_words(const LatentParams& p) { return words_of(p); }
std::vector<uint32_t> param_words(const VisualParams& p) { return words_of(p); }

std::string template_hash() {
  std::string all;
  for (const auto& [name, text] : {std::pair<const char*, const std::string*>{"kernels.cu.in", &kernels_cu_template_text()},
                                   {"latent_section.inc.in", &latent_section_inc_template_text()}}) {
    all += name;
    all += '\0';
    all += std::to_string(text->size());
    all += '\0';
    all += *text;
  }
  return sha256_hex(all);
}

std::string generate_latent_section(const LatentParams& p) {
  return fill(chomp(latent_section_inc_template_text()), {{"LATENT_FIELDS", initialisers(p)}});
}

std::string generated_file_name(const std::string& spec_hash) { return "kage_" + spec_hash.substr(0, 16) + ".cu"; }

GeneratedSource generate_source(const CodegenInput& in) {
  KAGE_INTERNAL_ASSERT(in.spec_hash.size() == 64, "codegen needs the 64-digit spec hash");
  GeneratedSource g;
  const std::string short_hash = in.spec_hash.substr(0, 16);
  g.file_name = generated_file_name(in.spec_hash);
  g.config_name = "KageConfig_" + short_hash;
  g.latent_section = generate_latent_section(in.latent);
  g.latent_hash = sha256_hex(g.latent_section);
  g.template_hash = template_hash();
  g.text = fill(kernels_cu_template_text(), {
                                             {"FILE_NAME", g.file_name},
                                             {"CODEGEN_VERSION", std::to_string(kCodegenVersion)},
                                             {"SPEC_HASH", in.spec_hash},
                                             {"TEMPLATE_HASH", g.template_hash},
                                             {"LATENT_HASH", g.latent_hash},
                                             {"NVCC_FLAGS", join_flags(nvcc_flags())},
                                             {"HOST_FLAGS", join_flags(host_flags())},
                                             {"LATENT_BYTES", std::to_string(sizeof(LatentParams))},
                                             {"VISUAL_BYTES", std::to_string(sizeof(VisualParams))},
                                             {"CONFIG_NAME", g.config_name},
                                             {"LATENT_SECTION", g.latent_section},
                                             {"VISUAL_FIELDS", initialisers(in.visual)},
                                         });
  return g;
}

}  // namespace kage
