// Procedural 128x128 backgrounds: twelve scene families (hills, night city,
// clouds, stripes, marble noise, mountains, dunes, sea, forest, bricks, cave,
// sunset), each with its own seed and palette, so the stack is diverse.
#include <algorithm>
#include <cmath>

#include "tools/assetgen/assetgen.h"

namespace kage::assetgen {

Rgb hsv(double h, double s, double v) {
  h = std::fmod(std::fmod(h, 360.0) + 360.0, 360.0) / 60.0;
  const int i = int(h);
  const double f = h - i, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double r = v, g = t, b = p;
  switch (i) {
    case 1: r = q; g = v; b = p; break;
    case 2: r = p; g = v; b = t; break;
    case 3: r = p; g = q; b = v; break;
    case 4: r = t; g = p; b = v; break;
    case 5: r = v; g = p; b = q; break;
    default: break;
  }
  return {r * 255, g * 255, b * 255};
}

Rgb mix(const Rgb& a, const Rgb& b, double t) {
  return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}

namespace {

constexpr int kSize = 128;

struct Canvas {
  std::vector<Rgb> px = std::vector<Rgb>(kSize * kSize);
  Rgb& at(int x, int y) { return px[size_t(y) * kSize + x]; }
  void blend(int x, int y, const Rgb& c, double a) {
    if (x < 0 || y < 0 || x >= kSize || y >= kSize) return;
    at(x, y) = mix(at(x, y), c, a);
  }
};

// Value noise on a lattice hashed from the seed; smooth, tileable enough.
double lattice(uint64_t seed, int x, int y) {
  uint64_t h = seed ^ (uint64_t(uint32_t(x)) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(uint32_t(y)) * 0xC2B2AE3D27D4EB4Full);
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  return double(h & 0xFFFFFF) / double(0xFFFFFF);
}

double value_noise(uint64_t seed, double x, double y) {
  const int xi = int(std::floor(x)), yi = int(std::floor(y));
  double fx = x - xi, fy = y - yi;
  fx = fx * fx * (3 - 2 * fx);
  fy = fy * fy * (3 - 2 * fy);
  const double a = lattice(seed, xi, yi), b = lattice(seed, xi + 1, yi);
  const double c = lattice(seed, xi, yi + 1), d = lattice(seed, xi + 1, yi + 1);
  return (a + (b - a) * fx) + ((c + (d - c) * fx) - (a + (b - a) * fx)) * fy;
}

double fbm(uint64_t seed, double x, double y, int octaves) {
  double sum = 0, amp = 0.5, norm = 0;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * value_noise(seed + uint64_t(o) * 1013, x, y);
    norm += amp;
    x *= 2.03;
    y *= 2.03;
    amp *= 0.5;
  }
  return sum / norm;
}

void vertical_gradient(Canvas& c, const Rgb& top, const Rgb& bottom) {
  for (int y = 0; y < kSize; ++y) {
    const Rgb row = mix(top, bottom, y / double(kSize - 1));
    for (int x = 0; x < kSize; ++x) c.at(x, y) = row;
  }
}

void disc(Canvas& c, double cx, double cy, double r, const Rgb& col, double alpha) {
  for (int y = int(cy - r - 2); y <= int(cy + r + 2); ++y) {
    for (int x = int(cx - r - 2); x <= int(cx + r + 2); ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      const double cover = std::clamp(r - d + 0.5, 0.0, 1.0);
      if (cover > 0) c.blend(x, y, col, cover * alpha);
    }
  }
}

// Fills below a ridge line height(x) (rows from the top) with a colour.
template <class F>
void ridge(Canvas& c, F height, const Rgb& col, const Rgb& shade) {
  for (int x = 0; x < kSize; ++x) {
    const double h = height(x);
    for (int y = std::max(0, int(h)); y < kSize; ++y) c.at(x, y) = mix(col, shade, std::min(1.0, (y - h) / 60.0));
  }
}

void stars(Canvas& c, Rng& rng, int n, double max_y) {
  for (int i = 0; i < n; ++i) {
    const int x = rng.range(0, kSize - 1), y = rng.range(0, int(max_y));
    const double b = rng.uniform(0.4, 1.0);
    c.blend(x, y, {255, 255, 235}, b);
    if (b > 0.9) {
      c.blend(x + 1, y, {255, 255, 235}, 0.4);
      c.blend(x - 1, y, {255, 255, 235}, 0.4);
      c.blend(x, y + 1, {255, 255, 235}, 0.4);
      c.blend(x, y - 1, {255, 255, 235}, 0.4);
    }
  }
}

void hills(Canvas& c, Rng& rng, uint64_t seed, double hue) {
  vertical_gradient(c, hsv(hue + 200, 0.55, 0.95), hsv(hue + 180, 0.15, 1.0));
  disc(c, rng.uniform(15, 110), rng.uniform(12, 35), rng.uniform(6, 12), {255, 244, 190}, 1.0);
  for (int layer = 0; layer < 3; ++layer) {
    const double base = 60 + layer * 22, amp = 14 - layer * 3, freq = rng.uniform(0.02, 0.05);
    const double ph = rng.uniform(0, 6.28);
    const Rgb col = hsv(hue + 90 + layer * 12, 0.5 + 0.12 * layer, 0.75 - 0.15 * layer);
    ridge(c, [&](int x) { return base + amp * std::sin(x * freq + ph) + 6 * fbm(seed + layer, x / 20.0, layer, 2); },
          col, mix(col, {0, 0, 0}, 0.4));
  }
}

void night_city(Canvas& c, Rng& rng, double hue) {
  vertical_gradient(c, hsv(hue + 230, 0.7, 0.12), hsv(hue + 260, 0.5, 0.45));
  stars(c, rng, 70, 80);
  disc(c, rng.uniform(20, 108), rng.uniform(14, 30), rng.uniform(5, 9), {240, 240, 215}, 1.0);
  for (int layer = 0; layer < 2; ++layer) {
    const Rgb body = hsv(hue + 240, 0.3, 0.10 + 0.08 * (1 - layer));
    int x = -rng.range(0, 8);
    while (x < kSize) {
      const int w = rng.range(8, 18), h = rng.range(25, 70) - layer * 15;
      const int top = kSize - h;
      for (int yy = top; yy < kSize; ++yy) {
        for (int xx = std::max(0, x); xx < std::min(kSize, x + w); ++xx) c.at(xx, yy) = body;
      }
      if (layer == 1) {
        for (int yy = top + 3; yy < kSize - 3; yy += 4) {
          for (int xx = x + 2; xx < x + w - 2; xx += 3) {
            if (xx >= 0 && xx < kSize && rng.uniform() < 0.45) {
              const Rgb lit = hsv(45 + rng.uniform(-15, 15), 0.6, 1.0);
              c.at(xx, yy) = lit;
              if (xx + 1 < kSize) c.at(xx + 1, yy) = lit;
            }
          }
        }
      }
      x += w + rng.range(0, 3);
    }
  }
}

void clouds(Canvas& c, uint64_t seed, double hue) {
  vertical_gradient(c, hsv(hue + 205, 0.65, 0.9), hsv(hue + 195, 0.25, 1.0));
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const double n = fbm(seed, x / 28.0, y / 16.0, 5);
      const double a = std::clamp((n - 0.52) * 5.0, 0.0, 1.0);
      c.blend(x, y, mix({255, 255, 255}, {200, 205, 220}, std::clamp((n - 0.6) * 3, 0.0, 1.0)), a);
    }
  }
}

