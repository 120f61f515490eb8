// Test helpers for the per-ray accelerator cross-check: ray sets (camera, random, surface
// bounces, rays starting on surfaces, shadow rays) and the comparison rules:
// hit/miss identical; t within 1e-5 relative; primitive ids identical unless both primitives are
// hit at the same t (a tie on a shared edge); occluded() == closest hit exists.
#pragma once

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "renderer/accel/factory.h"
#include "renderer/core/geometry.h"
#include "renderer/core/rng.h"
#include "renderer/scene/camera.h"

namespace penumbra::test {

inline constexpr float kTimeEps = 1e-5f;

struct NamedAccel {
  std::string name;
  std::unique_ptr<Accelerator> accel;
};

/// Which back ends a check builds besides Embree and brute force (which it always builds):
/// those `keep` accepts by name; all when it is empty.
using AccelFilter = std::function<bool(const std::string&)>;

/// Every back end over `views` that `keep` accepts, the BVH in each width and with spatial
/// splits, in accelerator_names() order ("brute" keeps references: views must outlive the result).
inline std::vector<NamedAccel> build_all(std::span<const GeometryView> views, const AccelConfig& config = {},
                                         const AccelFilter& keep = {}) {
  std::vector<NamedAccel> out;
  for (const auto& n : accelerator_names()) {
    if (keep && n != "embree" && n != "brute" && !keep(n)) continue;
    out.push_back({n, make_accelerator(n, views, config)});
    if (n != "bvh" || config.bvh.width != 0) continue;
    // Every BVH width, not only the CPU's widest that "bvh" builds by default.
    for (int width : {2, 4}) {
      AccelConfig c = config;
      c.bvh.width = width;
      out.push_back({"bvh/width=" + std::to_string(width), make_accelerator("bvh", views, c)});
    }
    // Spatial splits: primitives referenced from several leaves.
    AccelConfig c = config;
    c.bvh.spatial_alpha = 1e-5f;
    out.push_back({"bvh/spatial", make_accelerator("bvh", views, c)});
  }
  return out;
}

inline const Accelerator& find(const std::vector<NamedAccel>& all, const std::string& name) {
  for (const auto& a : all)
    if (a.name == name) return *a.accel;
  throw std::logic_error("no accelerator " + name);
}

inline std::string describe(const Ray& r) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "org (%.9g, %.9g, %.9g) dir (%.9g, %.9g, %.9g) t [%.9g, %.9g]", r.org.x,
                r.org.y, r.org.z, r.dir.x, r.dir.y, r.dir.z, r.tnear, r.tfar);
  return buf;
}

inline std::string describe(const Hit& h) {
  if (!h.valid()) return "miss";
  char buf[160];
  std::snprintf(buf, sizeof buf, "t %.9g geom %u prim %u uv (%.6g, %.6g)", h.t, h.geom_id, h.prim_id, h.u,
                h.v);
  return buf;
}

/// True if the ray meets the shape at distance t within eps: its hit from just before t lands
/// within eps of t.
inline bool shape_meets_at(const Shape& shape, const Ray& r, float t, double eps) {
  Ray q = r;
  q.tnear = std::max(r.tnear, float(t - eps));
  q.tfar = std::min(r.tfar, float(t + eps));
  ShapeHit sh;
  return intersect_shape(shape, q, sh);
}

