// Draws one sprite frame: body layers on a 16x24 RGBA canvas, then a dark
// outline, semi-transparent shadow and glow pixels, then an optional crop.
#include "tools/assetgen/sprite_draw.h"

#include <algorithm>
#include <vector>

namespace kage::assetgen {
namespace {

constexpr int kW = 16;

class Sprite {
 public:
  Sprite(int w, int h) : w_(w), h_(h), px_(size_t(w) * h), glow_(size_t(w) * h) {}
  int w() const { return w_; }
  int h() const { return h_; }
  void set(int x, int y, Px c) {
    if (x >= 0 && y >= 0 && x < w_ && y < h_) px_[size_t(y) * w_ + x] = c;
  }
  void rect(int x0, int y0, int x1, int y1, Px c) {
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) set(x, y, c);
    }
  }
  void glow(int x, int y, Px c) {
    if (x >= 0 && y >= 0 && x < w_ && y < h_) glow_[size_t(y) * w_ + x] = c;
  }
  const Px& at(int x, int y) const { return px_[size_t(y) * w_ + x]; }

  // Outline, then shadow on the bottom row, then glow, then crop.
  Image finish(Px outline, bool crop, int shadow_x0, int shadow_x1) const {
    std::vector<Px> out = px_;
    for (int y = 0; y < h_; ++y) {
      for (int x = 0; x < w_; ++x) {
        if (at(x, y).a != 0) continue;
        const bool edge = (x > 0 && at(x - 1, y).a) || (x + 1 < w_ && at(x + 1, y).a) ||
                          (y > 0 && at(x, y - 1).a) || (y + 1 < h_ && at(x, y + 1).a);
        if (edge) out[size_t(y) * w_ + x] = outline;
      }
    }
    for (int x = shadow_x0; x <= shadow_x1; ++x) {
      Px& p = out[size_t(h_ - 1) * w_ + x];
      if (p.a == 0) p = Px{10, 8, 20, 128};
    }
    for (size_t i = 0; i < out.size(); ++i) {
      if (out[i].a == 0 && glow_[i].a != 0) out[i] = glow_[i];
    }
    int x0 = 0, x1 = w_ - 1, y0 = 0;
    if (crop) {
      x0 = w_;
      x1 = -1;
      y0 = h_ - 1;
      for (int y = 0; y < h_; ++y) {
        for (int x = 0; x < w_; ++x) {
          if (out[size_t(y) * w_ + x].a == 0) continue;
          x0 = std::min(x0, x);
          x1 = std::max(x1, x);
          y0 = std::min(y0, y);
        }
      }
    }
    Image img{x1 - x0 + 1, h_ - y0, 4, {}};
    for (int y = y0; y < h_; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const Px& p = out[size_t(y) * w_ + x];
        img.pixels.insert(img.pixels.end(), {p.r, p.g, p.b, p.a});
      }
    }
    return img;
  }

 private:
  int w_, h_;
  std::vector<Px> px_;
  std::vector<Px> glow_;
};

Px shade(Px c, double f) {
  auto s = [f](uint8_t v) { return uint8_t(std::clamp(v * f, 0.0, 255.0)); };
  return Px{s(c.r), s(c.g), s(c.b), c.a};
}

constexpr Px kDark{30, 24, 34, 255};
constexpr Px kWhite{245, 245, 240, 255};

// Figure geometry; rows grow downward, the last row is the ground row.
struct Geo {
  int hx0, hx1, hy0, hy1;  // head box
  int tx0, tx1, ty0, ty1;  // torso box
  int ly0;                 // first leg row
  int eye_y, eye_h;
};

Geo geometry(const Look& look, int bob) {
  if (look.body == Body::kChibi) return Geo{3, 12, 1 + bob, 10 + bob, 5, 10, 12 + bob, 17, 18, 5 + bob, 2};
  const int t = look.top_offset;
  return Geo{5, 10, 3 + t + bob, 9 + t + bob, 5, 10, 11 + t + bob, 15 + t, 16 + t, 6 + t + bob, 1};
}