void stripes(Canvas& c, Rng& rng, double hue) {
  const int n = rng.range(3, 6);
  std::vector<Rgb> pal;
  for (int i = 0; i < n; ++i) pal.push_back(hsv(hue + i * rng.uniform(20, 70), rng.uniform(0.3, 0.9), rng.uniform(0.4, 1.0)));
  const double angle = rng.range(0, 3) * 0.785398 + rng.uniform(-0.1, 0.1);
  const double width = rng.uniform(6, 18), wave = rng.uniform(0, 6);
  const double ca = std::cos(angle), sa = std::sin(angle);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const double u = x * ca + y * sa + wave * std::sin((x * sa - y * ca) / 9.0);
      const int band = int(std::floor(u / width));
      c.at(x, y) = pal[size_t(((band % n) + n) % n)];
    }
  }
}

void marble(Canvas& c, uint64_t seed, Rng& rng, double hue) {
  const Rgb a = hsv(hue, rng.uniform(0.2, 0.9), rng.uniform(0.2, 0.5));
  const Rgb b = hsv(hue + rng.uniform(30, 180), rng.uniform(0.2, 0.8), rng.uniform(0.7, 1.0));
  const double scale = rng.uniform(14, 40), turb = rng.uniform(2, 8);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const double n = fbm(seed, x / scale, y / scale, 5);
      const double t = 0.5 + 0.5 * std::sin(x / scale * 3 + turb * n);
      c.at(x, y) = mix(a, b, t);
    }
  }
}