/// True if the ray meets triangle (geom, prim) (or the shape of view geom) at distance t
/// (tolerance eps in t), in double precision with a small barycentric tolerance: the test for a
/// legitimate tie.
inline bool meets_at(std::span<const GeometryView> views, const Ray& r, uint32_t geom, uint32_t prim, float t,
                     double eps) {
  if (geom < views.size() && views[geom].shape)
    return prim == 0 && shape_meets_at(*views[geom].shape, r, t, eps);
  if (geom >= views.size() || size_t(prim) * 3 + 2 >= views[geom].indices.size()) return false;
  const auto& m = views[geom];
  const Vec3f a = m.positions[m.indices[prim * 3]], b = m.positions[m.indices[prim * 3 + 1]],
              c = m.positions[m.indices[prim * 3 + 2]];
  const double o[3] = {r.org.x, r.org.y, r.org.z}, d[3] = {r.dir.x, r.dir.y, r.dir.z};
  double p[3], e1[3], e2[3], ap[3];
  for (int k = 0; k < 3; ++k) p[k] = o[k] + double(t) * d[k];
  for (int k = 0; k < 3; ++k) {
    e1[k] = double(b[k]) - a[k];
    e2[k] = double(c[k]) - a[k];
    ap[k] = p[k] - a[k];
  }
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
  const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  if (nn == 0) return false;
  // Distance of p from the plane, in units of t.
  const double dist = std::fabs(n[0] * ap[0] + n[1] * ap[1] + n[2] * ap[2]) / std::sqrt(nn);
  const double dlen = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (dist > eps * dlen * 4) return false;
  // Barycentrics of p (projected): inside with a small tolerance.
  auto dot = [](const double* x, const double* y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
  const double d00 = dot(e1, e1), d01 = dot(e1, e2), d11 = dot(e2, e2), d20 = dot(ap, e1), d21 = dot(ap, e2);
  const double den = d00 * d11 - d01 * d01;
  if (den == 0) return false;
  const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  const double tol = 1e-4;
  return v >= -tol && w >= -tol && v + w <= 1 + tol;
}

/// The point of triangle (h.geom_id, h.prim_id) at barycentrics (h.u, h.v) (views of triangles only).
inline Vec3f point_at(std::span<const GeometryView> views, const Hit& h) {
  const auto& m = views[h.geom_id];
  const Vec3f a = m.positions[m.indices[h.prim_id * 3]], b = m.positions[m.indices[h.prim_id * 3 + 1]],
              c = m.positions[m.indices[h.prim_id * 3 + 2]];
  return a * (1 - h.u - h.v) + b * h.u + c * h.v;
}

/// Unit geometric normal of the hit triangle, or of the hit shape at the hit point.
inline Vec3f triangle_normal_of(std::span<const GeometryView> views, const Ray& r, const Hit& h) {
  const auto& m = views[h.geom_id];
  if (m.shape) return normalize(shape_surface(*m.shape, r.org + r.dir * h.t, 1e-4f).n);
  return triangle_normal(m.positions[m.indices[h.prim_id * 3]], m.positions[m.indices[h.prim_id * 3 + 1]],
                         m.positions[m.indices[h.prim_id * 3 + 2]]);
}

/// Distance between the points at (ha.u, ha.v) and (hb.u, hb.v) on the same triangle,
/// |(b - a) du + (c - a) dv| in double: independent of where the triangle sits.
inline double point_distance(std::span<const GeometryView> views, const Hit& ha, const Hit& hb) {
  const auto& m = views[ha.geom_id];
  if (m.shape) return 0;  // shapes report u = v = 0
  const Vec3f a = m.positions[m.indices[ha.prim_id * 3]], b = m.positions[m.indices[ha.prim_id * 3 + 1]],
              c = m.positions[m.indices[ha.prim_id * 3 + 2]];
  const double du = double(ha.u) - hb.u, dv = double(ha.v) - hb.v;
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double x = (double(b[k]) - a[k]) * du + (double(c[k]) - a[k]) * dv;
    d2 += x * x;
  }
  return std::sqrt(d2);
}