void draw_hair(Sprite& s, const Look& k, const Geo& g) {
  const Px c = k.hair;
  switch (k.hair_style) {
    case Hair::kNone: return;
    case Hair::kAfro:
      s.rect(g.hx0 - 2, g.hy0 - 2, g.hx1 + 2, g.hy0 + 1, c);
      s.rect(g.hx0 - 2, g.hy0 + 2, g.hx0 - 1, g.hy0 + 4, c);
      s.rect(g.hx1 + 1, g.hy0 + 2, g.hx1 + 2, g.hy0 + 4, c);
      return;
    default: break;
  }
  s.rect(g.hx0, g.hy0, g.hx1, g.hy0 + 1, c);
  s.rect(g.hx0 + 1, g.hy0 - 1, g.hx1 - 1, g.hy0 - 1, c);
  switch (k.hair_style) {
    case Hair::kLong:
      s.rect(g.hx0 - 1, g.hy0, g.hx0 - 1, g.ty0 + 2, c);
      s.rect(g.hx1 + 1, g.hy0, g.hx1 + 1, g.ty0 + 2, c);
      s.set(g.hx0, g.hy0 + 2, c);
      s.set(g.hx1, g.hy0 + 2, c);
      break;
    case Hair::kBob:
      s.rect(g.hx0 - 1, g.hy0, g.hx0 - 1, g.hy1 - 1, c);
      s.rect(g.hx1 + 1, g.hy0, g.hx1 + 1, g.hy1 - 1, c);
      break;
    case Hair::kPigtails:
      s.rect(g.hx0 - 2, g.hy0 + 2, g.hx0 - 1, g.hy0 + 4, c);
      s.rect(g.hx1 + 1, g.hy0 + 2, g.hx1 + 2, g.hy0 + 4, c);
      s.set(g.hx0 - 1, g.hy0 + 1, k.hat_trim);
      s.set(g.hx1 + 1, g.hy0 + 1, k.hat_trim);
      break;
    case Hair::kBun: s.rect(g.hx0 + 1, g.hy0 - 3, g.hx1 - 1, g.hy0 - 2, c); break;
    case Hair::kSpiky:
      for (int x = g.hx0; x <= g.hx1; x += 2) s.set(x, g.hy0 - 2, c);
      break;
    case Hair::kMessy:
      s.set(g.hx0 - 1, g.hy0 - 1, c);
      s.set(g.hx1 + 1, g.hy0 - 1, c);
      s.rect(g.hx0 - 1, g.hy0 + 1, g.hx0 - 1, g.hy0 + 3, c);
      s.rect(g.hx1 + 1, g.hy0 + 1, g.hx1 + 1, g.hy0 + 3, c);
      break;
    default: break;
  }
}

void draw_hat(Sprite& s, const Look& k, const Geo& g) {
  const Px c = k.hat_color, trim = k.hat_trim;
  const int y = g.hy0;
  switch (k.hat) {
    case Hat::kNone: break;
    case Hat::kCowboy:
      s.rect(g.hx0 - 2, y, g.hx1 + 2, y, c);
      s.rect(g.hx0, y - 2, g.hx1, y - 1, c);
      s.rect(g.hx0, y - 1, g.hx1, y - 1, trim);
      s.set(g.hx0 - 2, y - 1, c);
      s.set(g.hx1 + 2, y - 1, c);
      break;
    case Hat::kFedora:
      s.rect(g.hx0 - 1, y, g.hx1 + 1, y, c);
      s.rect(g.hx0, y - 2, g.hx1, y - 1, c);
      s.rect(g.hx0, y - 1, g.hx1, y - 1, trim);
      break;
    case Hat::kWizard:
      s.rect(g.hx0 - 2, y, g.hx1 + 2, y, c);
      s.rect(g.hx0, y - 1, g.hx1, y - 1, c);
      s.rect(g.hx0 + 1, y - 2, g.hx1 - 1, y - 2, c);
      s.rect(g.hx0 + 2, y - 3, g.hx1 - 1, y - 3, c);
      s.set(g.hx1, y - 3, c);
      s.set(g.hx0 + 2, y - 1, trim);
      s.set(g.hx1 - 1, y - 2, trim);
      break;
    case Hat::kHelmet:
    case Hat::kHorned:
      s.rect(g.hx0 - 1, y - 1, g.hx1 + 1, g.hy1, c);
      s.rect(g.hx0, y + 2, g.hx1, y + 3, trim);  // visor slit
      s.rect(g.hx0 + 2, y + 5, g.hx1 - 2, g.hy1, shade(c, 0.75));
      if (k.hat == Hat::kHorned) {
        s.rect(g.hx0 - 2, y - 2, g.hx0 - 2, y, kWhite);
        s.rect(g.hx1 + 2, y - 2, g.hx1 + 2, y, kWhite);
        s.set(g.hx0 - 3, y - 3, kWhite);
        s.set(g.hx1 + 3, y - 3, kWhite);
      } else {
        s.rect(g.hx0 + 2, y - 3, g.hx1 - 1, y - 2, k.cape_color);  // plume
      }
      break;
    case Hat::kHood:
      s.rect(g.hx0 - 1, y - 1, g.hx1 + 1, y + 1, c);
      s.rect(g.hx0 - 1, y + 2, g.hx0, g.hy1 + 1, c);
      s.rect(g.hx1, y + 2, g.hx1 + 1, g.hy1 + 1, c);
      break;
    case Hat::kCap:
      s.rect(g.hx0, y - 1, g.hx1, y, c);
      s.rect(g.hx1, y + 1, g.hx1 + 2, y + 1, trim);
      break;
    case Hat::kStraw:
      s.rect(g.hx0 - 3, y, g.hx1 + 3, y, c);
      s.rect(g.hx0, y - 2, g.hx1, y - 1, c);
      s.rect(g.hx0, y - 1, g.hx1, y - 1, trim);
      break;
    case Hat::kHeadband:
      s.rect(g.hx0, y + 1, g.hx1, y + 1, c);
      s.set(g.hx1 + 1, y + 2, c);
      s.set(g.hx1 + 2, y + 3, c);
      break;
    case Hat::kAntenna:
      s.rect(g.hx0 + 2, y - 3, g.hx0 + 2, y - 1, c);
      s.set(g.hx0 + 2, y - 4, trim);
      s.glow(g.hx0 + 1, y - 4, k.glow);
      s.glow(g.hx0 + 3, y - 4, k.glow);
      s.glow(g.hx0 + 2, y - 5, k.glow);
      break;
  }
}

