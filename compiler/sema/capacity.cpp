// Capacity checks against the runtime's storage bounds (see capacity.h).
#include "compiler/sema/capacity.h"

#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>

#include "compiler/basic/internal_error.h"
#include "compiler/sema/resolve.h"
#include "compiler/sema/schema.h"

namespace kage {

namespace {

constexpr double kNoBound = std::numeric_limits<double>::infinity();

/// The runtime's storage bounds, by the id the schema's `x-kage-capacity` names.
struct CapacityLimit {
  const char* id;
  double lo;
  double hi;
};

const CapacityLimit kCapacityLimits[] = {
    {"positive", 1, kNoBound},
    {"image_side", 1, RuntimeCapacity::kImageSide},
    {"world_width", 1, RuntimeCapacity::kWorldWidth},
    {"non_negative", 0, kNoBound},
    {"segment_byte", 0, 255},
    {"npc_slots", 0, RuntimeCapacity::kNpcSlots},
    {"sticky_slots", 0, RuntimeCapacity::kStickySlots},
    {"distractor_slots", -kNoBound, RuntimeCapacity::kDistractorSlots},
    {"sticky_offsets", 0, RuntimeCapacity::kStickyOffsets},
    {"list_entries", 0, RuntimeCapacity::kListEntries},
};

const CapacityLimit* find_capacity_limit(const std::string& id) {
  for (const CapacityLimit& l : kCapacityLimits)
    if (id == l.id) return &l;
  return nullptr;
}

const CapacityLimit& capacity_limit(const std::string& id) {
  if (const CapacityLimit* l = find_capacity_limit(id)) return *l;
  internal_error("schema names unknown capacity limit '" + id + "'", __FILE__, __LINE__);
}

/// A number, or the length of a list; nullopt for anything else (null, strings).
std::optional<double> measure(const Json& v) {
  if (v.is_array()) return static_cast<double>(v.size());
  if (v.is_number()) return v.get<double>();
  return std::nullopt;
}

std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

std::vector<CapacityError> capacity_errors(const Spec& spec) {
  std::vector<CapacityError> out;
  // Every integer is narrowed to int32 by the lowering, inert or not: one that does not fit would wrap.
  for (const KeySchema& k : config_schema().keys()) {
    if (k.ctype != "int" && k.ctype != "int?" && k.ctype != "int_list") continue;
    const Json& v = spec.value(k.path);
    for (const Json& x : v.is_array() ? v : Json::array({v})) {
      if (!x.is_number_integer()) continue;
      const bool fits = x.is_number_unsigned() ? x.get<uint64_t>() <= uint64_t(INT32_MAX)
                                               : x.get<int64_t>() >= INT32_MIN && x.get<int64_t>() <= INT32_MAX;
      if (fits) continue;
      out.push_back(CapacityError{k.path, "is " + x.dump() + ", which does not fit the runtime's 32-bit integers (" +
                                              std::to_string(INT32_MIN) + ".." + std::to_string(INT32_MAX) +
                                              "); use a smaller value"});
      break;
    }
  }
  for (const KeySchema& k : config_schema().keys()) {
    if (k.capacity_limit.empty() || spec.inert.count(k.path)) continue;
    const CapacityLimit& r = capacity_limit(k.capacity_limit);
    std::optional<double> v = measure(spec.value(k.path));
    if (!v) continue;
    if (!k.capacity_minus.empty()) {
      const std::optional<double> m = measure(spec.value(k.capacity_minus));
      if (!m) continue;
      *v -= *m;
    }
    if (*v >= r.lo && *v <= r.hi) continue;
    const std::string lo = format_number(r.lo), hi = format_number(r.hi);
    const std::string& what = k.capacity_what;
    std::string msg;
    if (spec.value(k.path).is_array()) {
      msg = "has " + format_number(*v) + " entries, but the runtime holds at most " + hi + "; shorten the list";
    } else if (!k.capacity_minus.empty()) {
      msg = "minus '" + k.capacity_minus + "' is " + format_number(*v) + ", but the runtime holds a " + what + " of " +
            lo + ".." + hi + "; bring the two closer";
    } else if (*v > r.hi) {
      msg = "is " + format_number(*v) + ", but the runtime holds at most " + hi + " " + what + "; set it to " + hi +
            " or less";
    } else {
      msg = "is " + format_number(*v) + ", but the " + what + " must be at least " + lo + "; set it to " + lo +
            " or more";
    }
    out.push_back(CapacityError{k.path, msg});
  }
  return out;
}

void report_capacity(const ComposedConfig& config, const Spec& spec, DiagEngine& diags) {
  const Schema& schema = config_schema();
  for (const CapacityError& e : capacity_errors(spec)) {
    const KeySchema* key = schema.find(e.path);
    const DocEntry* entry = key ? find_key_entry(config.root, *key) : nullptr;
    const Range at = entry ? entry->key_range : config.root.range;
    diags.report(Rule::CapacityExceeded, at, "'" + e.path + "' " + e.message, key ? key->pointer : std::string());
  }
}

bool capacity_limit_known(const std::string& id) { return find_capacity_limit(id) != nullptr; }

}  // namespace kage
