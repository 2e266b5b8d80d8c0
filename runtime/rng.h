// Counter-based random numbers (Threefry-2x32, 20 rounds).
//
// Every draw is a pure function of (key, counter): nothing random is stored,
// CPU and GPU produce the same bits, and each consumer owns a stream
// (streams.def) so that visual settings never move a latent draw.
// The samplers follow the original's float32 formulas (spec Appendix A.4).
#pragma once

#include "runtime/kage_hd.h"

namespace kage {

struct Key {
  uint32_t k0;
  uint32_t k1;
};

enum class Stream : uint32_t {
#define KAGE_STREAM(name, id, doc) name = id,
#include "runtime/streams.def"
#undef KAGE_STREAM
};

KAGE_HD uint32_t rotl32(uint32_t x, uint32_t r) { return (x << r) | (x >> (32u - r)); }

/// Threefry-2x32 block function T(k; c0, c1) (spec Appendix A.1).
KAGE_HD void threefry2x32(Key k, uint32_t c0, uint32_t c1, uint32_t& y0, uint32_t& y1) {
  const uint32_t ks[3] = {k.k0, k.k1, k.k0 ^ k.k1 ^ 0x1BD11BDAu};
  const uint32_t r0[4] = {13, 15, 26, 6};
  const uint32_t r1[4] = {17, 29, 16, 24};
  uint32_t x0 = c0 + ks[0];
  uint32_t x1 = c1 + ks[1];
KAGE_UNROLL
  for (uint32_t j = 1; j <= 5; ++j) {
    const uint32_t* rs = (j & 1u) ? r0 : r1;
KAGE_UNROLL
    for (int i = 0; i < 4; ++i) {
      x0 += x1;
      x1 = rotl32(x1, rs[i]);
      x1 ^= x0;
    }
    x0 += ks[j % 3];
    x1 += ks[(j + 1) % 3] + j;
  }
  y0 = x0;
  y1 = x1;
}

/// The key of a user seed (spec A.2: high word, low word).
KAGE_HD Key seed_key(uint64_t seed) {
  return Key{static_cast<uint32_t>(seed >> 32), static_cast<uint32_t>(seed & 0xFFFFFFFFu)};
}

/// A child key: T(k; a, b) as a new key. Used to derive episode, stream and step keys.
KAGE_HD Key fold(Key k, uint32_t a, uint32_t b = 0) {
  Key out;
  threefry2x32(k, a, b, out.k0, out.k1);
  return out;
}

/// The key a consumer draws from within one episode.
KAGE_HD Key stream_key(Key episode, Stream s) { return fold(episode, static_cast<uint32_t>(s), 0x4B414745u); }

/// 32 random bits number `i` of key k.
KAGE_HD uint32_t bits32(Key k, uint32_t i) {
  uint32_t y0, y1;
  threefry2x32(k, 0u, i, y0, y1);
  return y0 ^ y1;
}

/// Uniform float in [0, 1 - 2^-23] from 32 bits (A.4: mantissa trick).
KAGE_HD float unit_float(uint32_t bits) {
  union {
    uint32_t u;
    float f;
  } v;
  v.u = (bits >> 9) | 0x3F800000u;
  return v.f - 1.0f;
}

/// uniform(k, i, lo, hi) in [lo, hi), float32, as A.4.
KAGE_HD float uniform(Key k, uint32_t i, float lo, float hi) {
  const float f = unit_float(bits32(k, i));
  const float v = f * (hi - lo) + lo;
  return v > lo ? v : lo;
}

/// randint(k, i, lo, hi) uniform on [lo, hi) (hi <= lo gives lo), A.4's two-word method.
KAGE_HD int32_t randint(Key k, uint32_t i, int32_t lo, int32_t hi) {
  uint32_t span = static_cast<uint32_t>(hi - lo);
  if (hi <= lo) span = 1u;
  uint32_t u, v;
  threefry2x32(k, 1u, i, u, v);
  const uint32_t mult = ((65536u % span) * (65536u % span)) % span;
  const uint32_t off = ((u % span) * mult + (v % span)) % span;
  return lo + static_cast<int32_t>(off);
}


/// Four 32-bit words of Philox-4x32-10 (Salmon et al. 2011) for counter (c0, c1, c2, c3) under key k:
/// a second counter-based generator, about 4x cheaper per word than threefry2x32 (10 rounds of two
/// 32 x 32 -> 64-bit products), for per-pixel noise where one Threefry block per sample dominated the
/// frame time. A pure function of (key, counter) like every draw here.
struct Words4 {
  uint32_t w[4];
};

KAGE_HD Words4 philox4x32(Key k, uint32_t c0, uint32_t c1, uint32_t c2 = 0u, uint32_t c3 = 0u) {
  uint32_t k0 = k.k0, k1 = k.k1;
KAGE_UNROLL
  for (int r = 0; r < 10; ++r) {
    const uint64_t p0 = static_cast<uint64_t>(0xD2511F53u) * c0;
    const uint64_t p1 = static_cast<uint64_t>(0xCD9E8D57u) * c2;
    const uint32_t hi0 = static_cast<uint32_t>(p0 >> 32), lo0 = static_cast<uint32_t>(p0);
    const uint32_t hi1 = static_cast<uint32_t>(p1 >> 32), lo1 = static_cast<uint32_t>(p1);
    c0 = hi1 ^ c1 ^ k0;
    c1 = lo1;
    c2 = hi0 ^ c3 ^ k1;
    c3 = lo0;
    k0 += 0x9E3779B9u;
    k1 += 0xBB67AE85u;
  }
  return Words4{{c0, c1, c2, c3}};
}

/// The uniform random action in [0, 8) of environment `env` at step t of a benchmark run (its own key,
/// from `seed`): kage_sample_actions draws it on the GPU, the benchmark's CPU check on the host.
KAGE_HD int32_t benchmark_action(uint64_t seed, uint32_t t, uint32_t env) {
  return randint(fold(seed_key(seed), t), env, 0, 8);
}

}  // namespace kage