void draw_face(Sprite& s, const Look& k, const Geo& g) {
  const int ey = g.eye_y, lx = g.hx0 + 1, rx = g.hx1 - 1;
  for (int dy = 0; dy < g.eye_h; ++dy) {
    s.set(lx, ey + dy, k.eyes);
    s.set(rx, ey + dy, k.eyes);
  }
  if (g.eye_h > 1) {
    s.set(lx, ey, kWhite);
    s.set(rx, ey, kWhite);
  }
  const int mid = (g.hx0 + g.hx1) / 2;
  switch (k.face) {
    case Face::kPlain: break;
    case Face::kGlasses:
      s.set(lx - 1, ey, kDark);
      s.set(lx + 1, ey, kDark);
      s.set(rx - 1, ey, kDark);
      s.set(rx + 1, ey, kDark);
      s.rect(lx, ey - 1, lx, ey - 1, kDark);
      s.rect(rx, ey - 1, rx, ey - 1, kDark);
      break;
    case Face::kShades: s.rect(g.hx0, ey, g.hx1, ey, Px{15, 15, 20, 255}); break;
    case Face::kMask:
      s.rect(g.hx0 - 1, ey, g.hx1 + 1, ey, Px{20, 20, 25, 255});
      s.set(lx, ey, kWhite);
      s.set(rx, ey, kWhite);
      s.rect(g.hx0, ey + 2, g.hx1, g.hy1, k.hat_color);
      break;
    case Face::kClown:
      s.rect(mid, ey + 1, mid + 1, ey + 2, Px{230, 20, 30, 255});
      s.rect(mid - 1, ey + 3, mid + 2, ey + 3, Px{200, 30, 60, 255});
      s.set(lx, ey - 1, Px{60, 90, 220, 255});
      s.set(rx, ey - 1, Px{60, 90, 220, 255});
      break;
    case Face::kBeard:
      s.rect(g.hx0, ey + 2, g.hx1, g.hy1, k.hair);
      s.rect(g.hx0 + 1, g.hy1 + 1, g.hx1 - 1, g.hy1 + 3, k.hair);
      s.rect(mid, g.hy1 + 4, mid + 1, g.hy1 + 4, k.hair);
      break;
    case Face::kVisor: s.rect(g.hx0, ey, g.hx1, ey, k.eyes); break;
  }
}

