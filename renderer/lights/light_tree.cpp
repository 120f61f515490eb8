// Light BVH: importance, bounds union, the SAOH build, sampling and the probability of a light.
#include "renderer/lights/light_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace penumbra {

namespace {

float safe_sqrt(float x) {
  return std::sqrt(std::max(0.0f, x));
}
float safe_acos(float x) {
  return std::acos(std::clamp(x, -1.0f, 1.0f));
}
// cos(max(0, a - b)) and sin(max(0, a - b)) from the sines and cosines of a and b in [0, pi].
float cos_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  return cos_a > cos_b ? 1.0f : cos_a * cos_b + sin_a * sin_b;
}
float sin_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  return cos_a > cos_b ? 0.0f : sin_a * cos_b - cos_a * sin_b;
}

float box_area(const Bounds3f& b) {
  if (b.empty()) return 0;
  const Vec3f d = b.extent();
  return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

// Rotation of v by `angle` about the unit axis k (Rodrigues' formula).
Vec3f rotate(Vec3f v, Vec3f k, float angle) {
  const float c = std::cos(angle), s = std::sin(angle);
  return v * c + cross(k, v) * s + k * (dot(k, v) * (1 - c));
}

// The orientation measure M_omega of Conty Estevez & Kulla 2018 (eq. 1): the solid angle of
// the normal cone widened by the emission angle, weighted by the cosine.
float orientation_measure(const LightBounds& b) {
  const float theta_o = safe_acos(b.cos_o), theta_e = safe_acos(b.cos_e);
  const float theta_w = std::min(theta_o + theta_e, kPi);
  const float sin_o = safe_sqrt(1 - b.cos_o * b.cos_o);
  return 2 * kPi * (1 - b.cos_o) +
         kPi / 2 * (2 * theta_w * sin_o - std::cos(theta_o - 2 * theta_w) - 2 * theta_o * sin_o + b.cos_o);
}

// The cost of a child with bounds b when splitting a node of box `node` along `axis`.
float split_cost(const LightBounds& b, const Bounds3f& node, int axis) {
  const Vec3f d = node.extent();
  const float kr = max_component(d) / d[axis];
  return b.phi * orientation_measure(b) * kr * box_area(b.bounds);
}

struct Builder {
  std::span<const LightBounds> lights;
  LightTree& tree;

  // Builds the subtree over ids[begin, end) (non-empty); returns its root's index.
  uint32_t build(std::vector<uint32_t>& ids, size_t begin, size_t end, uint64_t trail, int depth) {
    const uint32_t node = uint32_t(tree.nodes.size());
    tree.nodes.emplace_back();
    if (end - begin == 1) {
      tree.nodes[node] = {lights[ids[begin]], ids[begin], true};
      tree.trail[ids[begin]] = trail;
      return node;
    }
    const size_t mid = split(ids, begin, end, depth);
    build(ids, begin, mid, trail, depth + 1);
    const uint32_t second = build(ids, mid, end, trail | (uint64_t(1) << depth), depth + 1);
    tree.nodes[node].lb = merge(tree.nodes[node + 1].lb, tree.nodes[second].lb);
    tree.nodes[node].index = second;
    return node;
  }

  // Partitions ids[begin, end) and returns where the second child starts (strictly inside).
  size_t split(std::vector<uint32_t>& ids, size_t begin, size_t end, int depth) const {
    Bounds3f box, centroids;
    for (size_t i = begin; i < end; ++i) {
      box = merge(box, lights[ids[i]].bounds);
      centroids = merge(centroids, lights[ids[i]].bounds.center());
    }
    constexpr int kBuckets = 12;
    float best = kInfinity;
    int best_axis = -1, best_bucket = -1;
    for (int axis = 0; axis < 3 && depth < 32; ++axis) {
      const float lo = centroids.lo[axis], width = centroids.hi[axis] - lo;
      if (!(width > 0)) continue;
      const auto bucket_of = [&](uint32_t id) {
        const int b = int(float(kBuckets) * (lights[id].bounds.center()[axis] - lo) / width);
        return std::clamp(b, 0, kBuckets - 1);
      };
      std::array<LightBounds, kBuckets> buckets{};
      std::array<bool, kBuckets> used{};
      for (size_t i = begin; i < end; ++i) {
        const int b = bucket_of(ids[i]);
        buckets[size_t(b)] = used[size_t(b)] ? merge(buckets[size_t(b)], lights[ids[i]]) : lights[ids[i]];
        used[size_t(b)] = true;
      }
      // The bounds of buckets [0, s] and [s + 1, kBuckets) for every s, swept from each end.
      std::array<LightBounds, kBuckets> below{}, above{};
      std::array<bool, kBuckets> any_below{}, any_above{};
      for (int b = 0; b < kBuckets; ++b) {
        const size_t i = size_t(b), prev = i - 1;
        any_below[i] = used[i] || (b > 0 && any_below[prev]);
        if (b > 0 && any_below[prev])
          below[i] = used[i] ? merge(below[prev], buckets[i]) : below[prev];
        else
          below[i] = buckets[i];
      }
      for (int b = kBuckets - 1; b >= 0; --b) {
        const size_t i = size_t(b), next = i + 1;
        any_above[i] = used[i] || (b + 1 < kBuckets && any_above[next]);
        if (b + 1 < kBuckets && any_above[next])
          above[i] = used[i] ? merge(above[next], buckets[i]) : above[next];
        else
          above[i] = buckets[i];
      }
      for (int s = 0; s + 1 < kBuckets; ++s) {
        if (!any_below[size_t(s)] || !any_above[size_t(s) + 1]) continue;
        const float cost =
            split_cost(below[size_t(s)], box, axis) + split_cost(above[size_t(s) + 1], box, axis);
        if (cost < best) {
          best = cost;
          best_axis = axis;
          best_bucket = s;
        }
      }
    }
    size_t mid = (begin + end) / 2;
    if (best_axis >= 0) {
      const float lo = centroids.lo[best_axis], width = centroids.hi[best_axis] - lo;
      const auto it =
          std::partition(ids.begin() + ptrdiff_t(begin), ids.begin() + ptrdiff_t(end), [&](uint32_t id) {
            const int b = int(float(kBuckets) * (lights[id].bounds.center()[best_axis] - lo) / width);
            return std::clamp(b, 0, kBuckets - 1) <= best_bucket;
          });
      mid = size_t(it - ids.begin());
    } else {
      // No useful split (all centroids together) or deep in the tree: the median along the
      // widest axis of the centroids.
      int axis = 0;
      const Vec3f e = centroids.extent();
      if (e.y > e[axis]) axis = 1;
      if (e.z > e[axis]) axis = 2;
      std::nth_element(ids.begin() + ptrdiff_t(begin), ids.begin() + ptrdiff_t(mid),
                       ids.begin() + ptrdiff_t(end), [&](uint32_t a, uint32_t b) {
                         return lights[a].bounds.center()[axis] < lights[b].bounds.center()[axis];
                       });
    }
    if (mid == begin || mid == end) mid = (begin + end) / 2;
    return mid;
  }
};

}  // namespace