/// How far a float triangle test's hit point can drift on triangle `h`: the longest edge L times
/// float epsilon times the aspect L / h (h the smallest height). Negligible on well-shaped
/// triangles; on a 70 m x 5 mm sliver it is centimetres, which Embree's barycentrics show.
inline double barycentric_slack(std::span<const GeometryView> views, const Hit& hit) {
  const auto& m = views[hit.geom_id];
  if (m.shape) return 0;
  const Vec3f a = m.positions[m.indices[hit.prim_id * 3]], b = m.positions[m.indices[hit.prim_id * 3 + 1]],
              c = m.positions[m.indices[hit.prim_id * 3 + 2]];
  const double L = std::max({length(b - a), length(c - b), length(a - c)});
  const double area2 = length(cross(b - a, c - a));
  if (!(area2 > 0)) return 0;
  const double h = area2 / L;
  return 8 * 1.1920929e-7 * L * (L / h);
}

struct CrossCheckResult {
  size_t rays = 0, hits = 0;
  size_t boundary = 0;  ///< tolerated hit/miss differences at t = tnear or tfar (see cross_check)
  size_t edge = 0;      ///< tolerated hit/miss differences exactly on a triangle's boundary
  size_t hit_miss = 0, t = 0, prim = 0, uv = 0, occlusion = 0;
  std::string first;  ///< the first mismatching ray and both answers
  size_t failures() const { return hit_miss + t + prim + uv + occlusion; }
};

inline std::string summary(const std::string& what, const CrossCheckResult& r) {
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "%s: %zu rays (%zu hits, tolerated: %zu boundary, %zu edge): hit/miss %zu, t %zu, prim %zu, uv %zu, "
      "occluded %zu%s%s",
      what.c_str(), r.rays, r.hits, r.boundary, r.edge, r.hit_miss, r.t, r.prim, r.uv, r.occlusion,
      r.first.empty() ? "" : "\n  first: ", r.first.c_str());
  return buf;
}

/// A reference answer per ray, computed once.
struct Reference {
  std::vector<Ray> rays;
  std::vector<Hit> hits;
};

inline Reference reference(const Accelerator& ref, std::vector<Ray> rays) {
  Reference r{std::move(rays), {}};
  r.hits.resize(r.rays.size());
  for (size_t i = 0; i < r.rays.size(); ++i) ref.intersect(r.rays[i], r.hits[i]);
  return r;
}

