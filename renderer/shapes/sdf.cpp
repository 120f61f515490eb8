// SDF primitives (closed forms), CSG operators, noise displacement, Lipschitz bounds and sphere
// tracing.
#include "renderer/shapes/sdf.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

namespace {

float length2(float x, float y) {
  return std::sqrt(x * x + y * y);
}

float box_distance(Vec3f p, Vec3f half) {
  const Vec3f q = abs(p) - half;
  return length(max(q, Vec3f{})) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
}

// Capped cone with radius r1 at y = -h and r2 at y = +h, exact distance (the nearer of the
// distances to the caps and to the slanted side in the (radial, y) half-plane).
float capped_cone_distance(Vec3f p, float h, float r1, float r2) {
  const float qx = length2(p.x, p.z), qy = p.y;
  const float k2x = r2 - r1, k2y = 2 * h;
  const float cax = qx - std::min(qx, qy < 0 ? r1 : r2), cay = std::abs(qy) - h;
  const float t = std::clamp(((r2 - qx) * k2x + (h - qy) * k2y) / (k2x * k2x + k2y * k2y), 0.0f, 1.0f);
  const float cbx = qx - r2 + k2x * t, cby = qy - h + k2y * t;
  const float s = (cbx < 0 && cay < 0) ? -1.0f : 1.0f;
  return s * std::sqrt(std::min(cax * cax + cay * cay, cbx * cbx + cby * cby));
}

// Polynomial smooth minimum with blend radius k > 0: equals min(a, b) where |a - b| >= k; its
// gradient is h grad a + (1 - h) grad b, a convex combination.
float smooth_min(float a, float b, float k) {
  const float h = std::clamp(0.5f + 0.5f * (b - a) / k, 0.0f, 1.0f);
  return b + (a - b) * h - k * h * (1 - h);
}

float primitive(const SdfTree& tree, const SdfNode& n, Vec3f p) {
  switch (n.kind) {
    case SdfKind::Sphere:
      return length(p) - n.size.x;
    case SdfKind::Box:
      return box_distance(p, n.size);
    case SdfKind::RoundBox:
      return box_distance(p, n.size - Vec3f{n.radius, n.radius, n.radius}) - n.radius;
    case SdfKind::Capsule: {
      const Vec3f q{p.x, p.y - std::clamp(p.y, -n.size.y, n.size.y), p.z};
      return length(q) - n.radius;
    }
    case SdfKind::Cylinder: {
      const float dx = length2(p.x, p.z) - n.radius, dy = std::abs(p.y) - n.size.y;
      return std::min(std::max(dx, dy), 0.0f) + length2(std::max(dx, 0.0f), std::max(dy, 0.0f));
    }
    case SdfKind::Cone:
      return capped_cone_distance(p, n.size.y, n.radius, 0);
    case SdfKind::Torus:
      return length2(length2(p.x, p.z) - n.size.x, p.y) - n.radius;
    case SdfKind::HalfSpace:
      return dot(n.normal, p) - n.offset;
    case SdfKind::ConvexPolyhedron: {
      float d = -kInfinity;
      for (int i = n.first_plane; i < n.first_plane + n.plane_count; ++i) {
        const Vec4f& pl = tree.planes[size_t(i)];
        d = std::max(d, pl.x * p.x + pl.y * p.y + pl.z * p.z - pl.w);
      }
      return d;
    }
    case SdfKind::Polyhedron:
      return size_t(n.polyhedron) < tree.polyhedra.size()
                 ? solid_mesh_signed_distance(tree.polyhedra[size_t(n.polyhedron)], p)
                 : kInfinity;
    default:
      return kInfinity;
  }
}

// The noise a Displace node adds at its local point p, with its gradient in that frame.
Noise3 displacement(const SdfTree& tree, const SdfNode& n, Vec3f p) {
  const SdfDisplacement& d = tree.displacements[size_t(n.displacement)];
  const Noise3 noise = fractal_noise(d.table, p * d.frequency, d.params);
  return {d.amplitude * noise.value, noise.grad * (d.amplitude * d.frequency)};
}

float eval(const SdfTree& tree, int index, Vec3f p_parent, int depth) {
  const SdfNode& n = tree.nodes[size_t(index)];
  const Vec3f p = apply_point(n.to_local, p_parent);
  if (!is_operator(n.kind)) return primitive(tree, n, p);
  if (depth >= kMaxSdfDepth) return kInfinity;
  const float a = eval(tree, n.a, p, depth + 1);
  if (n.kind == SdfKind::Complement) return -a;
  if (n.kind == SdfKind::Displace) return a + displacement(tree, n, p).value;
  const float b = eval(tree, n.b, p, depth + 1);
  switch (n.kind) {
    case SdfKind::Union:
      return std::min(a, b);
    case SdfKind::Intersection:
      return std::max(a, b);
    case SdfKind::Subtraction:
      return std::max(a, -b);
    case SdfKind::SmoothUnion:
      return smooth_min(a, b, n.radius);
    case SdfKind::SmoothIntersection:
      return -smooth_min(-a, -b, n.radius);
    case SdfKind::SmoothSubtraction:
      return -smooth_min(-a, b, n.radius);
    default:
      return kInfinity;
  }
}

// The analytic gradient of a primitive's distance in its local frame (the cone, whose closest
// feature is awkward to track, by central differences of its closed form).
Vec3f primitive_gradient(const SdfTree& tree, const SdfNode& n, Vec3f p) {
  const auto sgn = [](float x) { return x < 0 ? -1.0f : 1.0f; };
  switch (n.kind) {
    case SdfKind::Sphere:
      return p;
    case SdfKind::Box:
    case SdfKind::RoundBox: {
      const Vec3f h = n.kind == SdfKind::Box ? n.size : n.size - Vec3f{n.radius, n.radius, n.radius};
      const Vec3f q = abs(p) - h;
      const Vec3f outside = max(q, Vec3f{});
      if (dot(outside, outside) > 0)
        return {sgn(p.x) * outside.x, sgn(p.y) * outside.y, sgn(p.z) * outside.z};
      const int k = q.x >= q.y && q.x >= q.z ? 0 : (q.y >= q.z ? 1 : 2);
      return {k == 0 ? sgn(p.x) : 0.0f, k == 1 ? sgn(p.y) : 0.0f, k == 2 ? sgn(p.z) : 0.0f};
    }
    case SdfKind::Capsule:
      return {p.x, p.y - std::clamp(p.y, -n.size.y, n.size.y), p.z};
    case SdfKind::Cylinder: {
      const float r = length2(p.x, p.z);
      const Vec3f radial = r > 0 ? Vec3f{p.x / r, 0, p.z / r} : Vec3f{1, 0, 0};
      const float dx = r - n.radius, dy = std::abs(p.y) - n.size.y;
      const Vec3f axial{0, sgn(p.y), 0};
      if (dx > 0 && dy > 0) return radial * dx + axial * dy;
      return dx > dy ? radial : axial;
    }
    case SdfKind::Torus: {
      const float r = length2(p.x, p.z);
      const Vec3f radial = r > 0 ? Vec3f{p.x / r, 0, p.z / r} : Vec3f{1, 0, 0};
      return radial * (r - n.size.x) + Vec3f{0, p.y, 0};
    }
    case SdfKind::HalfSpace:
      return n.normal;
    case SdfKind::ConvexPolyhedron: {
      float best = -kInfinity;
      Vec3f g{0, 1, 0};
      for (int i = n.first_plane; i < n.first_plane + n.plane_count; ++i) {
        const Vec4f& pl = tree.planes[size_t(i)];
        const float d = pl.x * p.x + pl.y * p.y + pl.z * p.z - pl.w;
        if (d > best) best = d, g = {pl.x, pl.y, pl.z};
      }
      return g;
    }
    case SdfKind::Polyhedron:
      return size_t(n.polyhedron) < tree.polyhedra.size()
                 ? solid_mesh_gradient(tree.polyhedra[size_t(n.polyhedron)], p)
                 : Vec3f{0, 1, 0};
    default: {  // Cone
      const float h = 1e-4f * std::max({n.size.y, n.radius, 1e-6f});
      const Vec3f dx{h, 0, 0}, dy{0, h, 0}, dz{0, 0, h};
      return {primitive(tree, n, p + dx) - primitive(tree, n, p - dx),
              primitive(tree, n, p + dy) - primitive(tree, n, p - dy),
              primitive(tree, n, p + dz) - primitive(tree, n, p - dz)};
    }
  }
}

// Weight h of the first operand in smooth_min(a, b, k): its gradient is h ga + (1 - h) gb.
float smooth_weight(float a, float b, float k) {
  return std::clamp(0.5f + 0.5f * (b - a) / k, 0.0f, 1.0f);
}

// The value and the (unnormalised) gradient of node `index` at p_parent, in the parent's frame:
// grad f(x) = L^T grad g(L x + t) for the node's to_local = (L, t).
float eval_gradient(const SdfTree& tree, int index, Vec3f p_parent, Vec3f& grad, int depth) {
  const SdfNode& n = tree.nodes[size_t(index)];
  const Vec3f p = apply_point(n.to_local, p_parent);
  float value = 0;
  Vec3f g{0, 0, 0};
  if (!is_operator(n.kind)) {
    value = primitive(tree, n, p);
    g = normalize(primitive_gradient(tree, n, p));
  } else if (depth >= kMaxSdfDepth) {
    grad = {0, 0, 0};
    return kInfinity;
  } else {
    Vec3f ga, gb;
    const float a = eval_gradient(tree, n.a, p, ga, depth + 1);
    if (n.kind == SdfKind::Complement) {
      value = -a, g = -ga;
    } else if (n.kind == SdfKind::Displace) {
      const Noise3 d = displacement(tree, n, p);
      value = a + d.value, g = ga + d.grad;
    } else {
      const float b = eval_gradient(tree, n.b, p, gb, depth + 1);
      switch (n.kind) {
        case SdfKind::Union:
          value = std::min(a, b), g = a <= b ? ga : gb;
          break;
        case SdfKind::Intersection:
          value = std::max(a, b), g = a >= b ? ga : gb;
          break;
        case SdfKind::Subtraction:
          value = std::max(a, -b), g = a >= -b ? ga : -gb;
          break;
        case SdfKind::SmoothUnion: {
          const float h = smooth_weight(a, b, n.radius);
          value = smooth_min(a, b, n.radius), g = ga * h + gb * (1 - h);
          break;
        }
        case SdfKind::SmoothIntersection: {
          const float h = smooth_weight(-a, -b, n.radius);
          value = -smooth_min(-a, -b, n.radius), g = ga * h + gb * (1 - h);
          break;
        }
        default: {  // SmoothSubtraction
          const float h = smooth_weight(-a, b, n.radius);
          value = -smooth_min(-a, b, n.radius), g = ga * h - gb * (1 - h);
        }
      }
    }
  }
  const auto& m = n.to_local.m;  // L^T g
  grad = {m[0][0] * g.x + m[1][0] * g.y + m[2][0] * g.z, m[0][1] * g.x + m[1][1] * g.y + m[2][1] * g.z,
          m[0][2] * g.x + m[1][2] * g.y + m[2][2] * g.z};
  return value;
}

// |grad (amplitude x noise(frequency x p))| <= |amplitude| x frequency x the noise's bound.
float displacement_lipschitz(const SdfDisplacement& d) {
  return std::abs(d.amplitude) * d.frequency * fractal_gradient_bound(d.params);
}

float lipschitz(const SdfTree& tree, int index, int depth) {
  const SdfNode& n = tree.nodes[size_t(index)];
  float l = 1;
  if (is_operator(n.kind) && depth < kMaxSdfDepth) {
    l = lipschitz(tree, n.a, depth + 1);
    if (n.kind == SdfKind::Displace)
      l += displacement_lipschitz(tree.displacements[size_t(n.displacement)]);
    else if (n.kind != SdfKind::Complement)
      l = std::max(l, lipschitz(tree, n.b, depth + 1));
  }
  return l * max_singular_value(n.to_local);
}

}  // namespace

