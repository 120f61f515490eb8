// Shapes as triangles: the icosphere, the capsule from its halves, flat shapes and marching
// cubes, and the bound of each tessellation's distance to the true surface.
#include "renderer/collision/shape_triangles.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "renderer/collision/gjk.h"
#include "renderer/shapes/marching_cubes.h"

namespace penumbra {

namespace {

// The unit icosphere: the icosahedron's 20 faces, each split into 4 `levels` times, every new
// corner pushed onto the sphere. Counter-clockwise seen from outside.
void icosphere(int levels, std::vector<DVec3>& points, std::vector<uint32_t>& tris) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  points = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
            {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (DVec3& p : points) p = p * (1 / length(p));
  tris = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,  11, 10, 2,  10, 7, 6, 7, 1, 8,
          3, 9,  4, 3, 4, 2, 3, 2, 6, 3, 6, 8,  3, 8,  9,  4, 9, 5, 2, 4,  11, 6,  2,  10, 8,  6, 7, 9, 8, 1};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> middle;
    auto mid = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = middle.find(key);
      if (it != middle.end()) return it->second;
      const DVec3 m = points[a] + points[b];
      points.push_back(m * (1 / length(m)));
      return middle[key] = uint32_t(points.size() - 1);
    };
    std::vector<uint32_t> next;
    next.reserve(tris.size() * 4);
    for (size_t i = 0; i < tris.size(); i += 3) {
      const uint32_t a = tris[i], b = tris[i + 1], c = tris[i + 2];
      const uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    tris = std::move(next);
  }
}

