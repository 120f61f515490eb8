// Exact ray tests of the analytic primitives (in double, as roots of their equations), bounds of
// CSG trees, and the per-kind dispatch every acceleration structure's leaves call.
#include "renderer/shapes/shape.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace penumbra {

namespace {

struct DRay {
  double ox, oy, oz, dx, dy, dz, tmin, tmax;
};

DRay to_double(const Ray& r) {
  return {r.org.x,       r.org.y, r.org.z, r.dir.x, r.dir.y, r.dir.z, std::max(double(r.tnear), 0.0),
          double(r.tfar)};
}

// Keeps the smaller of `best` and t when t lies in the ray's range.
void consider(const DRay& r, double t, double& best) {
  if (t >= r.tmin && t <= r.tmax && t < best) best = t;
}

// Both roots of a t^2 + 2 b t + c = 0 (a > 0), or false if none: the stable form that avoids
// cancellation between -b and the square root (Press et al., Numerical Recipes, 5.6).
bool solve_quadratic(double a, double b, double c, double& t0, double& t1) {
  const double disc = b * b - a * c;
  if (!(a > 0) || !(disc >= 0)) return false;
  const double q = -(b + std::copysign(std::sqrt(disc), b));
  t0 = q / a;
  t1 = q != 0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

// Roots of the sphere |o + t d - centre|^2 = r^2, each kept if `keep(y at t)` holds.
template <typename Keep>
void sphere_roots(const DRay& r, double cy, double radius, double& best, Keep keep) {
  const double oy = r.oy - cy;
  const double a = r.dx * r.dx + r.dy * r.dy + r.dz * r.dz;
  const double b = r.ox * r.dx + oy * r.dy + r.oz * r.dz;
  const double c = r.ox * r.ox + oy * oy + r.oz * r.oz - radius * radius;
  double t0, t1;
  if (!solve_quadratic(a, b, c, t0, t1)) return;
  if (keep(r.oy + t0 * r.dy)) consider(r, t0, best);
  if (keep(r.oy + t1 * r.dy)) consider(r, t1, best);
}

double intersect_capsule(const DRay& r, double radius, double h) {
  double best = kInfinity;
  // The side: the infinite cylinder x^2 + z^2 = r^2, kept where |y| <= h.
  const double a = r.dx * r.dx + r.dz * r.dz;
  double t0, t1;
  if (solve_quadratic(a, r.ox * r.dx + r.oz * r.dz, r.ox * r.ox + r.oz * r.oz - radius * radius, t0, t1)) {
    if (std::abs(r.oy + t0 * r.dy) <= h) consider(r, t0, best);
    if (std::abs(r.oy + t1 * r.dy) <= h) consider(r, t1, best);
  }
  // The caps: hemispheres beyond the segment's ends.
  sphere_roots(r, h, radius, best, [&](double y) { return y >= h; });
  sphere_roots(r, -h, radius, best, [&](double y) { return y <= -h; });
  return best;
}

// The capsule about p0-p1: the ray in a frame whose +Y runs along the axis from its midpoint,
// then intersect_capsule (a point, p0 == p1, is a sphere: any frame).
double intersect_segment(const DRay& r, Vec3f p0, Vec3f p1, double radius) {
  const double mx = 0.5 * (double(p0.x) + p1.x), my = 0.5 * (double(p0.y) + p1.y),
               mz = 0.5 * (double(p0.z) + p1.z);
  double ax = double(p1.x) - p0.x, ay = double(p1.y) - p0.y, az = double(p1.z) - p0.z;
  const double len = std::sqrt(ax * ax + ay * ay + az * az);
  if (len > 0) {
    ax /= len, ay /= len, az /= len;
  } else {
    ax = 0, ay = 1, az = 0;
  }
  // An orthonormal frame (e1, a, e2) about the axis (Duff et al. 2017).
  const double sign = std::copysign(1.0, az), a = -1 / (sign + az), b = ax * ay * a;
  const double e1[3] = {1 + sign * ax * ax * a, sign * b, -sign * ax};
  const double e2[3] = {b, sign + ay * ay * a, -ay};
  const double o[3] = {r.ox - mx, r.oy - my, r.oz - mz};
  auto along = [](const double* e, const double* v) { return e[0] * v[0] + e[1] * v[1] + e[2] * v[2]; };
  const double axis[3] = {ax, ay, az}, d[3] = {r.dx, r.dy, r.dz};
  const DRay local{along(e1, o),   along(axis, o), along(e2, o), along(e1, d),
                   along(axis, d), along(e2, d),   r.tmin,       r.tmax};
  return intersect_capsule(local, radius, 0.5 * len);
}

// The nearest point of the segment p0-p1 to p, as the parameter from p0 (0) to p1 (1).
float segment_param(Vec3f p0, Vec3f p1, Vec3f p) {
  const Vec3f d = p1 - p0;
  const float dd = dot(d, d);
  return dd > 0 ? std::clamp(dot(p - p0, d) / dd, 0.0f, 1.0f) : 0.0f;
}

double intersect_box(const DRay& r, Vec3f half) {
  const double o[3] = {r.ox, r.oy, r.oz}, d[3] = {r.dx, r.dy, r.dz}, hs[3] = {half.x, half.y, half.z};
  double t_in = -kInfinity, t_out = kInfinity;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0) {
      if (std::abs(o[k]) > hs[k]) return kInfinity;
      continue;
    }
    double ta = (-hs[k] - o[k]) / d[k], tb = (hs[k] - o[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t_in = std::max(t_in, ta);
    t_out = std::min(t_out, tb);
  }
  if (t_in > t_out) return kInfinity;
  double best = kInfinity;
  consider(r, t_in, best);
  if (best == kInfinity) consider(r, t_out, best);
  return best;
}

// Flat shapes at y = 0: the crossing of the plane, kept if `inside(x, z)` holds.
template <typename Inside>
double intersect_flat(const DRay& r, Inside inside) {
  if (r.dy == 0) return kInfinity;
  const double t = -r.oy / r.dy;
  double best = kInfinity;
  if (inside(r.ox + t * r.dx, r.oz + t * r.dz)) consider(r, t, best);
  return best;
}

bool intersect_implicit(const Shape& s, const Ray& ray, ShapeHit& hit) {
  // Clip the ray to the tree's bounds, then sphere trace the part inside them.
  if (s.sdf_bounds.empty()) return false;
  const Vec3f pad = s.sdf_bounds.extent() * 1e-4f + Vec3f{1e-6f, 1e-6f, 1e-6f};
  const Vec3f lo = s.sdf_bounds.lo - pad, hi = s.sdf_bounds.hi + pad;
  float t0 = std::max(ray.tnear, 0.0f), t1 = ray.tfar;
  for (int k = 0; k < 3; ++k) {
    const float o = ray.org[k], d = ray.dir[k];
    if (d == 0) {
      if (o < lo[k] || o > hi[k]) return false;
      continue;
    }
    float ta = (lo[k] - o) / d, tb = (hi[k] - o) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  Ray clipped = ray;
  clipped.tnear = t0;
  clipped.tfar = t1;
  float t = 0;
  int steps = 0;
  const bool found = sphere_trace(s.sdf, s.lipschitz, clipped, s.trace, t, steps);
  hit.evaluations = uint32_t(steps);
  if (!found || t < std::max(ray.tnear, 0.0f) || t > ray.tfar) return false;
  hit.t = t;
  return true;
}

// A box and whether the set it bounds is unbounded (then the box is meaningless).
struct TreeBox {
  Bounds3f box;
  bool unbounded = false;
};

TreeBox unbounded_box() {
  return {Bounds3f{}, true};
}

TreeBox symmetric_box(float x, float y, float z) {
  return {Bounds3f{{-x, -y, -z}, {x, y, z}}, false};
}

// The box of the convex polyhedron {p : n_i . p <= d_i + delta}: its vertices are the feasible
// intersections of three planes. A cube of half size 1e7 is added to the planes, and a vertex on
// that cube means the polyhedron is unbounded.
TreeBox polyhedron_box(const std::vector<Vec4f>& planes, float delta) {
  constexpr double kFar = 1e7;
  std::vector<std::array<double, 4>> all;
  for (const Vec4f& p : planes) all.push_back({p.x, p.y, p.z, double(p.w) + delta});
  for (int k = 0; k < 3; ++k)
    for (double s : {1.0, -1.0}) {
      std::array<double, 4> q{0, 0, 0, kFar};
      q[size_t(k)] = s;
      all.push_back(q);
    }
  TreeBox out;
  bool far = false;
  const size_t n = all.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      for (size_t k = j + 1; k < n; ++k) {
        const auto &a = all[i], &b = all[j], &c = all[k];
        // Cramer's rule on [a; b; c] x = (a3, b3, c3).
        const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                           a[2] * (b[0] * c[1] - b[1] * c[0]);
        if (std::abs(det) < 1e-12) continue;
        const double x = (a[3] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[3] * c[2] - b[2] * c[3]) +
                          a[2] * (b[3] * c[1] - b[1] * c[3])) /
                         det;
        const double y = (a[0] * (b[3] * c[2] - b[2] * c[3]) - a[3] * (b[0] * c[2] - b[2] * c[0]) +
                          a[2] * (b[0] * c[3] - b[3] * c[0])) /
                         det;
        const double z = (a[0] * (b[1] * c[3] - b[3] * c[1]) - a[1] * (b[0] * c[3] - b[3] * c[0]) +
                          a[3] * (b[0] * c[1] - b[1] * c[0])) /
                         det;
        bool feasible = true;
        for (const auto& p : all)
          if (p[0] * x + p[1] * y + p[2] * z > p[3] + 1e-6 * (1 + std::abs(p[3]))) feasible = false;
        if (!feasible) continue;
        if (std::max({std::abs(x), std::abs(y), std::abs(z)}) > 0.5 * kFar) far = true;
        out.box = merge(out.box, Vec3f{float(x), float(y), float(z)});
      }
  out.unbounded = far;
  return out;
}

TreeBox primitive_box(const SdfTree& tree, const SdfNode& n, float delta) {
  const float d = delta;
  switch (n.kind) {
    case SdfKind::Sphere:
      return symmetric_box(n.size.x + d, n.size.x + d, n.size.x + d);
    case SdfKind::Box:
    case SdfKind::RoundBox:
      return symmetric_box(n.size.x + d, n.size.y + d, n.size.z + d);
    case SdfKind::Capsule:
      return symmetric_box(n.radius + d, n.size.y + n.radius + d, n.radius + d);
    case SdfKind::Cylinder:
    case SdfKind::Cone:
      return symmetric_box(n.radius + d, n.size.y + d, n.radius + d);
    case SdfKind::Torus:
      return symmetric_box(n.size.x + n.radius + d, n.radius + d, n.size.x + n.radius + d);
    case SdfKind::ConvexPolyhedron: {
      const std::vector<Vec4f> planes(tree.planes.begin() + n.first_plane,
                                      tree.planes.begin() + n.first_plane + n.plane_count);
      return polyhedron_box(planes, d);
    }
    case SdfKind::Polyhedron: {  // the mesh's box: every point with f <= d lies within d of it
      if (size_t(n.polyhedron) >= tree.polyhedra.size()) return {Bounds3f{}, false};
      const Bounds3f& b = tree.polyhedra[size_t(n.polyhedron)].bounds;
      if (b.empty()) return {b, false};
      return {Bounds3f{b.lo - Vec3f{d, d, d}, b.hi + Vec3f{d, d, d}}, false};
    }
    default:  // HalfSpace
      return unbounded_box();
  }
}

TreeBox overlap(const TreeBox& a, const TreeBox& b) {
  if (a.unbounded) return b;
  if (b.unbounded) return a;
  return {Bounds3f{max(a.box.lo, b.box.lo), min(a.box.hi, b.box.hi)}, false};
}

// The box (in the parent's frame) of {p : f_node(p) <= delta}. Values pass through transforms
// unchanged (f_node(p) = g(to_local p)), so delta does too; the smooth union widens it, since
// smin(a, b) >= min(a, b) - k / 4, and Displace by |amplitude|, since |fractal_noise| <= 1.
TreeBox node_box(const SdfTree& tree, int index, float delta, int depth) {
  if (index < 0 || size_t(index) >= tree.nodes.size() || depth > kMaxSdfDepth) return unbounded_box();
  const SdfNode& n = tree.nodes[size_t(index)];
  TreeBox local;
  switch (n.kind) {
    case SdfKind::Union:
    case SdfKind::SmoothUnion: {
      const float d = n.kind == SdfKind::Union ? delta : delta + 0.25f * n.radius;
      const TreeBox a = node_box(tree, n.a, d, depth + 1), b = node_box(tree, n.b, d, depth + 1);
      local = {merge(a.box, b.box), a.unbounded || b.unbounded};
      break;
    }
    case SdfKind::Intersection:
    case SdfKind::SmoothIntersection:
      local = overlap(node_box(tree, n.a, delta, depth + 1), node_box(tree, n.b, delta, depth + 1));
      break;
    case SdfKind::Subtraction:
    case SdfKind::SmoothSubtraction:
      local = node_box(tree, n.a, delta, depth + 1);
      break;
    case SdfKind::Complement:
      local = unbounded_box();
      break;
    case SdfKind::Displace: {
      const float amplitude = tree.displacements[size_t(n.displacement)].amplitude;
      local = node_box(tree, n.a, delta + std::abs(amplitude), depth + 1);
      break;
    }
    default:
      local = primitive_box(tree, n, delta);
  }
  if (local.unbounded || local.box.empty()) return local;
  Affine3f to_parent;
  if (!inverse(n.to_local, to_parent)) return unbounded_box();
  return {transform_bounds(to_parent, local.box), false};
}

Vec2f sphere_uv(Vec3f p) {
  const float r = length(p);
  float phi = std::atan2(-p.z, p.x);
  if (phi < 0) phi += 2 * kPi;
  const float theta = std::acos(std::clamp(p.y / std::max(r, 1e-30f), -1.0f, 1.0f));
  return {phi / (2 * kPi), theta / kPi};
}

}  // namespace

const char* shape_kind_name(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::Sphere:
      return "sphere";
    case ShapeKind::Plane:
      return "plane";
    case ShapeKind::Disk:
      return "disk";
    case ShapeKind::Box:
      return "box";
    case ShapeKind::Capsule:
      return "capsule";
    case ShapeKind::Implicit:
      return "implicit";
    case ShapeKind::Segment:
      return "segment";
    case ShapeKind::Splat:
      return "splat";
  }
  return "unknown";
}

