// Diff and certification of a train/eval pair of Specs.
//
// A change is a key whose effective value differs (a setting inert on both
// sides is no change; asset keys compare by content hash). A pair certifies
// when it changes exactly one visual axis (plus explicitly allowed ones) and
// no latent key.
#pragma once

#include <iosfwd>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "compiler/sema/schema.h"
#include "compiler/sema/spec.h"

namespace kage {

struct Change {
  std::string path;
  Axis axis;
  Json train;
  Json eval;
};

struct SpecDiff {
  std::vector<Change> changes;  // by axis, then path
  std::set<Axis> axes() const;
};

SpecDiff diff_specs(const Spec& train, const Spec& eval, const Schema& schema);

/// An extra axis a suite allows a pair to change, with the reason.
struct Allowance {
  Axis axis;
  std::string reason;
};

struct Certification {
  bool certified = false;
  std::optional<Axis> declared;
  std::set<Axis> measured;
  std::vector<std::string> problems;  // why it failed; empty when certified
  std::vector<Allowance> used_allowances;
};

/// Checks the single-axis rule; `declared` unset means "any one visual axis".
Certification certify(const SpecDiff& diff, std::optional<Axis> declared, const std::vector<Allowance>& allowed);

struct PairIdentity {
  std::string name;    // file or pair name
  std::string sha256;  // spec hash
};

/// The JSON certificate: both identities and hashes, the changes and the verdict.
Json certificate_json(const PairIdentity& train, const PairIdentity& eval, const SpecDiff& diff,
                      const Certification& cert);

/// Human report: changes grouped by axis.
void print_diff(const SpecDiff& diff, std::ostream& out);

/// "background, agent" style list.
std::string axes_text(const std::set<Axis>& axes);

}  // namespace kage
