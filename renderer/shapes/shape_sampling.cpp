// Area sampling of analytic shapes and cone sampling of spheres.
#include "renderer/shapes/shape_sampling.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/rng.h"

namespace penumbra {

namespace {

// Shirley and Chiu's concentric map of [0,1)^2 onto the unit disc ("A Low Distortion Map
// Between Disk and Square", 1997).
Vec2f concentric_disk(Vec2f u) {
  const float a = 2 * u.x - 1, b = 2 * u.y - 1;
  if (a == 0 && b == 0) return {0, 0};
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = (kPi / 4) * (b / a);
  } else {
    r = b;
    phi = kPi / 2 - (kPi / 4) * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

// Picks one of `count` parts with probabilities proportional to `area` using u (in [0,1)) and
// rescales u to [0,1) within the chosen part.
int choose_part(const float* area, int count, float& u) {
  float total = 0;
  for (int i = 0; i < count; ++i) total += area[i];
  float x = u * total;
  for (int i = 0; i < count; ++i) {
    if (x < area[i] || i == count - 1) {
      u = std::clamp(area[i] > 0 ? x / area[i] : 0.0f, 0.0f, 0x1.fffffep-1f);
      return i;
    }
    x -= area[i];
  }
  return count - 1;
}

ShapePoint sample_box(Vec3f h, Vec2f u) {
  const float face[3] = {h.y * h.z, h.x * h.z, h.x * h.y};  // faces normal to x, y, z (each side)
  int axis = choose_part(face, 3, u.x);
  const float side = u.x < 0.5f ? -1.0f : 1.0f;  // the half of u.x picks the side
  u.x = u.x < 0.5f ? 2 * u.x : 2 * u.x - 1;
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  ShapePoint s;
  s.p[axis] = side * h[axis];
  s.p[a1] = (2 * u.x - 1) * h[a1];
  s.p[a2] = (2 * u.y - 1) * h[a2];
  s.n = Vec3f{0, 0, 0};
  s.n[axis] = side;
  return s;
}

ShapePoint sample_capsule(float r, float hh, Vec2f u) {
  const float part[2] = {4 * kPi * r * hh, 4 * kPi * r * r};  // the cylinder, the two caps
  ShapePoint s;
  if (choose_part(part, 2, u.x) == 0) {
    const float phi = 2 * kPi * u.y;
    s.n = {std::cos(phi), 0, std::sin(phi)};
    s.p = {r * s.n.x, (2 * u.x - 1) * hh, r * s.n.z};
    return s;
  }
  s.n = sample_uniform_sphere(u);
  s.p = s.n * r + Vec3f{0, s.n.y >= 0 ? hh : -hh, 0};
  return s;
}

}  // namespace

float shape_area(const Shape& shape) {
  const float r = shape.radius;
  const Vec3f h = shape.half_size;
  switch (shape.kind) {
    case ShapeKind::Sphere:
      return 4 * kPi * r * r;
    case ShapeKind::Plane:
      return 4 * h.x * h.z;
    case ShapeKind::Disk:
      return kPi * r * r;
    case ShapeKind::Box:
      return 8 * (h.x * h.y + h.y * h.z + h.z * h.x);
    case ShapeKind::Capsule:
      return 4 * kPi * r * (shape.half_height + r);
    case ShapeKind::Segment:
      return 4 * kPi * r * (0.5f * length(shape.p1 - shape.p0) + r);
    case ShapeKind::Implicit:
    case ShapeKind::Splat:  // a density, not a surface
      return 0;
  }
  return 0;
}

ShapePoint sample_shape_area(const Shape& shape, Vec2f u) {
  ShapePoint s;
  switch (shape.kind) {
    case ShapeKind::Sphere:
      s.n = sample_uniform_sphere(u);
      s.p = s.n * shape.radius;
      return s;
    case ShapeKind::Plane:
      s.p = {(2 * u.x - 1) * shape.half_size.x, 0, (2 * u.y - 1) * shape.half_size.z};
      s.n = {0, 1, 0};
      return s;
    case ShapeKind::Disk: {
      const Vec2f d = concentric_disk(u);
      s.p = {d.x * shape.radius, 0, d.y * shape.radius};
      s.n = {0, 1, 0};
      return s;
    }
    case ShapeKind::Box:
      return sample_box(shape.half_size, u);
    case ShapeKind::Capsule:
      return sample_capsule(shape.radius, shape.half_height, u);
    case ShapeKind::Segment: {  // the capsule's sample turned onto the axis p0-p1
      const Vec3f d = shape.p1 - shape.p0;
      const float len = length(d);
      const ShapePoint c = sample_capsule(shape.radius, 0.5f * len, u);
      const Vec3f a = len > 0 ? d / len : Vec3f{0, 1, 0};
      Vec3f e1, e2;
      orthonormal_basis(a, e1, e2);
      const Vec3f mid = (shape.p0 + shape.p1) * 0.5f;
      s.p = mid + e1 * c.p.x + a * c.p.y + e2 * c.p.z;
      s.n = e1 * c.n.x + a * c.n.y + e2 * c.n.z;
      return s;
    }
    case ShapeKind::Splat:
      s.p = shape.p0;
      break;
    case ShapeKind::Implicit:
      break;
  }
  s.n = {0, 1, 0};
  return s;
}

float area_scale(const Affine3f& to_world, const Affine3f& inverse, Vec3f n) {
  const auto& m = to_world.m;
  const float det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                    m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                    m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  const float s = std::fabs(det) * length(apply_normal(inverse, n));
  return std::isfinite(s) ? s : 0.0f;
}

float similarity_scale(const Affine3f& to_world) {
  const auto& m = to_world.m;
  const Vec3f c0{m[0][0], m[1][0], m[2][0]}, c1{m[0][1], m[1][1], m[2][1]}, c2{m[0][2], m[1][2], m[2][2]};
  const float l0 = dot(c0, c0), l1 = dot(c1, c1), l2 = dot(c2, c2);
  const float tol = 1e-4f * l0;
  if (!(l0 > 0) || !std::isfinite(l0) || std::fabs(l1 - l0) > tol || std::fabs(l2 - l0) > tol ||
      std::fabs(dot(c0, c1)) > tol || std::fabs(dot(c1, c2)) > tol || std::fabs(dot(c0, c2)) > tol)
    return 0;
  return std::sqrt(l0);
}

float sphere_cone_one_minus_cos(float radius, float distance) {
  if (!(distance > radius) || !(radius > 0)) return 0;
  const float sin2 = (radius / distance) * (radius / distance);
  // Below sin^2 = 0.00068523 (about 1.5 degrees) 1 - sqrt(1 - x) loses digits: its series.
  if (sin2 < 0.00068523f) return sin2 / 2;
  return 1 - std::sqrt(std::max(0.0f, 1 - sin2));
}

bool sample_sphere_cone(Vec3f c, float r, Vec3f ref, Vec2f u, ShapePoint& out) {
  const Vec3f d = c - ref;
  const float dc = length(d);
  if (!(dc > r) || !(r > 0) || !std::isfinite(dc)) return false;
  // pbrt-v4 Sphere::Sample(ctx, u): a direction in the cone, then the point of the sphere that
  // the direction meets first, found through the angle alpha at the centre.
  const float sin_max = r / dc, sin2_max = sin_max * sin_max;
  const float cos_max = std::sqrt(std::max(0.0f, 1 - sin2_max));
  float cos_t = (cos_max - 1) * u.x + 1;
  float sin2_t = 1 - cos_t * cos_t;
  if (sin2_max < 0.00068523f) {
    sin2_t = sin2_max * u.x;
    cos_t = std::sqrt(1 - sin2_t);
  }
  const float cos_a = sin2_t / sin_max + cos_t * std::sqrt(std::max(0.0f, 1 - sin2_t / sin2_max));
  const float sin_a = std::sqrt(std::max(0.0f, 1 - cos_a * cos_a));
  const float phi = 2 * kPi * u.y;
  const Vec3f z = d / dc;
  Vec3f x, y;
  orthonormal_basis(z, x, y);
  // The normal at the point, from the centre's side: -(sin a cos phi x + sin a sin phi y + cos a z).
  out.n = -(x * (sin_a * std::cos(phi)) + y * (sin_a * std::sin(phi)) + z * cos_a);
  out.p = c + out.n * r;
  return true;
}

}  // namespace penumbra