Bounds3f sdf_tree_bounds(const SdfTree& tree) {
  if (tree.root < 0) return {};
  const TreeBox b = node_box(tree, tree.root, 0, 0);
  return b.unbounded ? Bounds3f{} : b.box;
}

Shape make_implicit_shape(SdfTree tree, const SphereTraceConfig& trace) {
  Shape s;
  s.kind = ShapeKind::Implicit;
  s.lipschitz = sdf_lipschitz(tree);
  s.sdf_bounds = sdf_tree_bounds(tree);
  s.sdf = std::move(tree);
  s.trace = trace;
  return s;
}

Shape make_segment_shape(Vec3f p0, Vec3f p1, float radius, uint32_t element) {
  Shape s;
  s.kind = ShapeKind::Segment;
  s.p0 = p0;
  s.p1 = p1;
  s.radius = radius;
  s.element = element;
  return s;
}

Shape make_splat_shape(Vec3f centre, Vec4f q, Vec3f scale, float opacity, uint32_t element) {
  Shape s;
  s.kind = ShapeKind::Splat;
  s.p0 = centre;
  s.element = element;
  const double big = std::max({double(scale.x), double(scale.y), double(scale.z)});
  if (!(big > 0) || !std::isfinite(big) || !(opacity > 0) || !std::isfinite(opacity)) {
    s.half_size = {-1, -1, -1};  // empty bounds: never hit
    return s;
  }
  s.opacity = std::min(opacity, 1.0f);
  const double x = q.x, y = q.y, z = q.z, w = q.w;
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  const double sd[3] = {std::max(double(scale.x), 1e-3 * big), std::max(double(scale.y), 1e-3 * big),
                        std::max(double(scale.z), 1e-3 * big)};
  for (int k = 0; k < 3; ++k)  // row k of S^-1 R^T is column k of R over s_k
    s.whiten[size_t(k)] = {float(r[0][k] / sd[k]), float(r[1][k] / sd[k]), float(r[2][k] / sd[k])};
  for (int a = 0; a < 3; ++a) {  // the ellipsoid's extent along axis a: sigmas |row a of R S|
    double e = 0;
    for (int k = 0; k < 3; ++k) e += (r[a][k] * sd[k]) * (r[a][k] * sd[k]);
    s.half_size[a] = float(kSplatSigmas * std::sqrt(e) * (1 + 1e-5));
  }
  return s;
}