/// Compares `a` with a reference on every ray. `scale` is the scene's size (bounds diagonal):
/// t agrees if |ta - tb| <= 1e-5 max(ta, tb, 0.1 scale) / max(|cos theta|, 1e-3), theta the angle
/// between the ray and the reference triangle's normal (t is ill-conditioned at grazing angles). `exact`
/// (back ends sharing the watertight test) demands identical hit/miss on every ray. Otherwise (against
/// Embree, whose triangle test rounds differently and treats triangle boundaries by its own rule) two kinds
/// of hit/miss difference are rounding or convention questions, counted but not failures:
///  - boundary: the one hit lies within 1e-4 scale of the ray's tnear or tfar (a ray starting
///    exactly on a surface, or a shadow ray ending exactly on one); likewise a t difference where
///    one side saw the surface at the origin and the other the next one;
///  - edge: the one hit lies exactly on the boundary of its triangle (a barycentric is 0 to
///    within 1e-6), as on the outline of an open mesh: Woop's test includes edges.
/// When both report the same primitive, `uv_tol` = 0 demands bit-identical u, v; otherwise the
/// two hit points p(u, v) on the triangle must agree to the t tolerance plus barycentric_slack()
/// (except at the origin).
inline CrossCheckResult cross_check(const Accelerator& a, const Reference& ref,
                                    std::span<const GeometryView> views, float scale, bool exact,
                                    float uv_tol) {
  CrossCheckResult res;
  auto note = [&](const char* what, const Ray& r, const Hit& ha, const Hit& hb) {
    if (res.first.empty())
      res.first = std::string(what) + ": " + describe(r) + " -> " + describe(ha) + " vs ref " + describe(hb);
  };
  auto tol = [&](float t1, float t2) {
    return kTimeEps * std::max({std::fabs(t1), std::fabs(t2), 0.1f * scale});
  };
  // Near the ends of the ray's interval, t is rounding noise in units of the scene's size.
  // (A ray leaving a surface at a grazing angle can re-meet it at t ~ 1e-5 scale.)
  auto near_end = [&](float t, float end) {
    return std::fabs(t - end) <= 1e-4f * std::max(scale, std::fabs(t));
  };
  auto on_edge = [](const Hit& h) {
    const float w = 1 - h.u - h.v, e = 1e-6f;
    return std::fabs(h.u) <= e || std::fabs(h.v) <= e || std::fabs(w) <= e;
  };
  for (size_t i = 0; i < ref.rays.size(); ++i) {
    const Ray& r = ref.rays[i];
    const Hit& hb = ref.hits[i];
    ++res.rays;
    Hit ha;
    const bool a_hit = a.intersect(r, ha), b_hit = hb.valid();
    res.hits += b_hit;
    if (a.occluded(r) != a_hit) {
      ++res.occlusion;
      note("occluded() disagrees with intersect()", r, ha, hb);
    }
    if (a_hit != b_hit) {
      const Hit& h = a_hit ? ha : hb;
      const float tn = std::max(r.tnear, 0.0f);
      if (!exact && (near_end(h.t, tn) || near_end(h.t, r.tfar))) {
        ++res.boundary;
      } else if (!exact && on_edge(h)) {
        ++res.edge;
      } else {
        ++res.hit_miss;
        note("hit/miss", r, ha, hb);
      }
      continue;
    }
    if (!a_hit) continue;
    // t along a ray meeting a surface at a grazing angle is ill-conditioned: a rounding-sized
    // shift of the hit point moves t by that shift / |cos theta|. Scale the tolerance by it.
    const float cos_theta = std::fabs(dot(normalize(r.dir), triangle_normal_of(views, r, hb)));
    const float grazing = 1.0f / std::max(cos_theta, 1e-3f);
    if (!(std::fabs(ha.t - hb.t) <= tol(ha.t, hb.t) * grazing)) {
      const float tn = std::max(r.tnear, 0.0f), t = std::min(ha.t, hb.t);
      if (!exact && near_end(t, tn)) {  // one side saw the surface at the origin
        ++res.boundary;
        continue;
      }
      ++res.t;
      note("t", r, ha, hb);
    } else if (ha.geom_id != hb.geom_id || ha.prim_id != hb.prim_id) {
      // A tie: acceptable only if each reported primitive really is met at the common t.
      if (!meets_at(views, r, ha.geom_id, ha.prim_id, hb.t, tol(ha.t, hb.t)) ||
          !meets_at(views, r, hb.geom_id, hb.prim_id, ha.t, tol(ha.t, hb.t))) {
        ++res.prim;
        note("primitive", r, ha, hb);
      }
    } else if (uv_tol == 0
                   ? (ha.u != hb.u || ha.v != hb.v)
                   : !(point_distance(views, ha, hb) <=
                       4 * tol(ha.t, hb.t) * grazing * length(r.dir) + barycentric_slack(views, hb)) &&
                         !near_end(std::min(ha.t, hb.t), std::max(r.tnear, 0.0f))) {
      ++res.uv;
      note("barycentrics", r, ha, hb);
    }
  }
  return res;
}

// ---- Ray sets -----------------------------------------------------------------------------------

inline Vec3f random_direction(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0, 1);
  const float a = u(rng), b = u(rng);
  return sample_uniform_sphere({a, b});
}

inline Bounds3f grown(const Bounds3f& b, float f) {
  const Vec3f e = b.extent() * f + Vec3f{1e-3f, 1e-3f, 1e-3f} * std::max(1e-6f, max_component(b.extent()));
  return {b.lo - e, b.hi + e};
}