void mountains(Canvas& c, uint64_t seed, Rng& rng, double hue) {
  vertical_gradient(c, hsv(hue + 210, 0.4, 0.85), hsv(hue + 30, 0.25, 0.95));
  for (int layer = 0; layer < 3; ++layer) {
    const double base = 45 + layer * 25;
    const Rgb col = hsv(hue + 220, 0.25 + 0.1 * layer, 0.7 - 0.2 * layer);
    const uint64_t s = seed + 77 * uint64_t(layer);
    const double snow = rng.uniform(0.15, 0.3);
    for (int x = 0; x < kSize; ++x) {
      double h = base - 40 * (fbm(s, x / 40.0, 0.5, 4) - 0.3) - 12 * std::fabs(std::sin(x / 17.0 + layer));
      for (int y = std::max(0, int(h)); y < kSize; ++y) {
        c.at(x, y) = (y - h) < snow * 40 && layer == 0 ? Rgb{245, 248, 255} : mix(col, {20, 20, 30}, (y - h) / 140.0);
      }
    }
  }
}

void dunes(Canvas& c, Rng& rng, double hue) {
  vertical_gradient(c, hsv(hue + 20, 0.5, 1.0), hsv(hue + 40, 0.3, 1.0));
  disc(c, rng.uniform(30, 100), rng.uniform(25, 45), rng.uniform(12, 20), {255, 250, 220}, 0.95);
  for (int layer = 0; layer < 4; ++layer) {
    const double base = 70 + layer * 15, ph = rng.uniform(0, 6.28), f = rng.uniform(0.03, 0.07);
    const Rgb col = hsv(hue + 30 - layer * 4, 0.55 + 0.05 * layer, 0.95 - 0.1 * layer);
    ridge(c, [&](int x) { return base - 8 * std::sin(x * f + ph) - 3 * std::sin(x * f * 2.7); }, col,
          mix(col, {120, 60, 20}, 0.5));
  }
}

void sea(Canvas& c, uint64_t seed, Rng& rng, double hue) {
  const int horizon = rng.range(45, 80);
  const Rgb sky_top = hsv(hue + 200, 0.5, 0.9), sky_low = hsv(hue + 20, 0.35, 1.0);
  const Rgb water = hsv(hue + 195, 0.7, 0.55), deep = hsv(hue + 215, 0.8, 0.3);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      if (y < horizon) {
        c.at(x, y) = mix(sky_top, sky_low, y / double(horizon));
      } else {
        const double t = (y - horizon) / double(kSize - horizon);
        const double w = fbm(seed, x / 10.0, y / 2.5, 3);
        c.at(x, y) = mix(mix(water, deep, t), {240, 250, 255}, w > 0.66 ? 0.6 : 0.0);
      }
    }
  }
  disc(c, rng.uniform(20, 108), horizon - rng.uniform(5, 25), rng.uniform(7, 12), {255, 230, 170}, 1.0);
}

void forest(Canvas& c, Rng& rng, double hue) {
  vertical_gradient(c, hsv(hue + 100, 0.3, 0.75), hsv(hue + 60, 0.2, 0.95));
  for (int layer = 0; layer < 3; ++layer) {
    const Rgb col = hsv(hue + 120 + 10 * layer, 0.5 + 0.1 * layer, 0.55 - 0.15 * layer);
    const int ground = 80 + 16 * layer;
    for (int y = ground; y < kSize; ++y) {
      for (int x = 0; x < kSize; ++x) c.at(x, y) = col;
    }
    for (int t = 0; t < 9 + 3 * layer; ++t) {
      const double cx = rng.uniform(-5, 133), h = rng.uniform(25, 45) + 10 * layer, w = h * rng.uniform(0.25, 0.4);
      for (int y = int(ground - h); y < ground; ++y) {
        const double half = w * (y - (ground - h)) / h;
        for (int x = int(cx - half); x <= int(cx + half); ++x) c.blend(x, y, col, 1.0);
      }
    }
  }
}

