// Shared (interpenetration) volumes: clipping, the lens, and the adaptive cell quadrature.
#include "renderer/collision/shared_volume.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "renderer/collision/gjk.h"

namespace penumbra {

namespace {

DVec3 min3(DVec3 a, DVec3 b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
DVec3 max3(DVec3 a, DVec3 b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}

// An axis-aligned box in double precision.
struct DBox {
  DVec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  void add(DVec3 p) { lo = min3(lo, p), hi = max3(hi, p); }
  bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
};

DBox meet(const DBox& a, const DBox& b) {
  return {max3(a.lo, b.lo), min3(a.hi, b.hi)};
}

// The same box rounded outwards to float.
Bounds3f outward(const DBox& b) {
  return {{std::nextafter(float(b.lo.x), -INFINITY), std::nextafter(float(b.lo.y), -INFINITY),
           std::nextafter(float(b.lo.z), -INFINITY)},
          {std::nextafter(float(b.hi.x), INFINITY), std::nextafter(float(b.hi.y), INFINITY),
           std::nextafter(float(b.hi.z), INFINITY)}};
}

// The adaptive cell quadrature of the banner over the box [lo, hi]: `da` and `db` give, at a
// point, a signed distance to each solid's surface that is exact inside (negative) and no more
// than the true distance outside; `margin` absorbs their rounding.
template <class DistA, class DistB>
VolumeEstimate cell_quadrature(const DistA& da, const DistB& db, const DBox& region, double margin,
                               double target, uint64_t max_cells) {
  VolumeEstimate out;
  if (region.empty()) {
    out.exact = true;
    return out;
  }
  // Cubic cells (the least diagonal for their volume) from a cube over the region: cells
  // beyond the region lie outside a solid's box and settle at once.
  std::vector<DVec3> level{region.lo}, next;
  std::vector<uint8_t> state;
  const DVec3 extent = region.hi - region.lo;
  const double side = std::max({extent.x, extent.y, extent.z});
  DVec3 size{side, side, side};
  double inside = 0;
  for (;;) {
    const double reach = 0.5 * length(size) + margin;
    const double cell_volume = size.x * size.y * size.z;
    state.assign(level.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, level.size(), 256),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t i = r.begin(); i != r.end(); ++i) {
                          const DVec3 c = level[i] + size * 0.5;
                          const double a = da(c);
                          if (a > reach) continue;  // wholly outside a
                          const double b = db(c);
                          if (b > reach) continue;
                          state[i] = a < -reach && b < -reach ? 1 : 2;  // wholly inside both, or unsettled
                        }
                      });
    out.cells += level.size();
    uint64_t open = 0;
    for (uint8_t s : state) {
      if (s == 1) inside += cell_volume;
      open += s == 2;
    }
    const double half_open = 0.5 * double(open) * cell_volume;
    if (half_open <= target || out.cells + 8 * open > max_cells) {
      out.volume = inside + half_open;
      out.error = half_open;
      return out;
    }
    next.clear();
    next.reserve(8 * open);
    const DVec3 half = size * 0.5;
    for (size_t i = 0; i < level.size(); ++i)
      if (state[i] == 2)
        for (int k = 0; k < 8; ++k)
          next.push_back(level[i] + DVec3{k & 1 ? half.x : 0, k & 2 ? half.y : 0, k & 4 ? half.z : 0});
    level.swap(next);
    size = half;
  }
}

bool polyhedral(ProxyKind k) {
  return k == ProxyKind::Aabb || k == ProxyKind::Obb || k == ProxyKind::Hull || k == ProxyKind::Kdop ||
         k == ProxyKind::Composite;
}

bool ball(ProxyKind k) {
  return k == ProxyKind::Sphere || k == ProxyKind::Ritter;
}

// A polyhedral proxy's convex parts as plane sets with their boxes.
struct PlanePart {
  std::vector<DPlane> planes;
  DBox box;
  double volume = 0;
};