bool splat_response(const Shape& s, const Ray& ray, double& t, double& m2, double& alpha) {
  const double o[3] = {double(ray.org.x) - s.p0.x, double(ray.org.y) - s.p0.y, double(ray.org.z) - s.p0.z};
  const double d[3] = {ray.dir.x, ray.dir.y, ray.dir.z};
  double ow[3], dw[3];
  for (size_t k = 0; k < 3; ++k) {
    const Vec3f w = s.whiten[k];
    ow[k] = w.x * o[0] + w.y * o[1] + w.z * o[2];
    dw[k] = w.x * d[0] + w.y * d[1] + w.z * d[2];
  }
  const double dd = dw[0] * dw[0] + dw[1] * dw[1] + dw[2] * dw[2];
  if (!(dd > 0)) return false;
  t = -(ow[0] * dw[0] + ow[1] * dw[1] + ow[2] * dw[2]) / dd;
  m2 = 0;
  for (int k = 0; k < 3; ++k) m2 += (ow[k] + t * dw[k]) * (ow[k] + t * dw[k]);
  alpha = s.opacity * std::exp(-0.5 * m2);
  return std::isfinite(t) && std::isfinite(m2);
}

Bounds3f shape_bounds(const Shape& s) {
  switch (s.kind) {
    case ShapeKind::Sphere:
      return {{-s.radius, -s.radius, -s.radius}, {s.radius, s.radius, s.radius}};
    case ShapeKind::Plane:
      return {{-s.half_size.x, 0, -s.half_size.z}, {s.half_size.x, 0, s.half_size.z}};
    case ShapeKind::Disk:
      return {{-s.radius, 0, -s.radius}, {s.radius, 0, s.radius}};
    case ShapeKind::Box:
      return {-s.half_size, s.half_size};
    case ShapeKind::Capsule: {
      const float y = s.half_height + s.radius;
      return {{-s.radius, -y, -s.radius}, {s.radius, y, s.radius}};
    }
    case ShapeKind::Implicit:
      return s.sdf_bounds;
    case ShapeKind::Segment: {
      if (!(s.radius >= 0)) return {};
      const Vec3f r{s.radius, s.radius, s.radius};
      return {min(s.p0, s.p1) - r, max(s.p0, s.p1) + r};
    }
    case ShapeKind::Splat:
      if (!(s.half_size.x >= 0)) return {};
      return {s.p0 - s.half_size, s.p0 + s.half_size};
  }
  return {};
}