/// n x n camera rays from three viewpoints framing `b`.
inline std::vector<Ray> camera_rays(const Bounds3f& b, int n) {
  std::vector<Ray> rays;
  const Vec3f c = b.center();
  const float r = std::max(1e-6f, length(b.extent()));
  const Vec3f eyes[3] = {c + Vec3f{0.3f, 0.4f, 1.0f} * (1.5f * r), c + Vec3f{-1.0f, 0.2f, -0.3f} * (1.5f * r),
                         c + Vec3f{0.1f, -1.2f, 0.4f} * (1.5f * r)};
  for (const Vec3f& eye : eyes) {
    const Camera cam = look_at(eye, c, Vec3f{0, 1, 0}, 0.9f);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) rays.push_back(generate_camera_ray(cam, n, n, x + 0.5f, y + 0.5f));
  }
  return rays;
}

/// Axis-parallel rays on the lines x, y in {lo, lo + step, ...} along +z and -z (and the other
/// two axes): they run through vertices, along edges and inside the planes of walls.
inline std::vector<Ray> lattice_rays(float lo, float hi, float step) {
  std::vector<Ray> rays;
  for (int axis = 0; axis < 3; ++axis)
    for (float a = lo; a <= hi; a += step)
      for (float b = lo; b <= hi; b += step)
        for (float sign : {1.0f, -1.0f}) {
          Vec3f o, d;
          o[axis] = sign > 0 ? lo - 1 : hi + 1;
          o[(axis + 1) % 3] = a;
          o[(axis + 2) % 3] = b;
          d[axis] = sign;
          rays.push_back({o, 0, d, kInfinity});
        }
  return rays;
}

/// Rays with origins in (a box around) `b` and uniform directions; every fourth is a segment.
inline std::vector<Ray> random_rays(const Bounds3f& b, int n, std::mt19937& rng) {
  const Bounds3f g = grown(b, 0.25f);
  std::uniform_real_distribution<float> u01(0, 1);
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    Vec3f o;
    for (int k = 0; k < 3; ++k) o[k] = g.lo[k] + u01(rng) * (g.hi[k] - g.lo[k]);
    Ray r{o, 0, random_direction(rng), kInfinity};
    if (i % 4 == 3) r.tfar = u01(rng) * length(g.extent());
    rays.push_back(r);
  }
  return rays;
}

struct SurfacePoint {
  Vec3f p, ng;  ///< point and geometric normal facing the ray that found it
};

/// Points where `rays` hit `ref`, computed from the barycentrics on the reference triangle (on a
/// shape: along the ray, with the shape's normal there).
inline std::vector<SurfacePoint> surface_points(const Accelerator& ref, std::span<const Ray> rays,
                                                std::span<const GeometryView> views) {
  std::vector<SurfacePoint> pts;
  for (const Ray& r : rays) {
    Hit h;
    if (!ref.intersect(r, h)) continue;
    const auto& m = views[h.geom_id];
    if (m.shape) {
      const Vec3f p = snap_to_shape(*m.shape, r.org + r.dir * h.t);
      Vec3f ng = normalize(shape_surface(*m.shape, p, 1e-4f).n);
      if (dot(ng, r.dir) > 0) ng = -ng;
      // Implicit hits lie within the tracer's tolerance of the surface: step off it by more.
      const float off = 4 * shape_hit_tolerance(*m.shape, h.t, length(r.dir));
      pts.push_back({p - normalize(r.dir) * off, ng});
      continue;
    }
    Vec3f ng =
        triangle_normal(m.positions[m.indices[h.prim_id * 3]], m.positions[m.indices[h.prim_id * 3 + 1]],
                        m.positions[m.indices[h.prim_id * 3 + 2]]);
    if (dot(ng, ng) == 0) continue;
    if (dot(ng, r.dir) > 0) ng = -ng;
    pts.push_back({point_at(views, h), ng});
  }
  return pts;
}

/// Diffuse bounces (offset origins, cosine-ish directions) and rays starting exactly on the
/// surface (no offset, any direction).
inline std::vector<Ray> bounce_rays(std::span<const SurfacePoint> pts, std::mt19937& rng) {
  std::vector<Ray> rays;
  for (const auto& s : pts) {
    Vec3f d = normalize(s.ng + random_direction(rng));
    if (!(dot(d, s.ng) > 0)) d = s.ng;
    rays.push_back({offset_ray_origin(s.p, s.ng, d), 0, d, kInfinity});
    rays.push_back({s.p, 0, random_direction(rng), kInfinity});
  }
  return rays;
}

