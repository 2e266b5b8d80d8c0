// Context lints over a resolved Spec.
#include "compiler/sema/lints.h"

#include <cmath>

#include "compiler/basic/internal_error.h"
#include "compiler/sema/conditions.h"
#include "compiler/sema/resolve.h"

namespace kage {

namespace {

void quirk_warning(const KeySchema& k, const DocEntry& e, DiagEngine& diags) {
  const RuleInfo* rule = find_rule(k.quirk_rule);
  KAGE_INTERNAL_ASSERT(rule != nullptr, "schema quirk rule '" + k.quirk_rule + "' is not in diag_rules.def");
  diags.report(rule->rule, e.key_range, "'" + k.path + "': " + k.quirk_message, k.pointer);
}

}  // namespace

void run_context_lints(const ComposedConfig& config, const Schema& schema, const Spec& spec, DiagEngine& diags) {
  for (const KeySchema& k : schema.keys()) {
    const DocEntry* e = find_key_entry(config.root, k);
    if (!e || e->key_range.begin.file != config.file) continue;
    // A legacy alias is judged by the modern key it feeds.
    const KeySchema* modern = k.alias_of.empty() ? &k : schema.find(k.section + "." + k.alias_of);
    const KeySchema& effective = modern ? *modern : k;
    const auto reason = inert_reason(effective, spec);
    const bool always_inert = k.inert_when.is_array() && k.inert_when.size() == 1 && k.inert_when[0].empty();
    // An inert value equal to its default is merely written out; only a real setting that does nothing is worth a word.
    const bool is_default = spec.value(effective.path) == effective.default_value;
    if (!k.quirk_rule.empty() && (!reason || always_inert)) {
      quirk_warning(k, *e, diags);
    } else if (reason && !is_default) {
      diags.report(Rule::InertSetting, e->key_range,
                   "'" + k.path + "' has no effect in this configuration because " + *reason +
                       "; remove it or change that setting",
                   k.pointer);
    }
  }
  // A present-but-partial section takes dataclass defaults, not the whole-section ones (spec 1.8, 11.4).
  for (const KeySchema& k : schema.keys()) {
    if (k.absent_section_of.empty()) continue;
    const DocEntry* sec = config.root.find(k.section);
    if (!sec || !sec->value.is_map() || find_key(config.root, k)) continue;
    const Json& of = spec.value(k.absent_section_of);
    if (!of.is_number() || !k.default_value.is_number()) continue;
    const double whole = std::llround(of.get<double>() * k.absent_section_scale);
    if (whole == k.default_value.get<double>()) continue;
    diags.report(Rule::QuirkPartialLayout, sec->key_range,
                 "'" + k.section + "' is given without '" + k.name + "', so " + k.name + " is " +
                     k.default_value.dump() + " (the default), not " + std::to_string(static_cast<long long>(whole)) +
                     " as when the whole section is absent; set '" + k.path + "' explicitly",
                 "/" + k.section);
  }
}

}  // namespace kage
