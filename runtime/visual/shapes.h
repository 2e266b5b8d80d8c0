// Shape rasterisation tests for the agent shape (spec 6.6) and the distractors (9.4): pure per-pixel
// inside tests in float32, plus the even-odd polygon test (6.7) both share.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/visual/visual_math.h"
#include "runtime/visual/visual_params.h"

namespace kage {

/// Even-odd test of point (px, py) against a closed polygon of n <= 10 vertices (spec 6.7).
KAGE_HD bool inside_polygon(const float* vx, const float* vy, int32_t n, float px, float py) {
  bool inside = false;
  for (int32_t k = 0; k < n; ++k) {
    const int32_t k1 = (k + 1) % n;
    const float x0 = vx[k], y0 = vy[k], x1 = vx[k1], y1 = vy[k1];
    float d = y1 - y0;
    if (d == 0.0f) d = 1e-12f;
    if (((y0 > py) != (y1 > py)) && px < x0 + (py - y0) * (x1 - x0) / d) inside = !inside;
  }
  return inside;
}

/// Regular polygon / star vertices around (ox, oy): n = 3 triangle, 6 hexagon, star = 10 alternating
/// radii (spec 6.6): th_k = -pi/2 + a + 2*pi*k/n (star: k*pi/5), float32 in the original's order.
KAGE_HD int32_t polygon_vertices(ShapeType type, float ox, float oy, float radius, float a, float* vx,
                                 float* vy) {
  const int32_t n = type == ShapeType::kTriangle ? 3 : (type == ShapeType::kPolygon ? 6 : 10);
  const float inner = radius * (sin(kPi / 10.0f) / sin(3.0f * kPi / 10.0f));
  for (int32_t k = 0; k < n; ++k) {
    const float step = type == ShapeType::kStar ? static_cast<float>(k) * kPi / 5.0f
                                                : 2.0f * kPi * static_cast<float>(k) / static_cast<float>(n);
    const float th = (-kPi / 2.0f + a) + step;
    const float rad = (type == ShapeType::kStar && (k & 1)) ? inner : radius;
    vx[k] = ox + rad * cos(th);
    vy[k] = oy + rad * sin(th);
  }
  return n;
}

/// Whether a shape type is drawn as a polygon (triangle, hexagon, star).
KAGE_HD bool polygon_type(ShapeType type) {
  return type == ShapeType::kTriangle || type == ShapeType::kPolygon || type == ShapeType::kStar;
}

/// The per-frame values of one drawn shape: cos and sin of its angle and, for polygon types, its
/// vertices around the original's half-pixel centre (spec 6.6 note). They depend only on the shape's
/// centre, radius and angle, so they are computed once per frame instead of once per pixel (a star
/// costs 20 sin/cos); the per-pixel tests below read them, so the arithmetic is unchanged.
struct ShapeFrame {
  float cos_a;
  float sin_a;
  int32_t n;  ///< polygon vertices (0 for the other types)
  float vx[10];
  float vy[10];
};

KAGE_HD ShapeFrame shape_frame(ShapeType type, int32_t cx, int32_t cy, float radius, float a) {
  ShapeFrame f{};
  f.cos_a = cos(a);
  f.sin_a = sin(a);
  f.n = polygon_type(type) ? polygon_vertices(type, static_cast<float>(cx) + 0.5f, static_cast<float>(cy) + 0.5f,
                                              radius, a, f.vx, f.vy)
                           : 0;
  return f;
}

/// Polygon-type test of pixel (c, r) against the shape's vertices, at the half-pixel centre.
KAGE_HD bool inside_polygon_shape(const ShapeFrame& sf, int32_t c, int32_t r) {
  return inside_polygon(sf.vx, sf.vy, sf.n, static_cast<float>(c) + 0.5f, static_cast<float>(r) + 0.5f);
}

/// Rotation of an offset by angle a (cos_a, sin_a precomputed): xr = dx cos - dy sin, yr = dx sin + dy cos.
struct Rotated {
  float xr, yr;
};

KAGE_HD Rotated rotate(float dx, float dy, float cos_a, float sin_a) {
  return Rotated{dx * cos_a - dy * sin_a, dx * sin_a + dy * cos_a};
}

/// Whether pixel (c, r) is inside the agent shape centred at (cx, cy) (spec 6.6).
/// w, h the character size; sf = shape_frame(type, cx, cy, 0.5 min(w, h), angle in radians).
KAGE_HD bool inside_agent_shape(ShapeType type, int32_t cx, int32_t cy, int32_t w, int32_t h, const ShapeFrame& sf,
                                int32_t c, int32_t r) {
  const float R = 0.5f * static_cast<float>(mini(w, h));
  const float dx = static_cast<float>(c - cx);
  const float dy = static_cast<float>(r - cy);
  const Rotated q = rotate(dx, dy, sf.cos_a, sf.sin_a);
  const float t_half = maxf(1.0f, R / 4.0f) / 2.0f;
  switch (type) {
    case ShapeType::kSquare:
      return fabs(q.xr) <= R && fabs(q.yr) <= R;
    case ShapeType::kLine:
      return fabs(q.xr) <= R && fabs(q.yr) <= t_half;
    case ShapeType::kCross:
      return (fabs(q.xr) <= R && fabs(q.yr) <= t_half) || (fabs(q.xr) <= t_half && fabs(q.yr) <= R);
    case ShapeType::kDiamond:
      return fabs(q.xr) / (R + 1e-12f) + fabs(q.yr) / (R + 1e-12f) <= 1.0f;
    case ShapeType::kEllipse: {
      // The ellipse alone uses the full width and height (spec 11.33).
      const float ex = q.xr / (static_cast<float>(w) / 2.0f + 1e-12f);
      const float ey = q.yr / (static_cast<float>(h) / 2.0f + 1e-12f);
      return ex * ex + ey * ey <= 1.0f;
    }
    case ShapeType::kTriangle:
    case ShapeType::kPolygon:
    case ShapeType::kStar:
      return inside_polygon_shape(sf, c, r);
    default:
      return dx * dx + dy * dy <= R * R;
  }
}

/// How far (in whole pixels along each axis) inside_agent_shape can be true from the centre at any
/// angle: the circle reaches R = min(w, h) / 2, the ellipse max(w, h) / 2, the other shapes at most the
/// rotated square's corner R * sqrt(2) (polygon vertices lie at R from the half-pixel centre). One
/// pixel of margin each; never more than agent_pixel's own max(w, h) test box.
KAGE_HD int32_t agent_shape_reach(ShapeType type, int32_t w, int32_t h) {
  const int32_t e = maxi(w, h);
  const float R = 0.5f * static_cast<float>(mini(w, h));
  switch (type) {
    case ShapeType::kCircle:
      return mini(e, static_cast<int32_t>(R) + 1);
    case ShapeType::kEllipse:
      return mini(e, e / 2 + 1);
    default:
      return mini(e, static_cast<int32_t>(R * 1.4143f) + 2);
  }
}

/// Whether pixel (c, r) is inside a distractor of size s centred at (cx, cy) (spec 9.4; the 32 x 32
/// window is the caller's); sf = shape_frame(type, cx, cy, s / 2, angle used as radians).
KAGE_HD bool inside_distractor(ShapeType type, int32_t cx, int32_t cy, float s, const ShapeFrame& sf, int32_t c,
                               int32_t r) {
  const float dx = static_cast<float>(c - cx);
  const float dy = static_cast<float>(r - cy);
  const Rotated q = rotate(dx, dy, sf.cos_a, sf.sin_a);
  const float half = s / 2.0f;
  const float ht = 0.5f * maxf(1.0f, s / 8.0f);
  switch (type) {
    case ShapeType::kSquare:
      return fabs(q.xr) <= half && fabs(q.yr) <= half;
    case ShapeType::kDiamond:
      return fabs(q.xr) / (half + 1e-12f) + fabs(q.yr) / (s + 1e-12f) <= 1.0f;
    case ShapeType::kCross:
      return (fabs(q.xr) <= half && fabs(q.yr) <= ht) || (fabs(q.yr) <= half && fabs(q.xr) <= ht);
    case ShapeType::kEllipse: {
      const float ex = q.xr / (0.5f * s + 1e-12f);
      const float ey = q.yr / (0.3f * s + 1e-12f);
      return ex * ex + ey * ey <= 1.0f;
    }
    case ShapeType::kLine:
      return fabs(q.yr) <= ht && fabs(q.xr) <= half;
    case ShapeType::kTriangle:
    case ShapeType::kPolygon:
    case ShapeType::kStar:
      return inside_polygon_shape(sf, c, r);
    default:
      return dx * dx + dy * dy <= half * half;
  }
}

}  // namespace kage
