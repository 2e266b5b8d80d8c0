// The few keys whose meaning the front end must know by name: the asset
// groups (which keys enable a group and which keys are its sources, in the
// original's precedence order, spec 2.4). Everything else comes from the
// schema; a test checks that every path here exists there.
#pragma once

#include <array>

namespace kage {

/// A set of assets that one switch enables and up to three keys provide.
struct AssetGroupRef {
  const char* name;          // key of the group in Spec::assets
  const char* enable_key;    // the group is loaded when this key equals enable_value
  const char* enable_value;  // "true" for booleans, else a string value
  std::array<const char*, 3> sources;  // in precedence order
  bool images;               // background images (files) rather than sprite skins (folders)
};

inline constexpr std::array<AssetGroupRef, 4> kAssetGroups = {{
    {"backgrounds", "background.mode", "image",
     {"background.image_paths", "background.image_dir", "background.image_path"}, true},
    {"agent_skins", "character.use_sprites", "true",
     {"character.sprite_dir", "character.sprite_paths", "character.sprite_path"}, false},
    {"npc_types", "npc.enabled", "true", {"npc.sprite_dir", "npc.sprite_paths", "npc.sprite_path"}, false},
    {"sticky_types", "npc.sticky_enabled", "true",
     {"npc.sticky_sprite_dir", "npc.sticky_sprite_dirs", "npc.sticky_sprite_path"}, false},
}};

}  // namespace kage