/// Shadow rays from each surface point to each light position, stopping just short of it.
inline std::vector<Ray> shadow_rays(std::span<const SurfacePoint> pts, std::span<const Vec3f> lights) {
  std::vector<Ray> rays;
  for (const auto& s : pts)
    for (const Vec3f& l : lights) {
      const Vec3f dir = l - s.p;
      const float dist = length(dir);
      if (!(dist > 0)) continue;
      const Vec3f d = dir / dist;
      rays.push_back({offset_ray_origin(s.p, s.ng, d), 0, d, dist * (1 - 1e-4f)});
    }
  return rays;
}

/// Light positions around `b`: four corners of a box grown by half its size.
inline std::vector<Vec3f> lights_around(const Bounds3f& b) {
  const Bounds3f g = grown(b, 0.5f);
  return {g.hi, {g.lo.x, g.hi.y, g.hi.z}, {g.hi.x, g.hi.y, g.lo.z}, {g.lo.x, g.lo.y, g.hi.z}};
}

/// Rays that must miss: NaN / infinite components, zero directions, tnear > tfar.
inline std::vector<Ray> bad_rays(const Bounds3f& b) {
  const float nan = std::nanf(""), inf = kInfinity;
  const Vec3f c = b.center();
  return {{{nan, c.y, c.z}, 0, {0, 0, 1}, inf},
          {c, 0, {nan, 0, 1}, inf},
          {c, 0, {0, 0, 0}, inf},
          {c, 0, {inf, 1, 0}, inf},
          {{inf, 0, 0}, 0, {-1, 0, 0}, inf},
          {c, nan, {0, 1, 0}, inf},
          {c, 0, {0, 1, 0}, nan},
          {c, 2, {0, 1, 0}, 1},
          {c, 0, {-inf, -inf, -inf}, inf}};
}

/// The whole ray collection for a scene: camera, random, bounce, on-surface and shadow rays.
/// `scale` multiplies the counts (the [slow] variant uses more).
inline std::vector<Ray> all_rays(const Accelerator& ref, std::span<const GeometryView> views,
                                 const Bounds3f& b, std::span<const Vec3f> lights, int scale, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Ray> rays = camera_rays(b, 16 * scale);
  const std::vector<Ray> rnd = random_rays(b, 1000 * scale * scale, rng);
  rays.insert(rays.end(), rnd.begin(), rnd.end());
  std::vector<SurfacePoint> pts = surface_points(ref, rays, views);
  if (pts.size() > size_t(400 * scale * scale)) pts.resize(size_t(400 * scale * scale));
  const std::vector<Ray> bounce = bounce_rays(pts, rng);
  rays.insert(rays.end(), bounce.begin(), bounce.end());
  const std::vector<Ray> shadow = shadow_rays(pts, lights);
  rays.insert(rays.end(), shadow.begin(), shadow.end());
  const std::vector<Ray> bad = bad_rays(b);
  rays.insert(rays.end(), bad.begin(), bad.end());
  return rays;
}

// ---- Whole-scene checks (Catch assertions) --------------------------------------------------

inline Bounds3f bounds_of(std::span<const GeometryView> views) {
  Bounds3f b;
  for (const auto& m : views) {
    if (m.shape && !shape_bounds(*m.shape).empty()) b = merge(b, shape_bounds(*m.shape));
    for (Vec3f p : m.positions) b = merge(b, p);
  }
  if (b.empty()) b = {{-1, -1, -1}, {1, 1, 1}};
  return b;
}

