// Context lints: warnings that need resolved values (inert settings, the
// original's surprising quirks, the partial-section default trap).
#pragma once

#include "compiler/basic/diag.h"
#include "compiler/parse/compose.h"
#include "compiler/sema/schema.h"
#include "compiler/sema/spec.h"

namespace kage {

/// Warns about keys written in `config.file` itself (not inherited) that are
/// inert or quirky, and about sections whose absent keys get surprising defaults.
void run_context_lints(const ComposedConfig& config, const Schema& schema, const Spec& spec, DiagEngine& diags);

}  // namespace kage