void check_range(const char* what, int value, int lo, int hi) {
  if (value < lo || value > hi)
    throw std::invalid_argument(std::string(what) + " " + std::to_string(value) + " is outside [" +
                                std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

// Spheres and capsules: the icosphere scaled by the radius, its upper half (y > 0) moved up by
// half_height and the rest down. The bound: the radius less the least distance from the axis
// segment to a triangle (each triangle is the convex hull of points on the surface, so the
// segment's nearest triangle is where the surface is farthest from the triangles).
ShapeTriangles round_shape(double radius, double half_height, int levels) {
  std::vector<DVec3> unit;
  std::vector<uint32_t> tris;
  icosphere(levels, unit, tris);
  ShapeTriangles out;
  out.indices = tris;
  std::vector<DVec3> placed;
  for (const DVec3& u : unit) {
    const DVec3 p{u.x * radius, u.y * radius + (u.y > 0 ? half_height : -half_height), u.z * radius};
    placed.push_back(p);
    out.positions.push_back({float(p.x), float(p.y), float(p.z)});
  }
  const DVec3 axis[2] = {{0, -half_height, 0}, {0, half_height, 0}};
  double nearest = radius;
  for (size_t i = 0; i < tris.size(); i += 3) {
    const DVec3 corners[3] = {placed[tris[i]], placed[tris[i + 1]], placed[tris[i + 2]]};
    const ConvexDistance d = gjk_distance({axis, 0}, {corners, 0});
    nearest = std::min(nearest, d.distance);
  }
  // The float corners move the triangles by at most their rounding.
  out.error = radius - nearest + 1e-7 * (radius + half_height);
  return out;
}

}  // namespace

ShapeTriangles shape_triangles(const Shape& shape, const ShapeTrianglesConfig& config) {
  check_range("subdivisions", config.subdivisions, 0, 6);
  check_range("disk segments", config.disk_segments, 3, 65536);
  check_range("implicit resolution", config.implicit_resolution, 1, 1024);
  ShapeTriangles out;
  switch (shape.kind) {
    case ShapeKind::Box: {
      const Vec3f h = shape.half_size;
      for (int i = 0; i < 8; ++i)
        out.positions.push_back({i & 1 ? h.x : -h.x, i & 2 ? h.y : -h.y, i & 4 ? h.z : -h.z});
      const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                               {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
      for (const auto& f : faces)
        for (int k : {0, 1, 2, 0, 2, 3}) out.indices.push_back(uint32_t(f[k]));
      return out;
    }
    case ShapeKind::Sphere:
      return round_shape(shape.radius, 0, config.subdivisions);
    case ShapeKind::Capsule:
      return round_shape(shape.radius, shape.half_height, config.subdivisions);
    case ShapeKind::Segment: {  // the capsule turned onto the axis p0-p1
      const Vec3f d = shape.p1 - shape.p0;
      const float len = length(d);
      out = round_shape(shape.radius, 0.5 * len, config.subdivisions);
      const Vec3f a = len > 0 ? d / len : Vec3f{0, 1, 0};
      Vec3f e1, e2;
      orthonormal_basis(a, e1, e2);
      const Vec3f mid = (shape.p0 + shape.p1) * 0.5f;
      for (Vec3f& q : out.positions) q = mid + e1 * q.x + a * q.y + e2 * q.z;
      // (e1, a, e2) may be left-handed: keep the faces counter-clockwise seen from outside.
      if (dot(cross(e1, a), e2) < 0)
        for (size_t i = 0; i < out.indices.size(); i += 3) std::swap(out.indices[i + 1], out.indices[i + 2]);
      return out;
    }
    case ShapeKind::Splat:  // a density without a surface: no triangles
      out.closed = false;
      return out;
    case ShapeKind::Plane: {
      const float x = shape.half_size.x, z = shape.half_size.z;
      out.positions = {{-x, 0, -z}, {x, 0, -z}, {x, 0, z}, {-x, 0, z}};
      out.indices = {0, 2, 1, 0, 3, 2};  // counter-clockwise seen from +Y
      out.closed = false;
      return out;
    }
    case ShapeKind::Disk: {
      const int n = config.disk_segments;
      out.positions.push_back({0, 0, 0});
      for (int i = 0; i < n; ++i) {
        const double a = 2 * 3.14159265358979323846 * i / n;
        out.positions.push_back({float(shape.radius * std::cos(a)), 0, float(shape.radius * std::sin(a))});
      }
      for (int i = 0; i < n; ++i)
        out.indices.insert(out.indices.end(), {0, uint32_t(1 + (i + 1) % n), uint32_t(1 + i)});
      out.closed = false;
      out.error = shape.radius * (1 - std::cos(3.14159265358979323846 / n)) + 1e-7 * shape.radius;
      return out;
    }
    case ShapeKind::Implicit: {
      if (shape.sdf_bounds.empty())
        throw std::invalid_argument("the implicit shape is unbounded and has no surface to mesh");
      IsosurfaceMesh iso = extract_isosurface(shape.sdf, shape.sdf_bounds, config.implicit_resolution);
      out.positions = std::move(iso.positions);
      out.indices = std::move(iso.indices);
      const Vec3f e = shape.sdf_bounds.hi - shape.sdf_bounds.lo;
      const double cell = double(std::max({e.x, e.y, e.z})) / config.implicit_resolution;
      out.error = cell * std::sqrt(3.0);
      return out;
    }
  }
  return out;
}

ShapeTrianglesCount shape_triangles_count(const Shape& shape, const ShapeTrianglesConfig& config) {
  check_range("subdivisions", config.subdivisions, 0, 6);
  check_range("disk segments", config.disk_segments, 3, 65536);
  check_range("implicit resolution", config.implicit_resolution, 1, 1024);
  const uint64_t faces = uint64_t(20) << (2 * config.subdivisions);
  switch (shape.kind) {
    case ShapeKind::Box:
      return {8, 12};
    case ShapeKind::Sphere:
    case ShapeKind::Capsule:
    case ShapeKind::Segment:
      return {faces / 2 + 2, faces};
    case ShapeKind::Plane:
      return {4, 2};
    case ShapeKind::Splat:
      return {};
    case ShapeKind::Disk:
      return {uint64_t(config.disk_segments) + 1, uint64_t(config.disk_segments)};
    case ShapeKind::Implicit: {
      if (shape.sdf_bounds.empty()) return {};
      const uint64_t mesh = marching_cubes_bytes(shape.sdf_bounds, config.implicit_resolution) -
                            marching_cubes_work_bytes(shape.sdf_bounds, config.implicit_resolution);
      return {mesh / 48, 2 * (mesh / 48)};
    }
  }
  return {};
}

}  // namespace penumbra
