// Closest points on shapes; see shape_distance.h.
#include "renderer/shapes/shape_distance.h"

#include <algorithm>
#include <cmath>

#include "renderer/shapes/sdf.h"

namespace penumbra {

namespace {

// The nearest point of the closed box |x_k| <= h_k's surface to p.
Vec3f closest_on_box_surface(Vec3f h, Vec3f p) {
  const Vec3f q{std::clamp(p.x, -h.x, h.x), std::clamp(p.y, -h.y, h.y), std::clamp(p.z, -h.z, h.z)};
  if (q.x != p.x || q.y != p.y || q.z != p.z) return q;  // outside: the clamp is on the surface
  // Inside: the nearest face, by the smallest gap (the first axis on ties).
  int axis = 0;
  float gap = h.x - std::fabs(p.x);
  for (int k = 1; k < 3; ++k)
    if (h[k] - std::fabs(p[k]) < gap) gap = h[k] - std::fabs(p[k]), axis = k;
  Vec3f r = p;
  r[axis] = std::signbit(p[axis]) ? -h[axis] : h[axis];
  return r;
}

// The point at distance `radius` from `centre` towards p (+x when p is the centre).
Vec3f on_ball(Vec3f centre, float radius, Vec3f p) {
  const Vec3f d = p - centre;
  const float len = length(d);
  if (!(len > 0)) return centre + Vec3f{radius, 0, 0};
  return centre + d * (radius / len);
}

Vec3f closest_on_implicit(const Shape& s, Vec3f p) {
  const float tol = std::max(s.trace.absolute_epsilon, s.trace.relative_epsilon * length(p));
  Vec3f x = p;
  for (int i = 0; i < 64; ++i) {
    const float f = sdf_eval(s.sdf, x);
    if (!std::isfinite(f)) break;
    if (std::fabs(f) / s.lipschitz <= tol) break;
    const Vec3f n = sdf_gradient_normal(s.sdf, x);
    x = x - n * (f / s.lipschitz);
  }
  return x;
}

}  // namespace

Vec3f closest_point_on_shape(const Shape& s, Vec3f p) {
  switch (s.kind) {
    case ShapeKind::Sphere:
      return on_ball({0, 0, 0}, s.radius, p);
    case ShapeKind::Plane:
      return {std::clamp(p.x, -s.half_size.x, s.half_size.x), 0.0f,
              std::clamp(p.z, -s.half_size.z, s.half_size.z)};
    case ShapeKind::Disk: {
      const float r = std::sqrt(p.x * p.x + p.z * p.z);
      const float f = r > s.radius ? s.radius / r : 1.0f;
      return {p.x * f, 0.0f, p.z * f};
    }
    case ShapeKind::Box:
      return closest_on_box_surface(s.half_size, p);
    case ShapeKind::Capsule: {
      const Vec3f axis{0, std::clamp(p.y, -s.half_height, s.half_height), 0};
      return on_ball(axis, s.radius, p);
    }
    case ShapeKind::Segment: {
      const Vec3f d = s.p1 - s.p0;
      const float dd = dot(d, d);
      const float u = dd > 0 ? std::clamp(dot(p - s.p0, d) / dd, 0.0f, 1.0f) : 0.0f;
      return on_ball(s.p0 + d * u, s.radius, p);
    }
    case ShapeKind::Implicit:
      return closest_on_implicit(s, p);
    case ShapeKind::Splat:  // a density without a surface: its centre
      return s.p0;
  }
  return p;
}

}  // namespace penumbra