void draw_torso(Sprite& s, const Look& k, const Geo& g, int pose) {
  const Px a = k.top_color, b = k.top_color2;
  s.rect(g.tx0, g.ty0, g.tx1, g.ty1, a);
  const int mid = (g.tx0 + g.tx1) / 2;
  switch (k.top) {
    case Top::kPlain: break;
    case Top::kVest: s.rect(mid, g.ty0, mid + 1, g.ty1, b); break;
    case Top::kOveralls:
      s.rect(g.tx0 + 1, g.ty0, g.tx0 + 1, g.ty1, k.lower_color);
      s.rect(g.tx1 - 1, g.ty0, g.tx1 - 1, g.ty1, k.lower_color);
      s.rect(g.tx0 + 1, g.ty1 - 1, g.tx1 - 1, g.ty1, k.lower_color);
      break;
    case Top::kDots:
      for (int y = g.ty0; y <= g.ty1; ++y) {
        for (int x = g.tx0; x <= g.tx1; ++x) {
          if ((x + y) % 2 == 0) s.set(x, y, b);
        }
      }
      break;
    case Top::kSplit: s.rect(mid + 1, g.ty0, g.tx1, g.ty1, b); break;
    case Top::kLabCoat: s.rect(mid, g.ty0, mid + 1, g.ty1 - 1, b); break;
    case Top::kStar:
      s.set(g.tx0 + 1, g.ty0 + 1, Px{250, 210, 40, 255});
      s.rect(mid, g.ty0, mid + 1, g.ty1, b);
      break;
    case Top::kTie:
      s.set(mid, g.ty0, b);
      s.set(mid + 1, g.ty0, b);
      s.rect(mid, g.ty0 + 1, mid, g.ty1 - 1, k.hat_trim);
      break;
    case Top::kPanel:
      s.rect(g.tx0 + 1, g.ty0 + 1, g.tx1 - 1, g.ty0 + 2, shade(a, 0.55));
      s.set(g.tx0 + 1 + pose % 3, g.ty0 + 1, Px{240, 60, 60, 255});
      s.set(g.tx1 - 1, g.ty0 + 2, Px{80, 240, 120, 255});
      break;
    case Top::kRobe: s.rect(mid, g.ty0, mid + 1, g.ty1, b); break;
  }
  if (k.top != Top::kRobe && k.top != Top::kLabCoat && k.lower != Lower::kLong) {
    s.rect(g.tx0, g.ty1, g.tx1, g.ty1, shade(k.lower_color, 0.7));  // belt
  }
}

// Legs and shoes. Stride poses lift one foot and move the other outward.
void draw_legs(Sprite& s, const Look& k, const Geo& g, int pose) {
  const int ground = s.h() - 1;
  const Px leg = k.lower == Lower::kShorts ? k.skin : k.lower_color;
  for (int side = 0; side < 2; ++side) {
    const bool lifted = (pose == 0 && side == 1) || (pose == 2 && side == 0);
    const bool planted = (pose == 0 && side == 0) || (pose == 2 && side == 1);
    const int x = side == 0 ? g.tx0 : g.tx1 - 1;
    const int out = planted ? (side == 0 ? -1 : 1) : 0;
    const int foot = lifted ? ground - 1 : ground;
    const int knee = g.ly0 + (foot - g.ly0) / 2;
    s.rect(x, g.ly0, x + 1, knee, leg);
    s.rect(x + out, knee + 1, x + 1 + out, foot - 1, leg);
    if (k.lower == Lower::kShorts) s.rect(x, g.ly0, x + 1, g.ly0 + 1, k.lower_color);
    const int toe = side == 0 ? x - 1 + out : x + out;
    s.rect(toe, foot, toe + 2, foot, k.shoes);
  }
  if (k.lower == Lower::kSkirt || k.lower == Lower::kLong) {
    const int last = k.lower == Lower::kSkirt ? g.ly0 + 3 : ground - 2;
    for (int y = g.ly0; y <= last; ++y) {
      const int grow = std::min(2, (y - g.ly0 + 1) / 2);
      const int sway = (pose == 1 || y < last - 1) ? 0 : (pose == 0 ? -1 : 1);
      s.rect(g.tx0 - grow + sway, y, g.tx1 + grow + sway, y, k.lower_color);
    }
  }
  if (k.top == Top::kLabCoat) {
    for (int y = g.ly0; y <= g.ly0 + 3; ++y) {
      s.rect(g.tx0 - 1, y, g.tx0 + 1, y, k.top_color);
      s.rect(g.tx1 - 1, y, g.tx1 + 1, y, k.top_color);
    }
  }
}

void draw_arms(Sprite& s, const Look& k, const Geo& g, int pose, bool bones) {
  const Px sleeve = bones ? k.skin : k.top_color;
  for (int side = 0; side < 2; ++side) {
    const int x = side == 0 ? g.tx0 - 1 : g.tx1 + 1;
    const bool swing = (pose == 0 && side == 1) || (pose == 2 && side == 0);
    const int hand = swing ? g.ty1 : g.ty1 + 1;
    s.rect(x, g.ty0, x, hand - 1, sleeve);
    s.set(x, hand, k.skin);
  }
}

