// Spatial queries over any acceleration structure; see query.h.
#include "renderer/accel/query.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "renderer/accel/grid.h"
#include "renderer/core/parallel.h"
#include "renderer/shapes/shape_distance.h"

namespace penumbra {

namespace {

struct DVec {
  double x, y, z;
};
DVec dv(Vec3f a) {
  return {a.x, a.y, a.z};
}
DVec operator-(DVec a, DVec b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
DVec operator+(DVec a, DVec b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
DVec operator*(DVec a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
double dot(DVec a, DVec b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

// The nearest point of segment ab to p, as the parameter t in [0, 1] (a for a point segment).
double segment_parameter(DVec p, DVec a, DVec b) {
  const DVec ab = b - a;
  const double len2 = dot(ab, ab);
  return len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
}

// A geometry's placement: the view and its map to world space (null: the identity).
struct Placed {
  const GeometryView* view = nullptr;
  const Affine3f* to_world = nullptr;
};

bool placement(const QueryScene& scene, uint32_t geom_id, Placed& out) {
  if (scene.instances.empty()) {
    if (geom_id >= scene.meshes.size()) return false;
    out = {&scene.meshes[geom_id], nullptr};
    return true;
  }
  if (geom_id >= scene.instances.size()) return false;
  const InstanceView& inst = scene.instances[geom_id];
  if (inst.mesh >= scene.meshes.size()) return false;
  out = {&scene.meshes[inst.mesh], is_identity(inst.to_world) ? nullptr : &inst.to_world};
  return true;
}

Vec3f to_world(const Placed& pl, Vec3f p) {
  return pl.to_world ? apply_point(*pl.to_world, p) : p;
}

bool triangle(const Placed& pl, uint32_t prim, Vec3f v[3]) {
  const GeometryView& g = *pl.view;
  if (g.shape || size_t(prim) * 3 + 3 > g.indices.size()) return false;
  for (int j = 0; j < 3; ++j) {
    const uint32_t i = g.indices[size_t(prim) * 3 + size_t(j)];
    if (i >= g.positions.size()) return false;
    v[j] = to_world(pl, g.positions[i]);
    if (!is_finite(v[j])) return false;
  }
  return true;
}

// A shape's nearest surface point to the world point p, in world space.
Vec3f shape_point(const Placed& pl, Vec3f p) {
  if (!pl.to_world) return closest_point_on_shape(*pl.view->shape, p);
  Affine3f to_object;
  if (!inverse(*pl.to_world, to_object)) return {kInfinity, kInfinity, kInfinity};
  return apply_point(*pl.to_world, closest_point_on_shape(*pl.view->shape, apply_point(to_object, p)));
}

bool match_less(const PrimitiveMatch& a, const PrimitiveMatch& b) {
  if (a.distance != b.distance) return a.distance < b.distance;
  if (a.geom_id != b.geom_id) return a.geom_id < b.geom_id;
  return a.prim_id < b.prim_id;
}

bool same_primitive(const PrimitiveMatch& a, const PrimitiveMatch& b) {
  return a.geom_id == b.geom_id && a.prim_id == b.prim_id;
}

// The k nearest so far in a max-heap on match_less (the worst on top), in caller storage; the
// ball shrinks to the worst one's distance once k are held.
class NearestVisitor final : public RegionVisitor {
 public:
  NearestVisitor(const QueryScene& scene, Vec3f p, std::span<PrimitiveMatch> heap, size_t k,
                 float max_distance)
      : m_scene(scene), m_p(p), m_heap(heap), m_k(k), m_max(max_distance) {}

  void visit(uint32_t geom_id, uint32_t prim_id, QueryRegion& region) override {
    for (size_t i = 0; i < m_n; ++i)
      if (m_heap[i].geom_id == geom_id && m_heap[i].prim_id == prim_id) return;
    PrimitiveMatch m;
    if (!measure_primitive(m_scene, geom_id, prim_id, m_p, m) || !(m.distance <= m_max)) return;
    if (m_n == m_k) {
      if (!match_less(m, m_heap[0])) return;
      std::pop_heap(m_heap.begin(), m_heap.begin() + std::ptrdiff_t(m_n), match_less);
      m_heap[m_n - 1] = m;
    } else {
      m_heap[m_n++] = m;
    }
    std::push_heap(m_heap.begin(), m_heap.begin() + std::ptrdiff_t(m_n), match_less);
    if (m_n == m_k) region.radius2 = std::min(region.radius2, m_heap[0].distance * m_heap[0].distance);
  }
  size_t count() const { return m_n; }

 private:
  const QueryScene& m_scene;
  Vec3f m_p;
  std::span<PrimitiveMatch> m_heap;
  size_t m_k, m_n = 0;
  float m_max;
};

// Every primitive the traversal offers, deduplicated and tested at the end.
class CollectVisitor final : public RegionVisitor {
 public:
  explicit CollectVisitor(std::vector<PrimitiveMatch>& out) : m_out(out) {}
  void visit(uint32_t geom_id, uint32_t prim_id, QueryRegion&) override {
    PrimitiveMatch m;
    m.geom_id = geom_id;
    m.prim_id = prim_id;
    m_out.push_back(m);
  }

 private:
  std::vector<PrimitiveMatch>& m_out;
};

void sort_unique_ids(std::vector<PrimitiveMatch>& v) {
  std::sort(v.begin(), v.end(), [](const PrimitiveMatch& a, const PrimitiveMatch& b) {
    return a.geom_id != b.geom_id ? a.geom_id < b.geom_id : a.prim_id < b.prim_id;
  });
  v.erase(std::unique(v.begin(), v.end(), same_primitive), v.end());
}

// Subdivision test of a shape's surface against a box (see primitive_meets_box).
bool shape_meets_box(const Placed& pl, const Bounds3f& box, int depth) {
  const Vec3f c = box.center();
  const Vec3f q = shape_point(pl, c);
  if (!is_finite(q)) return false;
  if (q.x >= box.lo.x && q.x <= box.hi.x && q.y >= box.lo.y && q.y <= box.hi.y && q.z >= box.lo.z &&
      q.z <= box.hi.z)
    return true;
  const float half_diagonal = 0.5f * length(box.extent());
  if (length(q - c) > half_diagonal) return false;  // the surface misses the box's ball
  if (depth == 0) return true;
  for (int i = 0; i < 8; ++i) {
    Bounds3f child;
    for (int k = 0; k < 3; ++k) {
      const bool hi = (i >> k) & 1;
      child.lo[k] = hi ? c[k] : box.lo[k];
      child.hi[k] = hi ? box.hi[k] : c[k];
    }
    if (shape_meets_box(pl, child, depth - 1)) return true;
  }
  return false;
}

}  // namespace

Vec3f closest_point_on_triangle(Vec3f pf, Vec3f af, Vec3f bf, Vec3f cf, float& u, float& v) {
  const DVec p = dv(pf), a = dv(af), b = dv(bf), c = dv(cf);
  const DVec ab = b - a, ac = c - a, ap = p - a;
  const DVec n{ab.y * ac.z - ab.z * ac.y, ab.z * ac.x - ab.x * ac.z, ab.x * ac.y - ab.y * ac.x};
  double bu = 0, bv = 0;  // barycentrics of b and c
  if (!(dot(n, n) > 0)) {
    // Degenerate: the nearest of the three edges' nearest points.
    const DVec e[3][2] = {{a, b}, {b, c}, {c, a}};
    double best = INFINITY;
    for (int i = 0; i < 3; ++i) {
      const double t = segment_parameter(p, e[i][0], e[i][1]);
      const DVec q = e[i][0] + (e[i][1] - e[i][0]) * t;
      const double d2 = dot(p - q, p - q);
      if (d2 < best) {
        best = d2;
        bu = i == 0 ? t : (i == 1 ? 1 - t : 0);
        bv = i == 0 ? 0 : (i == 1 ? t : 1 - t);
      }
    }
  } else {
    // Ericson 5.1.5: the Voronoi region of p among the vertices, edges and face.
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    const DVec bp = p - b, cp = p - c;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp), d5 = dot(ab, cp), d6 = dot(ac, cp);
    const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d1 <= 0 && d2 <= 0) {
      bu = bv = 0;  // vertex a
    } else if (d3 >= 0 && d4 <= d3) {
      bu = 1, bv = 0;  // vertex b
    } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
      bu = d1 / (d1 - d3), bv = 0;  // edge ab
    } else if (d6 >= 0 && d5 <= d6) {
      bu = 0, bv = 1;  // vertex c
    } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
      bu = 0, bv = d2 / (d2 - d6);  // edge ac
    } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
      const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));  // edge bc
      bu = 1 - w, bv = w;
    } else {
      const double denom = 1 / (va + vb + vc);  // inside the face
      bu = vb * denom, bv = vc * denom;
    }
  }
  u = float(bu);
  v = float(bv);
  const DVec q = a + ab * bu + ac * bv;
  return {float(q.x), float(q.y), float(q.z)};
}

