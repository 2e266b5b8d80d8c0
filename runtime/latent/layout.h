// Layout: generation of the segment heights (spec 4.3) and the terrain queries derived from them.
// The solid mask is never stored: it is a pure function of the per-segment heights (design.md "State is small").
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/latent/latent_params.h"
#include "runtime/rng.h"

namespace kage {

/// Read-only view of one environment's layout: segment s stores h_s - min_height (one byte each,
/// layout_segment_count(p) entries; latent_params_supported guarantees the range fits).
struct LayoutView {
  const uint8_t* segments;
};

/// Height (in height units) of segment s.
KAGE_HD int32_t segment_height(const LatentParams& p, LayoutView v, int32_t s) {
  return p.min_height + static_cast<int32_t>(v.segments[s]);
}

/// ground_top of column c (spec 4.3 step 5); c is clamped into [0, L) like the original's gathers.
KAGE_HD int32_t ground_top(const LatentParams& p, LayoutView v, int32_t c) {
  const int32_t cc = clampi(c, 0, p.length - 1);
  return p.base_ground_y - p.pix_per_unit * segment_height(p, v, cc / p.run_width);
}

/// Solid rows [lo, hi) of one column.
struct SolidSpan {
  int32_t lo;
  int32_t hi;
};

/// The solid rows of column c in [0, L). The band [gt, gt + thickness) and the connector
/// [min(gt[c-1], gt), max(gt[c-1], gt)) of spec 4.3 step 6 always touch, so their union is the single
/// interval [min(gt[c-1], gt), max(gt[c-1], gt + thickness)); column 0 has no left neighbour, and
/// using gt[0] for it gives the band alone.

KAGE_HD SolidSpan solid_span(const LatentParams& p, LayoutView v, int32_t c) {
  const int32_t gt = ground_top(p, v, c);
  const int32_t gl = c > 0 ? ground_top(p, v, c - 1) : gt;
  return SolidSpan{mini(gl, gt), maxi(gl, gt + p.ground_thickness)};
}

/// solid[r][c] of the original's mask, with r and c clamped into the mask (spec 0 "Gather clamping").
KAGE_HD bool solid(const LatentParams& p, LayoutView v, int32_t r, int32_t c) {
  const int32_t rr = clampi(r, 0, p.height_px - 1);
  const SolidSpan s = solid_span(p, v, clampi(c, 0, p.length - 1));
  return rr >= s.lo && rr < s.hi;
}

/// Whether any solid[clip(r)][clip(c)] for r in [r0, r1], c in [c0, c1] (inclusive, unclamped; empty
/// when r1 < r0 or c1 < c0). Clamping is monotonic, so the clamped rows and columns are again intervals
/// and the test costs one span per column instead of one read per cell.
KAGE_HD bool any_solid(const LatentParams& p, LayoutView v, int32_t c0, int32_t c1, int32_t r0, int32_t r1) {
  if (c1 < c0 || r1 < r0) return false;
  const int32_t rl = clampi(r0, 0, p.height_px - 1);
  const int32_t rh = clampi(r1, 0, p.height_px - 1);
  const int32_t cl = clampi(c0, 0, p.length - 1);
  const int32_t ch = clampi(c1, 0, p.length - 1);
  for (int32_t c = cl; c <= ch; ++c) {
    const SolidSpan s = solid_span(p, v, c);
    if (s.lo <= rh && s.hi > rl && s.lo < s.hi) return true;
  }
  return false;
}

/// Generates the segment heights of one episode from its layout stream key (spec 4.3 steps 1-4) into
/// `segments` (layout_segment_count(p) bytes). Events use uniforms of sub-key 0, magnitudes randints of
/// sub-key 1, one counter per segment (same distributions as the original, not its bits).
KAGE_HD void generate_layout(const LatentParams& p, Key layout_key, uint8_t* segments) {
  const int32_t count = layout_segment_count(p);
  const Key k_evt = fold(layout_key, 0u);
  const Key k_step = fold(layout_key, 1u);
  int32_t h = floor_div(p.min_height + p.max_height, 2);
  segments[0] = static_cast<uint8_t>(h - p.min_height);
  // The last event d_{Lc-1} is never used (spec 11.27), so it is not drawn.
  for (int32_t s = 1; s < count; ++s) {
    const uint32_t i = static_cast<uint32_t>(s - 1);
    const float u = uniform(k_evt, i, 0.0f, 1.0f);
    const int32_t event = u < p.layout_t_flat ? 0 : (u < p.layout_t_up ? 1 : -1);
    const int32_t mag = randint(k_step, i, p.min_step_height, p.max_step_height + 1);
    h = clampi(h + event * mag, p.min_height, p.max_height);
    segments[s] = static_cast<uint8_t>(h - p.min_height);
  }
}

/// Converts an explicit per-column ground_top (L values, e.g. recorded from the original) to segment
/// heights. Returns false when the columns are not of that form (not constant per run_width, not a
/// multiple of pix_per_unit from base_ground_y, or out of the stored height range); the segments are
/// then unspecified. With pix_per_unit = 0 every column must equal base_ground_y and heights are 0.
KAGE_HD bool layout_from_ground_top(const LatentParams& p, const int32_t* gt, uint8_t* segments) {
  const int32_t count = layout_segment_count(p);
  for (int32_t s = 0; s < count; ++s) {
    const int32_t first = s * p.run_width;
    const int32_t drop = p.base_ground_y - gt[first];
    int32_t h = p.min_height;
    if (p.pix_per_unit != 0) {
      if (drop % p.pix_per_unit != 0) return false;
      h = drop / p.pix_per_unit;
    } else if (drop != 0) {
      return false;
    }
    if (h < p.min_height || h > p.max_height) return false;
    segments[s] = static_cast<uint8_t>(h - p.min_height);
    const int32_t end = mini(first + p.run_width, p.length);
    for (int32_t c = first + 1; c < end; ++c) {
      if (gt[c] != gt[first]) return false;
    }
  }
  return true;
}

}  // namespace kage
