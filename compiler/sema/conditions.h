// Evaluation of the schema's `x-kage-inert-when` conditions over resolved values.
#pragma once

#include <optional>
#include <string>

#include "compiler/sema/schema.h"

namespace kage {

struct Spec;

/// If the key is inert in `spec`, a short reason ("background.mode is 'black'"); else nullopt.
std::optional<std::string> inert_reason(const KeySchema& key, const Spec& spec);

}  // namespace kage
