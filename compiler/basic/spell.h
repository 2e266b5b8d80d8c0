// Did-you-mean: the closest legal name to a misspelt one.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace kage {

/// Edit distance (insert, delete, substitute, transpose two adjacent characters: each one edit),
/// optionally ignoring case.
size_t edit_distance(const std::string& a, const std::string& b, bool ignore_case);

/// The unique best candidate within min(3, max(1, len/3)) edits, case-insensitive
/// matches first; nullopt when none is close enough or two tie.
std::optional<std::string> suggest(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace kage
