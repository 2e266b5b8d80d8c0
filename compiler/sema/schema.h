// The configuration schema as a table: one entry per key, read from
// schemas/kage-config.schema.json (embedded at build time). Passes that need to
// know about keys ask this table; the only other lists of keys are generated
// from the same schema (compiler/generated/spec_fields.h) or name the asset
// groups (key_refs.h).
#pragma once

#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "compiler/generated/spec_fields.h"

namespace kage {

using Json = nlohmann::json;

/// The benchmark axes, in the schema's order (definitions/axisName, through the generated
/// KAGE_SCHEMA_AXES). Latent keys change the hidden game; the others only its look.
enum class Axis {
#define KAGE_AXIS(Id, name) Id,
  KAGE_SCHEMA_AXES(KAGE_AXIS)
#undef KAGE_AXIS
};

const char* axis_name(Axis axis);
std::optional<Axis> parse_axis(const std::string& name);
/// The six visual axes, in the benchmark's order.
const std::vector<Axis>& visual_axes();

/// A named table of the schema's `definitions` (colour palettes, shape types, presets).
struct NameTable {
  std::string id;                                  // e.g. "shapeColorName"
  std::string title;                               // e.g. "shape colour"
  std::vector<std::string> names;                  // in source order
  std::map<std::string, std::array<int, 3>> rgb;   // empty unless the table has colours
};

/// Constraints on one value (a leaf, or the items of a list leaf).
struct ValueRule {
  std::set<std::string> types;  // JSON types: integer, number, boolean, string, array, null
  const NameTable* names = nullptr;
  std::optional<double> minimum, maximum, exclusive_minimum;
};

/// One configuration key.
struct KeySchema {
  std::string section;  // "" for root keys
  std::string name;
  std::string path;     // dotted: physics.gravity
  std::string pointer;  // JSON Pointer: /physics/gravity
  std::string ctype;
  std::string description;
  Axis axis = Axis::Latent;
  ValueRule value;
  std::optional<ValueRule> items;  // for lists
  std::optional<size_t> min_items, max_items;
  bool string_as_list = false;      // "name or list of names"
  bool string_is_characters = false;  // a string is read as a list of characters (quirk)
  std::optional<double> recommended_min, recommended_max;
  Json default_value;
  Json yaml_default;  // null when the key is not in the original default_config.yaml
  bool in_default_yaml = false;
  std::string alias_of;  // legacy key: the modern key's name
  std::string absent_section_of;  // root key this default scales when the section is absent
  double absent_section_scale = 1;
  std::string observation;  // "height" or "width": a side of the observation image (x-kage-observation), else empty
  std::string asset_kind;  // file, dir, file_list, dir_list, skin_parent, image_dir
  Json inert_when;         // list of condition objects, or null
  std::string quirk_rule, quirk_message;
  // A bound of the runtime's fixed storage (x-kage-capacity); empty limit when none.
  std::string capacity_limit, capacity_what, capacity_minus;
};

struct SectionSchema {
  std::string name;  // "" for the root
  std::vector<size_t> keys;  // indices into Schema::keys
  std::vector<std::vector<std::string>> exclusive;
  bool exclusive_counts_empty = false;  // an empty list counts as given (spec 2.3)
  std::vector<std::pair<std::string, std::string>> ordered;
  std::vector<std::pair<std::string, std::string>> one_true;  // if both are given, exactly one is true
};

class Schema {
 public:
  /// Builds the table from schema JSON; aborts with an internal error if the schema is malformed.
  static Schema from_json(const Json& doc);

  const std::vector<KeySchema>& keys() const { return keys_; }
  const std::vector<SectionSchema>& sections() const { return sections_; }
  const KeySchema* find(const std::string& path) const;
  const SectionSchema* section(const std::string& name) const;
  const NameTable* table(const std::string& id) const;
  /// Sections that declare a key named `name` (for "belongs under ..." hints).
  std::vector<std::string> sections_with_key(const std::string& name) const;
  /// The meta keys (e.g. `extends`) that are allowed at the root but are not settings.
  const std::set<std::string>& meta_keys() const { return meta_keys_; }

 private:
  friend class SchemaLoader;
  std::vector<KeySchema> keys_;
  std::vector<SectionSchema> sections_;
  std::map<std::string, NameTable> tables_;
  std::set<std::string> meta_keys_;
  std::map<std::string, size_t> by_path_;
};

/// The configuration schema compiled into this binary.
const Schema& config_schema();
/// Its JSON text (for `kagec schema`).
const std::string& config_schema_text();
/// The suite manifest schema text.
const std::string& suite_schema_text();

}  // namespace kage
