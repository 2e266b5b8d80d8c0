// Schema check: a composed document against the key table, value by value.
//
// Reports unknown keys (did-you-mean, "belongs under"), wrong types, unknown
// names, ranges, non-finite numbers, empty lists, conflicting alternatives and
// min > max pairs. Never stops at the first error.
#pragma once

#include "compiler/basic/diag.h"
#include "compiler/parse/compose.h"
#include "compiler/sema/schema.h"

namespace kage {

/// Checks every key and value of `config`; true when no error was added.
bool check_config(const ComposedConfig& config, const Schema& schema, DiagEngine& diags);

/// Checks one value against a key's schema (used by check_config and the suite loader).
void check_value(const KeySchema& key, const DocNode& value, DiagEngine& diags);

}  // namespace kage
