#include "compiler/basic/utf8.h"

namespace kage {

namespace {

// Length of the well-formed UTF-8 sequence at text[i], or 0 when the byte there starts none.
size_t sequence_at(const std::string& text, size_t i) {
  const auto c = static_cast<unsigned char>(text[i]);
  size_t len = 0;
  if (c < 0x80) return 1;
  if ((c >> 5) == 0x6 && c >= 0xC2) len = 2;  // C0, C1 only start overlong forms
  if ((c >> 4) == 0xE) len = 3;
  if ((c >> 3) == 0x1E && c <= 0xF4) len = 4;  // beyond F4 lies past U+10FFFF
  if (len == 0 || i + len > text.size()) return 0;
  for (size_t k = 1; k < len; ++k)
    if ((static_cast<unsigned char>(text[i + k]) & 0xC0) != 0x80) return 0;
  const auto c1 = static_cast<unsigned char>(text[i + 1]);
  if (len == 3 && ((c == 0xE0 && c1 < 0xA0) || (c == 0xED && c1 >= 0xA0))) return 0;  // overlong, surrogate
  if (len == 4 && ((c == 0xF0 && c1 < 0x90) || (c == 0xF4 && c1 >= 0x90))) return 0;  // overlong, too large
  return len;
}

}  // namespace

std::optional<size_t> invalid_utf8_offset(const std::string& text) {
  for (size_t i = 0; i < text.size();) {
    const size_t len = sequence_at(text, i);
    if (len == 0) return i;
    i += len;
  }
  return std::nullopt;
}

std::string utf8_from_latin1_strays(const std::string& text) {
  if (!invalid_utf8_offset(text)) return text;
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const size_t len = sequence_at(text, i);
    if (len > 0) {
      out.append(text, i, len);
      i += len;
      continue;
    }
    const auto byte = static_cast<unsigned char>(text[i++]);
    out += static_cast<char>(0xC0 | (byte >> 6));
    out += static_cast<char>(0x80 | (byte & 0x3F));
  }
  return out;
}

std::vector<std::string> utf8_characters(const std::string& text) {
  std::vector<std::string> out;
  for (size_t i = 0; i < text.size();) {
    // Malformed bytes (never in a checked file) stay single bytes rather than swallowing neighbours.
    size_t len = sequence_at(text, i);
    if (len == 0) len = 1;
    out.push_back(text.substr(i, len));
    i += len;
  }
  return out;
}

}  // namespace kage