bool intersect_shape(const Shape& s, const Ray& ray, ShapeHit& hit) {
  hit = ShapeHit{};
  if (s.kind == ShapeKind::Implicit) return intersect_implicit(s, ray, hit);
  const DRay r = to_double(ray);
  if (!(r.tmin <= r.tmax)) return false;
  double t = kInfinity;
  switch (s.kind) {
    case ShapeKind::Sphere:
      sphere_roots(r, 0, s.radius, t, [](double) { return true; });
      break;
    case ShapeKind::Plane: {
      const double hx = s.half_size.x, hz = s.half_size.z;
      t = intersect_flat(r, [&](double x, double z) { return std::abs(x) <= hx && std::abs(z) <= hz; });
      break;
    }
    case ShapeKind::Disk: {
      const double r2 = double(s.radius) * s.radius;
      t = intersect_flat(r, [&](double x, double z) { return x * x + z * z <= r2; });
      break;
    }
    case ShapeKind::Box:
      t = intersect_box(r, s.half_size);
      break;
    case ShapeKind::Capsule:
      t = intersect_capsule(r, s.radius, s.half_height);
      break;
    case ShapeKind::Segment:
      t = intersect_segment(r, s.p0, s.p1, s.radius);
      break;
    case ShapeKind::Splat: {
      double ts = 0, m2 = 0, alpha = 0;
      if (splat_response(s, ray, ts, m2, alpha) && m2 <= double(kSplatSigmas) * kSplatSigmas &&
          alpha >= kSplatMinAlpha)
        t = ts;
      break;
    }
    case ShapeKind::Implicit:
      break;
  }
  if (!(t < kInfinity)) return false;
  const float tf = float(t);
  if (!(tf >= std::max(ray.tnear, 0.0f) && tf <= ray.tfar)) return false;  // rounding at the ends
  hit.t = tf;
  return true;
}