namespace {

// The terms of a node that importance reads besides its bounds.
void set_terms(LightTreeNode& node) {
  const Bounds3f& b = node.lb.bounds;
  node.centre = b.center();
  node.radius2 = dot(b.extent(), b.extent()) / 4;
  node.min_d2 = length(b.extent()) / 2;
  node.sin_o = safe_sqrt(1 - node.lb.cos_o * node.lb.cos_o);
}

// light_importance() of a node, with `n` unit or zero.
float node_importance(const LightTreeNode& node, Vec3f p, Vec3f n) {
  const LightBounds& b = node.lb;
  const Vec3f to_p = p - node.centre;
  const float dist2 = dot(to_p, to_p);
  const float d2 = std::max(dist2, node.min_d2);
  const float inv_len = dist2 > 0 ? 1 / std::sqrt(dist2) : 0.0f;
  const Vec3f wi = dist2 > 0 ? to_p * inv_len : b.w;
  float cos_w = dot(b.w, wi);
  if (b.two_sided) cos_w = std::fabs(cos_w);
  const float sin_w = safe_sqrt(1 - cos_w * cos_w);
  // The cone from p around the box's bounding sphere (the whole sphere from inside it).
  float cos_b = -1, sin_b = 0;
  if (dist2 > node.radius2) {
    const float s2 = node.radius2 / dist2;
    sin_b = std::sqrt(s2);
    cos_b = std::sqrt(1 - s2);
  }
  // theta' = max(0, theta_w - theta_o - theta_b): the smallest angle between an emitting
  // normal and a direction towards p.
  const float cos_x = cos_sub_clamped(sin_w, cos_w, node.sin_o, b.cos_o);
  const float sin_x = sin_sub_clamped(sin_w, cos_w, node.sin_o, b.cos_o);
  const float cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
  if (cos_p <= b.cos_e) return 0;
  float importance = b.phi * cos_p / d2;
  if (n.x != 0 || n.y != 0 || n.z != 0) {
    // The receiver's cosine, bounded over the subtended directions (either side of the surface).
    const float cos_i = std::fabs(dot(wi, n));
    const float sin_i = safe_sqrt(1 - cos_i * cos_i);
    importance *= cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
  }
  return std::isfinite(importance) ? std::max(importance, 0.0f) : 0.0f;
}

// `n` made unit, or left zero.
Vec3f unit_or_zero(Vec3f n) {
  const float len2 = dot(n, n);
  return len2 > 0 && std::isfinite(len2) ? n / std::sqrt(len2) : Vec3f{0, 0, 0};
}

}  // namespace