bool is_operator(SdfKind kind) {
  return kind >= SdfKind::Union;
}

bool is_unary(SdfKind kind) {
  return kind == SdfKind::Complement || kind == SdfKind::Displace;
}

float sdf_eval(const SdfTree& tree, int node, Vec3f p) {
  return eval(tree, node, p, 0);
}

float sdf_eval(const SdfTree& tree, Vec3f p) {
  return tree.root < 0 ? kInfinity : eval(tree, tree.root, p, 0);
}

float sdf_lipschitz(const SdfTree& tree) {
  return tree.root < 0 ? 1.0f : lipschitz(tree, tree.root, 0);
}

Vec3f sdf_gradient_normal(const SdfTree& tree, Vec3f p) {
  if (tree.root < 0) return {0, 0, 0};
  Vec3f g;
  eval_gradient(tree, tree.root, p, g, 0);
  return is_finite(g) ? normalize(g) : Vec3f{0, 0, 0};
}

Vec3f sdf_normal(const SdfTree& tree, Vec3f p, float h) {
  const Vec3f dx{h, 0, 0}, dy{0, h, 0}, dz{0, 0, h};
  const Vec3f g{sdf_eval(tree, p + dx) - sdf_eval(tree, p - dx),
                sdf_eval(tree, p + dy) - sdf_eval(tree, p - dy),
                sdf_eval(tree, p + dz) - sdf_eval(tree, p - dz)};
  return normalize(g);
}

