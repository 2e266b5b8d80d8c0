// The per-pixel noise samplers (Philox-4x32, Box-Muller, Poisson by inversion / PTRS) against the exact
// distributions (spec A.4, 7.3): moments and CDF values; and the IEEE-only transcendentals of
// kage_math.h against the host's double-precision library.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

#include "runtime/kage_math.h"
#include "runtime/rng.h"
#include "runtime/visual/visual_random.h"

namespace {

/// Distance in ulps between a float result and a double reference.
double ulps(float got, double want) {
  const double ulp = std::ldexp(1.0, std::ilogb(static_cast<float>(want)) - 23);
  return std::fabs(static_cast<double>(got) - want) / ulp;
}

/// Poisson CDF P(X <= n) in double.
double poisson_cdf(double lam, int n) {
  double p = std::exp(-lam), c = p;
  for (int k = 1; k <= n; ++k) {
    p *= lam / k;
    c += p;
  }
  return c;
}

}  // namespace

TEST_CASE("IEEE-only log, exp, pow, sin, cos are accurate", "[math]") {
  double worst_log = 0, worst_exp = 0, worst_pow = 0, worst_trig = 0;
  for (uint32_t i = 0; i < 200000; ++i) {
    const uint32_t b = kage::bits32(kage::Key{3u, 4u}, i);
    const float x = std::ldexp(1.0f + static_cast<float>(b & 0xFFFFFu) / 1048576.0f, static_cast<int>(b >> 20) % 60 - 30);
    worst_log = std::fmax(worst_log, ulps(kage::log(x), std::log(static_cast<double>(x))));
    const float e = kage::unit_float(b) * 170.0f - 85.0f;
    worst_exp = std::fmax(worst_exp, ulps(kage::exp(e), std::exp(static_cast<double>(e))));
    const float base = kage::unit_float(b ^ 0x5a5a5a5au) * 1.2f;
    const float g = kage::unit_float(b * 2654435761u) * 4.0f;
    if (base > 1e-3f) worst_pow = std::fmax(worst_pow, ulps(kage::pow(base, g), std::pow(double(base), double(g))));
    const float a = kage::unit_float(b) * 800.0f - 400.0f;
    worst_trig = std::fmax(worst_trig, std::fabs(kage::sin(a) - std::sin(double(a))) / 6e-8);
    worst_trig = std::fmax(worst_trig, std::fabs(kage::cos(a) - std::cos(double(a))) / 6e-8);
  }
  INFO("log " << worst_log << " exp " << worst_exp << " pow " << worst_pow << " trig " << worst_trig);
  CHECK(worst_log <= 1.0);
  CHECK(worst_exp <= 1.0);
  CHECK(worst_pow <= 1.0);
  CHECK(worst_trig <= 1.0);
  CHECK(kage::pow(0.0f, 2.0f) == 0.0f);
  CHECK(kage::pow(2.0f, 10.0f) == 1024.0f);
  CHECK(kage::pow(-2.0f, 3.0f) == -8.0f);
  CHECK(std::isnan(kage::pow(-2.0f, 0.5f)));
  CHECK(kage::exp(0.0f) == 1.0f);
  CHECK(kage::log(1.0f) == 0.0f);
  CHECK(std::isinf(kage::log(0.0f)));
  CHECK(kage::exp(-200.0f) == 0.0f);
  float s, c;
  for (int i = 0; i < 1000; ++i) {
    const float u = static_cast<float>(i) / 1000.0f;
    kage::sincos_2pi(u, s, c);
    CHECK(std::fabs(s - std::sin(2.0 * M_PI * u)) < 2e-7);
    CHECK(std::fabs(c - std::cos(2.0 * M_PI * u)) < 2e-7);
  }
}

TEST_CASE("pixel normals are standard normal and uncorrelated", "[visual][distribution]") {
  const kage::Key k{21u, 22u};
  constexpr int n = 100000;
  double sum[3] = {}, sum2[3] = {}, cross = 0;
  int below = 0, inside = 0;
  for (int i = 0; i < n; ++i) {
    float z[3];
    kage::pixel_normals3(k, static_cast<uint32_t>(i), z);
    for (int ch = 0; ch < 3; ++ch) {
      sum[ch] += z[ch];
      sum2[ch] += double(z[ch]) * z[ch];
      below += z[ch] < -1.959964f;
      inside += std::fabs(z[ch]) < 1.0f;
    }
    cross += double(z[0]) * z[1] + double(z[1]) * z[2];
  }
  for (int ch = 0; ch < 3; ++ch) {
    CHECK(std::fabs(sum[ch] / n) < 0.015);
    CHECK(std::fabs(sum2[ch] / n - 1.0) < 0.02);
  }
  CHECK(std::fabs(cross / (2.0 * n)) < 0.015);
  CHECK(std::fabs(below / (3.0 * n) - 0.025) < 0.002);
  CHECK(std::fabs(inside / (3.0 * n) - 0.682689) < 0.005);
}

TEST_CASE("Poisson samples follow the Poisson CDF", "[visual][distribution]") {
  const kage::Key k{31u, 32u};
  constexpr int n = 100000;
  for (float lam : {0.3f, 2.0f, 9.9f, 10.0f, 37.5f, 255.0f}) {
    std::vector<int> v(n);
    double s = 0, s2 = 0;
    for (int i = 0; i < n; ++i) {
      v[i] = kage::poisson(k, static_cast<uint32_t>(i), lam);
      s += v[i];
      s2 += double(v[i]) * v[i];
    }
    const double mean = s / n, var = s2 / n - mean * mean;
    INFO("lam " << lam << " mean " << mean << " var " << var);
    CHECK(std::fabs(mean - lam) < 4.0 * std::sqrt(lam / n) + 1e-3);
    CHECK(std::fabs(var / lam - 1.0) < 0.03);
    // Empirical CDF at the integers around the mean, against the exact CDF (KS-style bound).
    const int lo = static_cast<int>(std::fmax(0.0, lam - 3.0 * std::sqrt(lam)));
    const int hi = static_cast<int>(lam + 3.0 * std::sqrt(lam)) + 1;
    double worst = 0;
    for (int m = lo; m <= hi; ++m) {
      int count = 0;
      for (int x : v) count += x <= m;
      worst = std::fmax(worst, std::fabs(double(count) / n - poisson_cdf(lam, m)));
    }
    INFO("max CDF deviation " << worst);
    CHECK(worst < 0.006);
  }
}
