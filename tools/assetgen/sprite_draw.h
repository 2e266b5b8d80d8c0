// Pixel-art character drawing for kage_assetgen: a parametric front-view
// figure (humans, robot), a skeleton and a dog, each with walking poses.
#pragma once

#include <cstdint>

#include "tools/assetgen/assetgen.h"

namespace kage::assetgen {

/// An 8-bit RGBA colour.
struct Px {
  uint8_t r = 0, g = 0, b = 0, a = 0;
};

enum class Hair { kNone, kShort, kLong, kBob, kPigtails, kAfro, kBun, kSpiky, kMessy };
enum class Hat { kNone, kCowboy, kFedora, kWizard, kHelmet, kHorned, kHood, kCap, kStraw, kHeadband, kAntenna };
enum class Face { kPlain, kGlasses, kShades, kMask, kClown, kBeard, kVisor };
enum class Top { kPlain, kVest, kOveralls, kDots, kSplit, kLabCoat, kStar, kTie, kPanel, kRobe };
enum class Lower { kPants, kShorts, kSkirt, kLong };
enum class Item { kNone, kSword, kStaff, kShield, kAxe, kPitchfork, kBag, kBalloon };
enum class Body { kHuman, kChibi, kSkeleton, kDog };

/// Everything that makes one skin look like its name.
struct Look {
  Body body = Body::kHuman;
  Px skin{236, 188, 150, 255};
  Px hair{90, 56, 30, 255};
  Hair hair_style = Hair::kShort;
  Hat hat = Hat::kNone;
  Px hat_color{0, 0, 0, 255};
  Px hat_trim{200, 40, 40, 255};
  Face face = Face::kPlain;
  Px eyes{30, 30, 40, 255};
  Top top = Top::kPlain;
  Px top_color{60, 90, 200, 255};
  Px top_color2{240, 240, 240, 255};
  Lower lower = Lower::kPants;
  Px lower_color{50, 60, 110, 255};
  Px shoes{70, 45, 30, 255};
  bool cape = false;
  Px cape_color{120, 20, 30, 255};
  Item item = Item::kNone;
  Px item_color{190, 195, 205, 255};
  Px glow{120, 200, 255, 128};
  Px outline{28, 22, 30, 255};
  int top_offset = 0;  ///< rows shorter than a full 24-row figure
  bool crop = false;   ///< trim transparent columns/rows (bottom row kept)
  bool glow_eyes = false;  ///< eyes in `eyes` colour with a `glow` halo
};

/// Draws frame `pose` (0 = left stride, 1 = passing, 2 = right stride) of `look`.
Image draw_figure(const Look& look, int pose);

}  // namespace kage::assetgen