float max_singular_value(const Affine3f& a) {
  // Gram matrix G = A^T A (symmetric); its largest eigenvalue is sigma_max^2.
  double g[3][3];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      g[r][c] = 0;
      for (int k = 0; k < 3; ++k) g[r][c] += double(a.m[k][r]) * double(a.m[k][c]);
    }
  double vectors[3][3], values[3];
  symmetric_eigen3(g, vectors, values);
  const double top = std::max(values[0], std::max(values[1], values[2]));
  return float(std::sqrt(std::max(top, 0.0)) * (1 + 1e-6));  // rounded up: a bound stays a bound
}

// How far past a point within the tolerance sphere_trace looks for the crossing, at most, in
// tolerances.
constexpr float kMaxProbeTolerances = 1024;

namespace {

// For a tree whose root displaces its child by at most |a|: marches `ray` from t with the child's
// bound g = f_child - |a| (g <= f, so a step of g / L_child never passes the displaced surface;
// L_child is smaller than the tree's bound and g costs no noise) until g falls below a tenth of
// |a| (the shell the noise moves the surface in), with steps of at least the tracer's
// tolerance. Returns the t reached, kInfinity when the ray leaves [t, tfar] first; `steps`
// counts the evaluations.
float march_to_displacement_shell(const SdfTree& tree, const Ray& ray, const SphereTraceConfig& config,
                                  float dir_len, float t, int& steps) {
  const SdfNode& root = tree.nodes[size_t(tree.root)];
  const float reach = std::abs(tree.displacements[size_t(root.displacement)].amplitude);
  const float child_lipschitz = lipschitz(tree, root.a, 1) * max_singular_value(root.to_local);
  const float step_scale = 1.0f / (child_lipschitz * dir_len);
  while (steps < config.max_steps && t <= ray.tfar) {
    const float g = eval(tree, root.a, apply_point(root.to_local, ray.org + ray.dir * t), 1) - reach;
    ++steps;
    const float eps = std::max(config.absolute_epsilon, config.relative_epsilon * t * dir_len);
    if (!(g > std::max(0.1f * reach, eps * child_lipschitz))) return t;
    t += std::max(g * step_scale, eps / dir_len);
  }
  return t <= ray.tfar ? t : kInfinity;
}

// Whether sphere_trace first marches to the displacement shell: a Displace root that displaces.
bool shell_march_applies(const SdfTree& tree) {
  const SdfNode& root = tree.nodes[size_t(tree.root)];
  return root.kind == SdfKind::Displace && tree.displacements[size_t(root.displacement)].amplitude != 0;
}

}  // namespace

