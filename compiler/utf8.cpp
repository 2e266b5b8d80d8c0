#include "compiler/utf8.h"

namespace kage {

namespace {

// Length of the sequence a lead byte starts, or 0 for a byte that cannot lead.
size_t sequence_length(unsigned char lead) {
  if (lead < 0x80) return 1;
  if ((lead >> 5) == 0x6) return lead < 0xC2 ? 0 : 2;  // C0, C1 only start overlong forms
  if ((lead >> 4) == 0xE) return 3;
  if ((lead >> 3) == 0x1E) return lead > 0xF4 ? 0 : 4;  // beyond U+10FFFF
  return 0;
}

}  // namespace

std::optional<size_t> invalid_utf8_offset(const std::string& text) {
  size_t i = 0;
  while (i < text.size()) {
    const auto c = static_cast<unsigned char>(text[i]);
    const size_t len = sequence_length(c);
    if (len == 0 || i + len > text.size()) return i;
    for (size_t k = 1; k < len; ++k)
      if ((static_cast<unsigned char>(text[i + k]) & 0xC0) != 0x80) return i;
    const auto c1 = len > 1 ? static_cast<unsigned char>(text[i + 1]) : 0;
    if (len == 3 && ((c == 0xE0 && c1 < 0xA0) || (c == 0xED && c1 >= 0xA0))) return i;  // overlong, surrogate
    if (len == 4 && ((c == 0xF0 && c1 < 0x90) || (c == 0xF4 && c1 >= 0x90))) return i;  // overlong, too large
    i += len;
  }
  return std::nullopt;
}

std::vector<std::string> utf8_characters(const std::string& text) {
  std::vector<std::string> out;
  for (size_t i = 0; i < text.size();) {
    // Malformed bytes (never in a checked file) stay single bytes rather than swallowing neighbours.
    size_t len = sequence_length(static_cast<unsigned char>(text[i]));
    if (len == 0 || i + len > text.size()) len = 1;
    out.push_back(text.substr(i, len));
    i += len;
  }
  return out;
}

}  // namespace kage
