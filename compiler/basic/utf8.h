// UTF-8 helpers: config files are UTF-8 text (as PyYAML requires), and the
// original iterates strings by code point.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace kage {

/// The offset of the first byte that does not belong to a well-formed UTF-8
/// sequence, or nullopt when the whole text is well-formed.
std::optional<size_t> invalid_utf8_offset(const std::string& text);

/// `text` with each byte that belongs to no well-formed UTF-8 sequence replaced by the UTF-8 form of
/// the code point of the same value. yaml-cpp writes the YAML escapes "\N" and "\_" (U+0085, U+00A0)
/// as the single bytes 0x85 and 0xA0; this restores them.
std::string utf8_from_latin1_strays(const std::string& text);

/// The characters (code points, each as its UTF-8 bytes) of well-formed text,
/// as Python's list(str) gives them.
std::vector<std::string> utf8_characters(const std::string& text);

}  // namespace kage
