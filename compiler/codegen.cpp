// Codegen: fills templates/*.in with the lowered parameters' words. The templates hold only includes,
// the config type and the instantiations; every decision was made by lowering.
#include "compiler/codegen.h"

#include <cstdio>
#include <cstring>
#include <string_view>

#include "compiler/build.h"
#include "compiler/internal_error.h"
#include "runtime/host/sha256.h"

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

/// Words as hex literals, eight per line, indented for the initializer.
std::string format_words(const std::vector<uint32_t>& w) {
  std::string out;
  char buf[16];
  for (size_t i = 0; i < w.size(); ++i) {
    if (i % 8 == 0) out += i == 0 ? "      " : "\n      ";
    std::snprintf(buf, sizeof buf, "0x%08xu,", w[i]);
    out += buf;
    if (i % 8 != 7 && i + 1 != w.size()) out += ' ';
  }
  return out;
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
  const std::vector<uint32_t> w = param_words(p);
  return fill(chomp(latent_section_inc_template_text()),
              {{"LATENT_WORD_COUNT", std::to_string(w.size())}, {"LATENT_WORDS", format_words(w)}});
}

GeneratedSource generate_source(const CodegenInput& in) {
  KAGE_INTERNAL_ASSERT(in.spec_hash.size() == 64, "codegen needs the 64-digit spec hash");
  GeneratedSource g;
  const std::string short_hash = in.spec_hash.substr(0, 16);
  g.file_name = "kage_" + short_hash + ".cu";
  g.config_name = "KageConfig_" + short_hash;
  g.latent_section = generate_latent_section(in.latent);
  g.latent_hash = sha256_hex(g.latent_section);
  g.template_hash = template_hash();
  const std::vector<uint32_t> vw = param_words(in.visual);
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
                                             {"VISUAL_WORD_COUNT", std::to_string(vw.size())},
                                             {"VISUAL_WORDS", format_words(vw)},
                                         });
  return g;
}

}  // namespace kage
