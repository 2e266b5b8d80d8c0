// kage_assetgen internals: deterministic random numbers, colours, and the
// generators for backgrounds and sprite skins written into assets/.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "fileio/image_io.h"

namespace kage::assetgen {

/// SplitMix64: fixed, platform-independent sequence for a given seed.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1).
  double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [lo, hi].
  int range(int lo, int hi) { return lo + int(next() % uint64_t(hi - lo + 1)); }

 private:
  uint64_t state_;
};

/// An RGB colour with float channels in 0..255.
struct Rgb {
  double r = 0, g = 0, b = 0;
};

/// HSV (h in degrees, s and v in 0..1) to RGB 0..255.
Rgb hsv(double h, double s, double v);
/// Linear blend a + (b - a) * t.
Rgb mix(const Rgb& a, const Rgb& b, double t);

/// Background number `index` (1-based), 128x128 RGB.
Image make_background(int index);

/// The 27 skin names, in sorted order.
const std::vector<std::string>& skin_names();
/// Frames of one skin, RGBA, at most 16x24 each.
std::vector<Image> make_skin(const std::string& name);
/// File stem of a skin's frames (the skin name).
std::string skin_file_stem(const std::string& name);

/// Writes the whole pack under `out_dir` (backgrounds/, sprites/, LICENSE,
/// README.md). Progress and errors go to `log`. Returns 0 on success.
int run_assetgen(const std::string& out_dir, std::ostream& log);

}  // namespace kage::assetgen