std::vector<PlanePart> plane_parts(const Proxy& p) {
  std::vector<PlanePart> out;
  if (p.kind == ProxyKind::Aabb || p.kind == ProxyKind::Obb) {
    PlanePart part;
    for (int i = 0; i < 3; ++i) {
      const DVec3 n = p.box.axis[i];
      const double c = dot(n, p.box.center);
      part.planes.push_back(
          {n, c + p.box.half.x * (i == 0) + p.box.half.y * (i == 1) + p.box.half.z * (i == 2)});
      part.planes.push_back(
          {n * -1, -c + p.box.half.x * (i == 0) + p.box.half.y * (i == 1) + p.box.half.z * (i == 2)});
    }
    DVec3 corners[8];
    box_corners(p.box, corners);
    for (const DVec3& c : corners) part.box.add(c);
    part.volume = 8 * p.box.half.x * p.box.half.y * p.box.half.z;
    out.push_back(std::move(part));
    return out;
  }
  for (const ConvexPolyhedron& c : p.parts) {
    if (c.vertices.empty()) continue;
    PlanePart part;
    part.planes = c.planes;
    part.volume = c.volume;
    for (const DVec3& v : c.vertices) part.box.add(v);
    out.push_back(std::move(part));
  }
  return out;
}

DBox proxy_box(const Proxy& p) {
  DBox b;
  const DVec3 r3{1, 1, 1};
  if (ball(p.kind)) {
    b.add(p.sphere.center - r3 * p.sphere.radius);
    b.add(p.sphere.center + r3 * p.sphere.radius);
  } else if (p.kind == ProxyKind::Capsule) {
    for (const DVec3& e : {p.capsule.a, p.capsule.b}) {
      b.add(e - r3 * p.capsule.radius);
      b.add(e + r3 * p.capsule.radius);
    }
  } else {
    for (const PlanePart& part : plane_parts(p)) b.add(part.box.lo), b.add(part.box.hi);
  }
  return b;
}

// A signed distance to the proxy's surface, exact inside and a lower bound outside (planes: the
// largest plane distance; a union of parts: the least over them).
struct ProxyDistance {
  const Proxy& proxy;
  std::vector<PlanePart> parts;
  explicit ProxyDistance(const Proxy& p) : proxy(p) {
    if (polyhedral(p.kind)) parts = plane_parts(p);
  }
  double operator()(DVec3 q) const {
    if (ball(proxy.kind)) return length(q - proxy.sphere.center) - proxy.sphere.radius;
    if (proxy.kind == ProxyKind::Capsule) {
      DVec3 c1, c2;
      return segment_distance(q, q, proxy.capsule.a, proxy.capsule.b, c1, c2) - proxy.capsule.radius;
    }
    double best = INFINITY;
    for (const PlanePart& part : parts) {
      double s = -INFINITY;
      for (const DPlane& pl : part.planes) s = std::max(s, dot(pl.n, q) - pl.d);
      best = std::min(best, s);
    }
    return best;
  }
};

}  // namespace

double convex_intersection_volume(std::span<const DPlane> a, std::span<const DPlane> b,
                                  const Bounds3f& start) {
  Polytope p(start);
  for (std::span<const DPlane> planes : {a, b})
    for (const DPlane& pl : planes) {
      if (p.empty()) return 0;
      p = p.clip(pl.n, pl.d, false);
    }
  return p.volume();
}

double ball_intersection_volume(const BoundingSphere& a, const BoundingSphere& b) {
  const double d = length(a.center - b.center), r1 = a.radius, r2 = b.radius;
  if (d >= r1 + r2) return 0;
  if (d <= std::abs(r1 - r2)) return 4.0 / 3.0 * std::numbers::pi * std::pow(std::min(r1, r2), 3);
  // The two caps of the lens (e.g. Weisstein, "Sphere-Sphere Intersection", MathWorld).
  const double s = r1 + r2 - d;
  return std::numbers::pi * s * s * (d * d + 2 * d * (r1 + r2) - 3 * (r1 - r2) * (r1 - r2)) / (12 * d);
}