/// Runs the cross-check of every back end against brute force and against Embree on `rays`.
/// Back ends sharing the watertight test must match brute force exactly (u, v bit for bit).
/// Brute force costs rays x triangles, so on big models it answers every k-th ray only
/// (at most ~2e8 triangle tests); Embree answers all of them.
inline void check_all(const std::string& scene, std::span<const GeometryView> views,
                      const std::vector<Ray>& rays, const AccelConfig& config = {},
                      const AccelFilter& keep = {}) {
  const auto all = build_all(views, config, keep);
  const Accelerator& brute = find(all, "brute");
  const Accelerator& embree = find(all, "embree");
  const float scale = length(bounds_of(views).extent());
  const uint64_t tris = std::max<uint64_t>(1, brute.stats().triangles);
  const size_t stride = std::max<size_t>(1, size_t(tris * rays.size() / 100'000'000ull) + 1);
  std::vector<Ray> subset;
  for (size_t i = 0; i < rays.size(); i += stride) subset.push_back(rays[i]);
  const Reference by_brute = reference(brute, subset);
  const Reference by_embree = reference(embree, rays);
  const Reference by_embree_subset = reference(embree, subset);
  for (const auto& a : all) {
    const bool own = a.name != "embree";
    if (a.name != "brute") {
      const auto rb = cross_check(*a.accel, by_brute, views, scale, own, own ? 0.0f : 1e-4f);
      INFO(summary(scene + ": " + a.name + " vs brute", rb));
      CHECK(rb.failures() == 0);
    }
    const bool slow = a.name == "brute";  // brute force answers the subset only
    const auto re =
        cross_check(*a.accel, slow ? by_embree_subset : by_embree, views, scale, a.name == "embree", 1e-4f);
    INFO(summary(scene + ": " + a.name + " vs embree", re));
    CHECK(re.failures() == 0);
    CHECK(a.accel->stats().triangles == brute.stats().triangles);
    CHECK(a.accel->stats().shapes == brute.stats().shapes);
  }
}

/// The standard ray collection (camera, random, bounces, on-surface, shadow, bad) for a scene.
inline void check_scene(const std::string& scene, std::span<const GeometryView> views,
                        std::vector<Vec3f> lights, int scale = 1, std::vector<Ray> extra = {},
                        const AccelFilter& keep = {}) {
  const Bounds3f b = bounds_of(views);
  if (lights.empty()) lights = lights_around(b);
  const auto embree = make_accelerator("embree", views);
  std::vector<Ray> rays = all_rays(*embree, views, b, lights, scale, 20261122u);
  rays.insert(rays.end(), extra.begin(), extra.end());
  check_all(scene, views, rays, {}, keep);
}

// ---- Synthetic geometry -------------------------------------------------------------------------

/// Owns the geometry of a synthetic scene and hands out views.
struct Soup {
  std::vector<std::vector<Vec3f>> positions;
  std::vector<std::vector<uint32_t>> indices;
  std::vector<GeometryView> views() const {
    std::vector<GeometryView> v;
    for (size_t i = 0; i < positions.size(); ++i) v.push_back({positions[i], indices[i]});
    return v;
  }
  void add(std::vector<Vec3f> p, std::vector<uint32_t> i) {
    positions.push_back(std::move(p));
    indices.push_back(std::move(i));
  }
  /// An n x n grid of quads in the plane axis = value, covering [lo, hi]^2 in the other two axes.
  void add_plane(int axis, float value, float lo, float hi, int n) {
    std::vector<Vec3f> p;
    std::vector<uint32_t> idx;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        Vec3f v;
        v[axis] = value;
        v[(axis + 1) % 3] = lo + (hi - lo) * float(i) / float(n);
        v[(axis + 2) % 3] = lo + (hi - lo) * float(j) / float(n);
        p.push_back(v);
      }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
        idx.insert(idx.end(), {a, b, d, a, d, c});
      }
    add(std::move(p), std::move(idx));
  }
};