bool measure_primitive(const QueryScene& scene, uint32_t geom_id, uint32_t prim_id, Vec3f p,
                       PrimitiveMatch& m) {
  Placed pl;
  if (!placement(scene, geom_id, pl)) return false;
  m.geom_id = geom_id;
  m.prim_id = prim_id;
  if (pl.view->shape) {
    if (prim_id != 0) return false;
    m.point = shape_point(pl, p);
    m.u = m.v = 0;
  } else {
    Vec3f v[3];
    if (!triangle(pl, prim_id, v)) return false;
    m.point = closest_point_on_triangle(p, v[0], v[1], v[2], m.u, m.v);
  }
  if (!is_finite(m.point)) return false;
  const DVec d = dv(p) - dv(m.point);
  m.distance = float(std::sqrt(dot(d, d)));
  return true;
}

bool primitive_meets_box(const QueryScene& scene, uint32_t geom_id, uint32_t prim_id, const Bounds3f& box) {
  Placed pl;
  if (!placement(scene, geom_id, pl)) return false;
  if (pl.view->shape) {
    if (prim_id != 0) return false;
    // The shape's world bounds first: no piece of the box outside them can meet it.
    const Bounds3f b = shape_bounds(*pl.view->shape);
    Bounds3f world;
    for (int i = 0; i < 8; ++i)
      world = merge(
          world, to_world(pl, {i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z}));
    const Bounds3f common = intersect(world, box);
    return !b.empty() && !common.empty() && shape_meets_box(pl, common, 6);
  }
  Vec3f v[3];
  if (!triangle(pl, prim_id, v)) return false;
  const double lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
  return triangle_box_overlap(lo, hi, v[0], v[1], v[2]);
}