void bricks(Canvas& c, Rng& rng, double hue) {
  const Rgb mortar = hsv(hue, 0.1, rng.uniform(0.3, 0.8));
  const int bw = rng.range(10, 24), bh = rng.range(5, 10);
  for (int y = 0; y < kSize; ++y) {
    const int row = y / bh;
    for (int x = 0; x < kSize; ++x) {
      const int xs = x + (row % 2) * bw / 2;
      const bool joint = y % bh == 0 || xs % bw == 0;
      const uint64_t id = uint64_t(row) * 977 + uint64_t(xs / bw);
      Rng cell(id * 31 + uint64_t(hue * 10));
      c.at(x, y) = joint ? mortar : hsv(hue + cell.uniform(-12, 12), 0.55, 0.45 + cell.uniform(0, 0.3));
    }
  }
}

void cave(Canvas& c, uint64_t seed, Rng& rng, double hue) {
  const Rgb rock = hsv(hue, 0.3, 0.35), dark = hsv(hue + 200, 0.4, 0.06);
  const Rgb gem = hsv(hue + 180, 0.8, 1.0);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const double n = fbm(seed, x / 22.0, y / 22.0, 4);
      const double open = 1.0 - std::fabs(y - 64.0) / 64.0;
      const double t = std::clamp((n + open * 0.5 - 0.6) * 4.0, 0.0, 1.0);
      c.at(x, y) = mix(rock, dark, t);
    }
  }
  for (int i = 0; i < 14; ++i) disc(c, rng.uniform(0, 128), rng.uniform(0, 128), rng.uniform(0.6, 1.6), gem, 0.9);
}

void sunset(Canvas& c, Rng& rng, double hue) {
  const Rgb a = hsv(hue + 270, 0.6, 0.35), b = hsv(hue + 330, 0.7, 0.9), d = hsv(hue + 30, 0.8, 1.0);
  const int bands = rng.range(6, 14);
  for (int y = 0; y < kSize; ++y) {
    const double t = y / double(kSize - 1);
    const double q = std::floor(t * bands) / bands;
    const Rgb col = q < 0.5 ? mix(a, b, q * 2) : mix(b, d, q * 2 - 1);
    for (int x = 0; x < kSize; ++x) c.at(x, y) = col;
  }
  disc(c, 64 + rng.uniform(-30, 30), 90, rng.uniform(18, 28), hsv(hue + 50, 0.5, 1.0), 0.9);
  ridge(c, [&](int x) { return 100 + 4 * std::sin(x / 9.0); }, hsv(hue + 280, 0.5, 0.15), {5, 0, 10});
}

}  // namespace

Image make_background(int index) {
  const uint64_t seed = 0x6B616765ull * 1000003ull + uint64_t(index) * 7919ull;
  Rng rng(seed);
  const double hue = rng.uniform(0, 360) * 0.35 + index * 29.0;
  Canvas c;
  switch ((index - 1) % 12) {
    case 0: hills(c, rng, seed, hue); break;
    case 1: night_city(c, rng, hue); break;
    case 2: clouds(c, seed, hue); break;
    case 3: stripes(c, rng, hue); break;
    case 4: marble(c, seed, rng, hue); break;
    case 5: mountains(c, seed, rng, hue); break;
    case 6: dunes(c, rng, hue); break;
    case 7: sea(c, seed, rng, hue); break;
    case 8: forest(c, rng, hue); break;
    case 9: bricks(c, rng, hue); break;
    case 10: cave(c, seed, rng, hue); break;
    default: sunset(c, rng, hue); break;
  }
  Image img{kSize, kSize, 3, std::vector<uint8_t>(size_t(kSize) * kSize * 3)};
  for (size_t i = 0; i < c.px.size(); ++i) {
    img.pixels[i * 3] = uint8_t(std::clamp(c.px[i].r + 0.5, 0.0, 255.0));
    img.pixels[i * 3 + 1] = uint8_t(std::clamp(c.px[i].g + 0.5, 0.0, 255.0));
    img.pixels[i * 3 + 2] = uint8_t(std::clamp(c.px[i].b + 0.5, 0.0, 255.0));
  }
  return img;
}

}  // namespace kage::assetgen