Vec2f shape_uv_delta(const Shape& shape, Vec2f a, Vec2f b) {
  Vec2f d{b.x - a.x, b.y - a.y};
  if (shape.kind == ShapeKind::Sphere || shape.kind == ShapeKind::Capsule) d.x -= std::round(d.x);
  return d;
}

ShapeSurface shape_surface(const Shape& s, Vec3f p, float h) {
  ShapeSurface out;
  switch (s.kind) {
    case ShapeKind::Sphere:
      out.n = normalize(p);
      out.uv = sphere_uv(p);
      out.has_uv = true;
      break;
    case ShapeKind::Plane:
      out.n = {0, 1, 0};
      out.uv = {0.5f + 0.5f * p.x / s.half_size.x, 0.5f + 0.5f * p.z / s.half_size.z};
      out.has_uv = true;
      break;
    case ShapeKind::Disk:
      out.n = {0, 1, 0};
      out.uv = {0.5f + 0.5f * p.x / s.radius, 0.5f + 0.5f * p.z / s.radius};
      out.has_uv = true;
      break;
    case ShapeKind::Box: {
      // The face whose plane the point is nearest, relative to the half extents.
      const Vec3f q{std::abs(p.x) / s.half_size.x, std::abs(p.y) / s.half_size.y,
                    std::abs(p.z) / s.half_size.z};
      const int k = q.x >= q.y && q.x >= q.z ? 0 : (q.y >= q.z ? 1 : 2);
      Vec3f n{0, 0, 0};
      n[k] = p[k] < 0 ? -1.0f : 1.0f;
      out.n = n;
      const int a = (k + 1) % 3, b = (k + 2) % 3;
      out.uv = {0.5f + 0.5f * p[a] / s.half_size[a], 0.5f + 0.5f * p[b] / s.half_size[b]};
      out.has_uv = true;
      break;
    }
    case ShapeKind::Capsule: {
      const Vec3f axis{0, std::clamp(p.y, -s.half_height, s.half_height), 0};
      out.n = normalize(p - axis);
      float phi = std::atan2(-p.z, p.x);
      if (phi < 0) phi += 2 * kPi;
      const float total = 2 * (s.half_height + s.radius);
      out.uv = {phi / (2 * kPi), 0.5f - p.y / total};
      out.has_uv = true;
      break;
    }
    case ShapeKind::Segment: {
      const float u = segment_param(s.p0, s.p1, p);
      const Vec3f n = p - (s.p0 + (s.p1 - s.p0) * u);
      out.n = dot(n, n) > 0 ? normalize(n) : Vec3f{0, 1, 0};
      out.uv = {u, 0};
      out.has_uv = true;
      break;
    }
    case ShapeKind::Splat: {  // the gradient of the Mahalanobis distance: W^T W (p - p0)
      const Vec3f o = p - s.p0;
      const Vec3f n = s.whiten[0] * dot(s.whiten[0], o) + s.whiten[1] * dot(s.whiten[1], o) +
                      s.whiten[2] * dot(s.whiten[2], o);
      out.n = dot(n, n) > 0 && is_finite(n) ? normalize(n) : Vec3f{0, 1, 0};
      break;
    }
    case ShapeKind::Implicit:
      out.n = sdf_gradient_normal(s.sdf, p);
      if (!is_finite(out.n) || dot(out.n, out.n) == 0) out.n = sdf_normal(s.sdf, p, h);
      if (!is_finite(out.n) || dot(out.n, out.n) == 0) out.n = {0, 1, 0};
      break;
  }
  return out;
}