void draw_item(Sprite& s, const Look& k, const Geo& g, int pose) {
  const int hx = g.tx1 + 2, hy = g.ty1 + (pose == 2 ? 0 : 1);
  const Px c = k.item_color, wood{120, 78, 40, 255};
  switch (k.item) {
    case Item::kNone: break;
    case Item::kSword:
      s.rect(hx, hy - 7, hx, hy - 1, c);
      s.rect(hx - 1, hy, hx + 1, hy, Px{200, 160, 40, 255});
      s.set(hx, hy + 1, wood);
      break;
    case Item::kStaff:
      s.rect(hx, g.hy0, hx, s.h() - 2, wood);
      s.rect(hx - 1, g.hy0 - 2, hx + 1, g.hy0 - 1, c);
      for (int d = -2; d <= 2; ++d) {
        s.glow(hx + d, g.hy0 - 3, k.glow);
        s.glow(hx + d, g.hy0, k.glow);
        s.glow(hx - 2, g.hy0 - 2 + (d + 2) % 2, k.glow);
        s.glow(hx + 2, g.hy0 - 2 + (d + 2) % 2, k.glow);
      }
      break;
    case Item::kShield: {
      const int x0 = g.tx0 - 4, y0 = g.ty0 + 1;
      s.rect(x0, y0, x0 + 2, y0 + 4, c);
      s.rect(x0 + 1, y0 + 5, x0 + 1, y0 + 5, c);
      s.rect(x0 + 1, y0 + 1, x0 + 1, y0 + 3, k.hat_trim);
      break;
    }
    case Item::kAxe:
      s.rect(hx, hy - 6, hx, hy + 1, wood);
      s.rect(hx + 1, hy - 6, hx + 2, hy - 4, c);
      s.set(hx - 1, hy - 5, c);
      break;
    case Item::kPitchfork:
      s.rect(hx, g.hy0 + 2, hx, s.h() - 2, wood);
      s.rect(hx - 1, g.hy0 + 1, hx + 1, g.hy0 + 1, c);
      s.set(hx - 1, g.hy0, c);
      s.set(hx + 1, g.hy0, c);
      s.set(hx, g.hy0, c);
      s.set(hx - 1, g.hy0 - 1, c);
      s.set(hx + 1, g.hy0 - 1, c);
      break;
    case Item::kBag:
      s.rect(hx - 1, hy - 1, hx + 1, hy + 2, c);
      s.set(hx, hy - 2, shade(c, 0.6));
      s.set(hx, hy + 1, Px{240, 210, 60, 255});
      break;
    case Item::kBalloon:
      s.rect(hx, g.hy0 + 3, hx, hy - 1, Px{230, 230, 230, 255});
      s.rect(hx - 1, g.hy0 - 1 + pose % 2, hx + 1, g.hy0 + 2 + pose % 2, c);
      s.glow(hx - 1, g.hy0 + 3 + pose % 2, k.glow);
      break;
  }
}

void draw_cape(Sprite& s, const Look& k, const Geo& g, int pose) {
  const int sway = pose == 0 ? -1 : pose == 2 ? 1 : 0;
  for (int y = g.ty0; y <= g.ly0 + 5; ++y) {
    const int grow = std::min(2, (y - g.ty0) / 2);
    s.rect(g.tx0 - grow + (y > g.ly0 ? sway : 0), y, g.tx1 + grow + (y > g.ly0 ? sway : 0), y, k.cape_color);
  }
}