size_t nearest(const Accelerator& accel, const QueryScene& scene, Vec3f p, int k, float max_distance,
               std::span<PrimitiveMatch> out, TraversalCost* cost) {
  if (k < 1 || out.size() < size_t(k) || !is_finite(p) || !(max_distance >= 0)) return 0;
  NearestVisitor visitor(scene, p, out.first(size_t(k)), size_t(k), max_distance);
  QueryRegion region;
  region.centre = p;
  region.radius2 = max_distance * max_distance;
  accel.visit_region(region, visitor, cost);
  const size_t n = visitor.count();
  std::sort_heap(out.begin(), out.begin() + std::ptrdiff_t(n), match_less);
  return n;
}

void within(const Accelerator& accel, const QueryScene& scene, Vec3f p, float radius,
            std::vector<PrimitiveMatch>& out, TraversalCost* cost) {
  out.clear();
  if (!is_finite(p) || !(radius >= 0) || !std::isfinite(radius)) return;
  CollectVisitor visitor(out);
  QueryRegion region;
  region.centre = p;
  region.radius2 = radius * radius;
  accel.visit_region(region, visitor, cost);
  sort_unique_ids(out);
  size_t n = 0;
  for (const PrimitiveMatch& c : out) {
    PrimitiveMatch m;
    if (measure_primitive(scene, c.geom_id, c.prim_id, p, m) && m.distance <= radius) out[n++] = m;
  }
  out.resize(n);
  std::sort(out.begin(), out.end(), match_less);
}

void overlap(const Accelerator& accel, const QueryScene& scene, const Bounds3f& box,
             std::vector<PrimitiveMatch>& out, TraversalCost* cost) {
  out.clear();
  if (box.empty() || !is_finite(box.lo) || !is_finite(box.hi)) return;
  CollectVisitor visitor(out);
  QueryRegion region;
  region.is_box = true;
  region.box = box;
  accel.visit_region(region, visitor, cost);
  sort_unique_ids(out);
  size_t n = 0;
  for (const PrimitiveMatch& c : out) {
    PrimitiveMatch m;
    if (primitive_meets_box(scene, c.geom_id, c.prim_id, box) &&
        measure_primitive(scene, c.geom_id, c.prim_id, box.center(), m))
      out[n++] = m;
  }
  out.resize(n);
}

void nearest_batch(const Accelerator& accel, const QueryScene& scene, std::span<const Vec3f> points, int k,
                   float max_distance, int threads, std::vector<PrimitiveMatch>& out,
                   std::vector<uint32_t>& counts) {
  out.assign(points.size() * size_t(std::max(k, 0)), PrimitiveMatch{});
  counts.assign(points.size(), 0);
  if (k < 1) return;
  tbb::task_arena arena(thread_count(threads));
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 64),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t i = r.begin(); i < r.end(); ++i)
                          counts[i] = uint32_t(nearest(accel, scene, points[i], k, max_distance,
                                                       std::span(out).subspan(i * size_t(k), size_t(k))));
                      });
  });
}

bool within_batch(const Accelerator& accel, const QueryScene& scene, std::span<const Vec3f> points,
                  float radius, int threads, size_t max_matches, std::vector<PrimitiveMatch>& out,
                  std::vector<size_t>& offsets) {
  out.clear();
  offsets.assign(points.size() + 1, 0);
  std::vector<std::vector<PrimitiveMatch>> each(points.size());
  std::atomic<size_t> total{0};
  std::atomic<bool> over{false};
  tbb::task_arena arena(thread_count(threads));
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, points.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
          for (size_t i = r.begin(); i < r.end() && !over.load(std::memory_order_relaxed); ++i) {
            within(accel, scene, points[i], radius, each[i]);
            if (total.fetch_add(each[i].size(), std::memory_order_relaxed) + each[i].size() > max_matches) {
              over = true;
              each[i] = {};
            }
          }
        });
  });
  if (over) {
    offsets.clear();
    return false;
  }
  out.reserve(total);
  for (size_t i = 0; i < points.size(); ++i) {
    out.insert(out.end(), each[i].begin(), each[i].end());
    offsets[i + 1] = out.size();
  }
  return true;
}

void intersect_batch(const Accelerator& accel, std::span<const Ray> rays, std::span<Hit> hits, int threads) {
  tbb::task_arena arena(thread_count(threads));
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t i = r.begin(); i < r.end(); ++i) {
                          hits[i] = Hit{};
                          if (!accel.intersect(rays[i], hits[i])) hits[i].geom_id = Hit::kInvalidId;
                        }
                      });
  });
}

}  // namespace penumbra