bool sphere_trace(const SdfTree& tree, float lipschitz_bound, const Ray& ray, const SphereTraceConfig& config,
                  float& t_hit, int& steps) {
  steps = 0;
  const float dir_len = length(ray.dir);
  if (!(dir_len > 0) || !(lipschitz_bound > 0) || tree.root < 0) return false;
  const float step_scale = 1.0f / (lipschitz_bound * dir_len);  // |f| * step_scale never passes the surface
  float t = ray.tnear;
  if (shell_march_applies(tree)) {
    t = march_to_displacement_shell(tree, ray, config, dir_len, t, steps);
    if (!(t <= ray.tfar)) return false;
  }
  const bool moved = t > ray.tnear;  // a ray moved to the shell is no longer at its start
  float prev_t = t, prev_f = 0;
  int iteration = 0;
  // Bisection of a bracketed crossing [lo, hi] (f(lo) has the sign of flo) to float precision.
  const auto bisect = [&](float lo, float hi, float flo) {
    for (int i = 0; i < 40 && hi - lo > 1e-7f * std::max(1.0f, hi); ++i) {
      const float mid = 0.5f * (lo + hi);
      if (mid == lo || mid == hi) break;  // neighbouring floats
      const float fm = sdf_eval(tree, ray.org + ray.dir * mid);
      ++steps;
      if ((fm < 0) == (flo < 0))
        lo = mid, flo = fm;
      else
        hi = mid;
    }
    return hi;
  };
  while (steps < config.max_steps && t <= ray.tfar) {
    const float f = sdf_eval(tree, ray.org + ray.dir * t);
    ++steps;
    ++iteration;
    const float eps = std::max(config.absolute_epsilon, config.relative_epsilon * t * dir_len);
    if (iteration > 1 && (f < 0) != (prev_f < 0)) {  // the minimum step crossed the surface
      t_hit = bisect(prev_t, t, prev_f);
      return t_hit <= ray.tfar;
    }
    if (std::abs(f) / lipschitz_bound < eps) {
      // Within the tolerance: refine to the crossing if it lies within two tolerances ahead, or
      // within twice the secant estimate from the last step while |f| falls: where L exceeds
      // the ray's slope |df/dt| (displaced surfaces, grazing rays) the steps shrink
      // geometrically and stop up to eps L / slope before the crossing. At the ray's start a
      // hit needs that crossing: a ray leaving the surface (or continued just past a hit)
      // starts within the tolerance and must not find that surface again.
      float ahead = 2 * eps / dir_len;
      if (t > prev_t && std::abs(prev_f) > std::abs(f))
        ahead = std::min(std::max(ahead, 2 * (t - prev_t) * std::abs(f) / (std::abs(prev_f) - std::abs(f))),
                         kMaxProbeTolerances * eps / dir_len);
      const float probe = std::min(t + ahead, ray.tfar);
      const float fp = sdf_eval(tree, ray.org + ray.dir * probe);
      ++steps;
      const bool crossing = (fp < 0) != (f < 0);
      if (crossing || iteration > 1 || moved) {
        t_hit = crossing ? bisect(t, probe, f) : t;
        return true;
      }
    }
    prev_t = t;
    prev_f = f;
    t += std::max(std::abs(f) * step_scale, eps / dir_len);
  }
  return false;
}

}  // namespace penumbra