/// A closed icosphere (shared vertices) of radius r around c, subdivided `level` times.
inline Soup icosphere(int level, float r, Vec3f c) {
  const float t = (1 + std::sqrt(5.0f)) / 2;
  std::vector<Vec3f> v{{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                       {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p = normalize(p);
  std::vector<uint32_t> f{0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                          4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                          6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
  for (int l = 0; l < level; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back(normalize((v[a] + v[b]) * 0.5f));
      return mid[key] = uint32_t(v.size() - 1);
    };
    std::vector<uint32_t> g;
    for (size_t i = 0; i < f.size(); i += 3) {
      const uint32_t a = f[i], b = f[i + 1], cc = f[i + 2];
      const uint32_t ab = midpoint(a, b), bc = midpoint(b, cc), ca = midpoint(cc, a);
      g.insert(g.end(), {a, ab, ca, b, bc, ab, cc, ca, bc, ab, bc, ca});
    }
    f.swap(g);
  }
  for (auto& p : v) p = c + p * r;
  Soup s;
  s.add(std::move(v), std::move(f));
  return s;
}

// ---- Instances ----------------------------------------------------------------------------------

/// World-space copies of every instance's triangles, one view per instance (geom_id = instance
/// index): the flattened scene that two-level structures must agree with. Instances with a
/// singular map get an empty view (they are never hit).
struct Flattened {
  std::vector<std::vector<Vec3f>> positions;
  std::vector<GeometryView> views;
};
inline Flattened flatten(std::span<const GeometryView> meshes, std::span<const InstanceView> instances) {
  Flattened f;
  f.positions.resize(instances.size());
  for (size_t i = 0; i < instances.size(); ++i) {
    Affine3f inv;
    if (!inverse(instances[i].to_world, inv)) continue;
    for (Vec3f p : meshes[instances[i].mesh].positions)
      f.positions[i].push_back(apply_point(instances[i].to_world, p));
  }
  for (size_t i = 0; i < instances.size(); ++i)
    f.views.push_back({f.positions[i], f.positions[i].empty() ? std::span<const uint32_t>{}
                                                              : meshes[instances[i].mesh].indices});
  return f;
}

/// Every back end built over `instances` of `meshes` against brute force over the flattened
/// copies (rounding apart: the ray is mapped into object space rather than the triangles into
/// world space), and Penumbra's own back ends against the two-level brute force exactly (the same
/// object-space rays meet the same watertight test).
inline void check_instanced(const std::string& scene, std::span<const GeometryView> meshes,
                            std::span<const InstanceView> instances, std::vector<Vec3f> lights,
                            uint32_t seed = 7, const AccelFilter& keep = {}) {
  const Flattened flat = flatten(meshes, instances);
  const Bounds3f b = bounds_of(flat.views);
  if (lights.empty()) lights = lights_around(b);
  const auto flat_brute = make_accelerator("brute", flat.views);
  const std::vector<Ray> rays = all_rays(*flat_brute, flat.views, b, lights, 1, seed);
  const Reference by_flat = reference(*flat_brute, rays);
  const auto brute = make_accelerator("brute", meshes, instances);
  const Reference by_brute = reference(*brute, rays);
  const float scale = length(b.extent());
  for (const auto& name : accelerator_names()) {
    if (keep && name != "embree" && name != "brute" && !keep(name)) continue;
    const auto a = make_accelerator(name, meshes, instances);
    const auto rf = cross_check(*a, by_flat, flat.views, scale, false, 1e-4f);
    INFO(summary(scene + ": " + name + " over instances vs brute over the flattened scene", rf));
    CHECK(rf.failures() == 0);
    CHECK(rf.hits >= rf.rays / 20);  // not a scene of misses
    if (name != "embree") {
      const auto rb = cross_check(*a, by_brute, flat.views, scale, true, 0.0f);
      INFO(summary(scene + ": " + name + " vs two-level brute", rb));
      CHECK(rb.failures() == 0);
    }
  }
}

}  // namespace penumbra::test