float light_importance(const LightBounds& b, Vec3f p, Vec3f n) {
  LightTreeNode node;
  node.lb = b;
  set_terms(node);
  return node_importance(node, p, unit_or_zero(n));
}

LightBounds merge(const LightBounds& a, const LightBounds& b) {
  LightBounds m;
  m.bounds = merge(a.bounds, b.bounds);
  m.phi = a.phi + b.phi;
  m.cos_e = std::min(a.cos_e, b.cos_e);
  m.two_sided = a.two_sided || b.two_sided;
  // pbrt-v4 DirectionCone Union: the cone around both, or the whole sphere.
  const float theta_a = safe_acos(a.cos_o), theta_b = safe_acos(b.cos_o);
  const float theta_d = safe_acos(dot(a.w, b.w));
  if (std::min(theta_d + theta_b, kPi) <= theta_a) {
    m.w = a.w, m.cos_o = a.cos_o;
    return m;
  }
  if (std::min(theta_d + theta_a, kPi) <= theta_b) {
    m.w = b.w, m.cos_o = b.cos_o;
    return m;
  }
  const float theta_o = (theta_a + theta_d + theta_b) / 2;
  const Vec3f axis = cross(a.w, b.w);
  if (theta_o >= kPi || !(dot(axis, axis) > 0)) {
    m.w = a.w, m.cos_o = -1;
    return m;
  }
  m.w = normalize(rotate(a.w, normalize(axis), theta_o - theta_a));
  m.cos_o = std::cos(theta_o);
  return m;
}

LightTree build_light_tree(std::span<const LightBounds> lights) {
  LightTree tree;
  tree.trail.assign(lights.size(), LightTree::kNotInTree);
  std::vector<uint32_t> ids;
  for (size_t i = 0; i < lights.size(); ++i)
    if (lights[i].phi > 0 && std::isfinite(lights[i].phi) && !lights[i].bounds.empty())
      ids.push_back(uint32_t(i));
  if (ids.empty()) return tree;
  tree.nodes.reserve(2 * ids.size());
  Builder{lights, tree}.build(ids, 0, ids.size(), 0, 0);
  for (LightTreeNode& node : tree.nodes) set_terms(node);
  return tree;
}

namespace {
// The probability of taking the first child of interior node `node` at p; false when neither
// child can reach p.
bool first_child_probability(const LightTree& tree, uint32_t node, Vec3f p, Vec3f n, float& p0) {
  const float c0 = node_importance(tree.nodes[node + 1], p, n);
  const float c1 = node_importance(tree.nodes[tree.nodes[node].index], p, n);
  if (!(c0 + c1 > 0)) return false;
  p0 = c0 / (c0 + c1);
  return true;
}
}  // namespace

bool sample_light_tree(const LightTree& tree, Vec3f p, Vec3f n, float u, uint32_t& light, float& pmf) {
  if (tree.nodes.empty()) return false;
  n = unit_or_zero(n);
  uint32_t node = 0;
  pmf = 1;
  while (!tree.nodes[node].leaf) {
    float p0 = 0;
    if (!first_child_probability(tree, node, p, n, p0)) return false;
    if (u < p0) {
      u = std::min(u / p0, 0x1.fffffep-1f);
      pmf *= p0;
      node = node + 1;
    } else {
      u = std::min((u - p0) / (1 - p0), 0x1.fffffep-1f);
      pmf *= 1 - p0;
      node = tree.nodes[node].index;
    }
  }
  if (!(node_importance(tree.nodes[node], p, n) > 0) || !(pmf > 0)) return false;
  light = tree.nodes[node].index;
  return true;
}

float light_tree_pmf(const LightTree& tree, Vec3f p, Vec3f n, uint32_t light) {
  if (light >= tree.trail.size() || tree.trail[light] == LightTree::kNotInTree) return 0;
  const uint64_t trail = tree.trail[light];
  n = unit_or_zero(n);
  uint32_t node = 0;
  float pmf = 1;
  for (int depth = 0; !tree.nodes[node].leaf; ++depth) {
    float p0 = 0;
    if (!first_child_probability(tree, node, p, n, p0)) return 0;
    if ((trail >> depth) & 1) {
      pmf *= 1 - p0;
      node = tree.nodes[node].index;
    } else {
      pmf *= p0;
      node = node + 1;
    }
  }
  return node_importance(tree.nodes[node], p, n) > 0 ? pmf : 0.0f;
}

}  // namespace penumbra