void draw_skeleton(Sprite& s, const Look& k, const Geo& g, int pose) {
  const Px bone = k.skin, hole{20, 18, 24, 255};
  s.rect(g.hx0, g.hy0, g.hx1, g.hy1 - 2, bone);
  s.rect(g.hx0 + 1, g.hy1 - 1, g.hx1 - 1, g.hy1, bone);
  s.set(g.hx0, g.hy0, Px{});
  s.set(g.hx1, g.hy0, Px{});
  s.rect(g.hx0 + 1, g.eye_y - 1, g.hx0 + 2, g.eye_y, hole);
  s.rect(g.hx1 - 2, g.eye_y - 1, g.hx1 - 1, g.eye_y, hole);
  s.set((g.hx0 + g.hx1) / 2, g.eye_y + 1, hole);
  for (int x = g.hx0 + 1; x <= g.hx1 - 1; x += 2) s.set(x, g.hy1, hole);
  if (k.glow_eyes) {
    s.set(g.hx0 + 1, g.eye_y, k.eyes);
    s.set(g.hx1 - 1, g.eye_y, k.eyes);
    s.glow(g.hx0 - 1, g.eye_y, k.glow);
    s.glow(g.hx1 + 1, g.eye_y, k.glow);
  }
  const int spine = (g.tx0 + g.tx1) / 2;
  s.rect(spine, g.hy1 + 1, spine, g.ty1, bone);
  s.rect(g.tx0 - 1, g.ty0, g.tx1 + 1, g.ty0, bone);
  for (int y = g.ty0 + 2; y < g.ty1; y += 2) s.rect(g.tx0, y, g.tx1, y, bone);
  s.rect(g.tx0, g.ty1, g.tx1, g.ty1, bone);
  draw_arms(s, k, g, pose, true);
  // One-pixel leg bones with the same stride rules as draw_legs.
  const int ground = s.h() - 1;
  for (int side = 0; side < 2; ++side) {
    const bool lifted = (pose == 0 && side == 1) || (pose == 2 && side == 0);
    const bool planted = (pose == 0 && side == 0) || (pose == 2 && side == 1);
    const int x = side == 0 ? g.tx0 + 1 : g.tx1 - 1;
    const int out = planted ? (side == 0 ? -1 : 1) : 0;
    const int foot = lifted ? ground - 1 : ground;
    const int knee = g.ly0 + (foot - g.ly0) / 2;
    s.rect(x, g.ly0, x, knee, bone);
    s.rect(x + out, knee + 1, x + out, foot - 1, bone);
    s.rect(side == 0 ? x - 1 + out : x + out, foot, side == 0 ? x + out : x + 1 + out, foot, bone);
  }
  if (k.face == Face::kBeard) {
    const int mid = (g.hx0 + g.hx1) / 2;
    s.rect(g.hx0 + 1, g.hy1 + 1, g.hx1 - 1, g.hy1 + 2, k.hair);
    s.rect(mid, g.hy1 + 3, mid + 1, g.hy1 + 4, k.hair);
  }
}

Image draw_dog(const Look& k, int pose) {
  Sprite s(kW, 13);
  const Px fur = k.skin, dark = shade(k.skin, 0.6), light = shade(k.skin, 1.25);
  s.rect(3, 5, 11, 8, fur);
  s.rect(4, 8, 10, 8, light);
  s.rect(10, 2, 14, 6, fur);
  s.rect(14, 4, 15, 6, light);
  s.set(15, 4, kDark);
  s.set(13, 3, kDark);
  s.rect(10, 1, 11, 4, dark);
  s.rect(10, 5, 10, 6, k.hat_trim);  // collar
  if (pose == 0) {
    s.rect(1, 2, 2, 4, fur);
    s.set(0, 1, fur);
  } else {
    s.rect(0, 5, 2, 5, fur);
    s.set(0, 6, fur);
  }
  const int legs0[] = {3, 6, 9, 11};
  const int legs1[] = {4, 5, 10, 12};
  const int* legs = pose == 0 ? legs0 : legs1;
  for (int i = 0; i < 4; ++i) {
    s.rect(legs[i], 9, legs[i], 11, i % 2 ? fur : dark);
    s.set(legs[i], 12, dark);
  }
  s.rect(2, 12, 2, 12, Px{});
  return s.finish(k.outline, k.crop, 1, 13);
}

}  // namespace

Image draw_figure(const Look& look, int pose) {
  if (look.body == Body::kDog) return draw_dog(look, pose);
  Sprite s(kW, 24);
  const Geo g = geometry(look, pose == 1 ? -1 : 0);
  if (look.cape) draw_cape(s, look, g, pose);
  if (look.body == Body::kSkeleton) {
    draw_skeleton(s, look, g, pose);
  } else {
    draw_legs(s, look, g, pose);
    draw_torso(s, look, g, pose);
    draw_arms(s, look, g, pose, false);
    s.rect(g.hx0, g.hy0, g.hx1, g.hy1, look.skin);
    s.rect((g.hx0 + g.hx1) / 2, g.hy1 + 1, (g.hx0 + g.hx1) / 2 + 1, g.ty0 - 1, shade(look.skin, 0.85));
    draw_face(s, look, g);
  }
  draw_hair(s, look, g);
  draw_hat(s, look, g);
  draw_item(s, look, g, pose);
  return s.finish(look.outline, look.crop, 3, 12);
}

}  // namespace kage::assetgen