Vec3f snap_to_shape(const Shape& s, Vec3f p) {
  switch (s.kind) {
    case ShapeKind::Sphere: {
      const float r = length(p);
      return r > 0 ? p * (s.radius / r) : p;
    }
    case ShapeKind::Plane:
    case ShapeKind::Disk:
      return {p.x, 0, p.z};
    case ShapeKind::Segment: {  // radially from the nearest axis point
      const Vec3f c = s.p0 + (s.p1 - s.p0) * segment_param(s.p0, s.p1, p);
      const float r = length(p - c);
      return r > 0 ? c + (p - c) * (s.radius / r) : p;
    }
    case ShapeKind::Box: {  // onto the face nearest relative to the half extents
      const Vec3f q{std::abs(p.x) / s.half_size.x, std::abs(p.y) / s.half_size.y,
                    std::abs(p.z) / s.half_size.z};
      const int k = q.x >= q.y && q.x >= q.z ? 0 : (q.y >= q.z ? 1 : 2);
      Vec3f out = p;
      const float h = k == 0 ? s.half_size.x : (k == 1 ? s.half_size.y : s.half_size.z);
      (k == 0 ? out.x : (k == 1 ? out.y : out.z)) = p[k] < 0 ? -h : h;
      return out;
    }
    default:
      return p;
  }
}

float shape_hit_tolerance(const Shape& s, float t, float dir_length) {
  if (s.kind != ShapeKind::Implicit) return 0;
  const float eps = std::max(s.trace.absolute_epsilon, s.trace.relative_epsilon * t * dir_length);
  return eps;
}

}  // namespace penumbra
