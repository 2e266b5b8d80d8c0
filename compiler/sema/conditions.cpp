// Inert conditions: a list of alternatives, each a conjunction of key tests.
#include "compiler/sema/conditions.h"

#include "compiler/basic/internal_error.h"
#include "compiler/sema/spec.h"

namespace kage {

namespace {

bool is_empty(const Json& v) {
  return v.is_null() || (v.is_string() && v.get<std::string>().empty()) || (v.is_array() && v.empty());
}

bool equal(const Json& a, const Json& b) {
  if (a.is_number() && b.is_number()) return a.get<double>() == b.get<double>();
  return a == b;
}

bool test(const Json& value, const std::string& op, const Json& arg) {
  if (op == "eq") return equal(value, arg);
  if (op == "ne") return !equal(value, arg);
  if (op == "in" || op == "not_in") {
    bool found = false;
    for (const Json& a : arg) found = found || equal(value, a);
    return op == "in" ? found : !found;
  }
  if (op == "le") return value.is_number() && value.get<double>() <= arg.get<double>();
  if (op == "empty") return is_empty(value) == arg.get<bool>();
  internal_error("unknown condition test '" + op + "' in the schema", __FILE__, __LINE__);
}

std::string describe(const std::string& path, const Json& value, const std::string& op, const Json& arg) {
  if (op == "empty") return path + (arg.get<bool>() ? " is empty" : " is given");
  return path + " is " + value.dump();
}

}  // namespace

std::optional<std::string> inert_reason(const KeySchema& key, const Spec& spec) {
  if (!key.inert_when.is_array()) return std::nullopt;
  for (const Json& alternative : key.inert_when) {
    bool all = true;
    std::string why;
    for (auto& [path, tests] : alternative.items()) {
      const std::string target = path == "." ? key.path : path;
      const Json& v = spec.value(target);
      for (auto& [op, arg] : tests.items()) {
        if (!test(v, op, arg)) {
          all = false;
          break;
        }
        why += (why.empty() ? "" : " and ") + describe(target, v, op, arg);
      }
      if (!all) break;
    }
    if (all) return why.empty() ? std::string("the original never uses it") : why;
  }
  return std::nullopt;
}

}  // namespace kage