namespace {

// True if no two of the parts share a volume (touching faces share none).
bool parts_disjoint(const std::vector<PlanePart>& parts) {
  for (size_t i = 0; i < parts.size(); ++i)
    for (size_t j = i + 1; j < parts.size(); ++j) {
      const DBox box = meet(parts[i].box, parts[j].box);
      if (box.empty()) continue;
      // Rounding on a shared face leaves slivers far below this.
      const double sliver = 1e-9 * std::min(parts[i].volume, parts[j].volume);
      if (convex_intersection_volume(parts[i].planes, parts[j].planes, outward(box)) > sliver) return false;
    }
  return true;
}

}  // namespace

VolumeEstimate proxy_intersection_volume(const Proxy& a, const Proxy& b, const SharedVolumeConfig& config) {
  VolumeEstimate out;
  if (polyhedral(a.kind) && polyhedral(b.kind) &&
      (a.kind != ProxyKind::Composite || parts_disjoint(plane_parts(a))) &&
      (b.kind != ProxyKind::Composite || parts_disjoint(plane_parts(b)))) {
    out.exact = true;
    const std::vector<PlanePart> pa = plane_parts(a), pb = plane_parts(b);
    for (const PlanePart& x : pa)
      for (const PlanePart& y : pb) {
        const DBox start = meet(x.box, y.box);
        if (!start.empty()) out.volume += convex_intersection_volume(x.planes, y.planes, outward(start));
      }
    return out;
  }
  if (ball(a.kind) && ball(b.kind)) {
    out.exact = true;
    out.volume = ball_intersection_volume(a.sphere, b.sphere);
    return out;
  }
  const DBox region = meet(proxy_box(a), proxy_box(b));
  const double scale = length(region.lo) + length(region.hi) + 1e-300;
  const double target = config.relative_error * std::min(proxy_volume(a), proxy_volume(b));
  return cell_quadrature(ProxyDistance(a), ProxyDistance(b), region, 1e-12 * scale, target, config.max_cells);
}

VolumeEstimate mesh_intersection_volume(std::span<const SolidMesh> a, std::span<const SolidMesh> b,
                                        const SharedVolumeConfig& config) {
  // A union of solids: inside if inside any, at the least distance of them outside.
  struct Union {
    std::span<const SolidMesh> meshes;
    DBox box;
    double volume = 0, tolerance = 0;
    explicit Union(std::span<const SolidMesh> m) : meshes(m) {
      for (const SolidMesh& s : m) {
        box.add(to_dvec(s.bounds.lo)), box.add(to_dvec(s.bounds.hi));
        volume = std::max(volume, s.bsp.volume);
        tolerance = std::max(tolerance, s.bsp.tolerance);
      }
    }
    double operator()(DVec3 p) const {
      const Vec3f q{float(p.x), float(p.y), float(p.z)};
      double best = INFINITY;
      for (const SolidMesh& s : meshes) {
        // A mesh whose box is farther than the best answer cannot lower it (its signed distance
        // is at least the distance to its box).
        const Vec3f lo = s.bounds.lo - q, hi = q - s.bounds.hi;
        const double dx = std::max({0.0f, lo.x, hi.x}), dy = std::max({0.0f, lo.y, hi.y}),
                     dz = std::max({0.0f, lo.z, hi.z});
        if (std::sqrt(dx * dx + dy * dy + dz * dz) >= best) continue;
        best = std::min(best, double(solid_mesh_signed_distance(s, q)));
      }
      return best;
    }
  };
  const Union ua(a), ub(b);
  const DBox region = meet(ua.box, ub.box);
  // Distances are single precision at points rounded to float, and points within the solid
  // BSP's tolerance of a surface may answer either way.
  const double scale = length(region.lo) + length(region.hi) + length(region.hi - region.lo);
  const double margin = 2 * std::max(ua.tolerance, ub.tolerance) + 1e-6 * scale;
  const double target = config.relative_error * std::min(ua.volume, ub.volume);
  return cell_quadrature(ua, ub, region, margin, target, config.max_cells);
}

}  // namespace penumbra
