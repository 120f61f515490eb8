// Static collision detection over a scene.
#include "renderer/collision/scene_collide.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "renderer/collision/gjk.h"
#include "renderer/collision/mesh_contact.h"
#include "renderer/collision/scene_proxies.h"

namespace penumbra {

std::vector<std::pair<uint32_t, uint32_t>> sweep_and_prune(std::span<const Bounds3f> boxes) {
  std::vector<uint32_t> order(boxes.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return boxes[a].lo.x < boxes[b].lo.x || (boxes[a].lo.x == boxes[b].lo.x && a < b);
  });
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  std::vector<uint32_t> active;
  for (uint32_t i : order) {
    const Bounds3f& b = boxes[i];
    // Drop the boxes that end before this one starts along x; the rest overlap it along x.
    active.erase(
        std::remove_if(active.begin(), active.end(), [&](uint32_t j) { return boxes[j].hi.x < b.lo.x; }),
        active.end());
    for (uint32_t j : active) {
      const Bounds3f& o = boxes[j];
      if (o.lo.y <= b.hi.y && b.lo.y <= o.hi.y && o.lo.z <= b.hi.z && b.lo.z <= o.hi.z)
        pairs.push_back({std::min(i, j), std::max(i, j)});
    }
    active.push_back(i);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

Bounds3f points_box(std::span<const DVec3> points) {
  Bounds3f b;
  for (const DVec3& p : points) {
    b = merge(b, Vec3f{std::nextafter(float(p.x), -INFINITY), std::nextafter(float(p.y), -INFINITY),
                       std::nextafter(float(p.z), -INFINITY)});
    b = merge(b, Vec3f{std::nextafter(float(p.x), INFINITY), std::nextafter(float(p.y), INFINITY),
                       std::nextafter(float(p.z), INFINITY)});
  }
  return b;
}

namespace {

// Triangle pairs kept per node pair (the contact point comes from the first; all are counted).
constexpr size_t kMaxKeptPairs = 1;

// A point of b's core deepest in a along the penetration: b's support point against the
// direction, moved half the depth back.
DVec3 proxy_contact_point(const Proxy& b, const Penetration& p) {
  ProxyCores cores(b);
  DVec3 best{0, 0, 0};
  double best_dot = INFINITY;
  double radius = 0;
  for (const ConvexCore& c : cores.cores)
    for (const DVec3& q : c.points)
      if (dot(q, p.direction) < best_dot) best_dot = dot(q, p.direction), best = q, radius = c.radius;
  return best - p.direction * radius + p.direction * (0.5 * p.depth);
}

// The solids of a node for volumes: one per placement, the instances that share it (a glTF
// mesh's primitives, which may each be open where they meet) taken together, so that copies
// placed apart, overlapping or mirrored stay separate solids whose union is sound.
std::vector<SolidMesh> placement_solids(const NodeGeometry& g, const SolidBspConfig& config) {
  const size_t n = g.instance_to_world.size();
  std::vector<uint8_t> taken(n, 0);
  std::vector<SolidMesh> out;
  for (size_t i = 0; i < n; ++i) {
    if (taken[i]) continue;
    std::vector<uint32_t> tris;
    for (size_t j = i; j < n; ++j) {
      if (taken[j] || std::memcmp(&g.instance_to_world[i], &g.instance_to_world[j], sizeof(Affine3f)) != 0)
        continue;
      taken[j] = 1;
      tris.insert(tris.end(), g.triangles.begin() + std::ptrdiff_t(g.instance_triangles[j]),
                  g.triangles.begin() + std::ptrdiff_t(g.instance_triangles[j + 1]));
    }
    if (tris.empty()) continue;
    // Over the span of vertices the triangles use (vertices between them that they do not use
    // are ignored by the solid's build).
    const uint32_t lo = *std::min_element(tris.begin(), tris.end());
    const uint32_t hi = *std::max_element(tris.begin(), tris.end());
    for (uint32_t& t : tris) t -= lo;
    out.push_back(
        build_solid_mesh(std::span<const Vec3f>(g.positions.data() + lo, size_t(hi - lo) + 1), tris, config));
  }
  return out;
}

// Samples of the part of g's surface inside `region`: each triangle split into four at its
// edges' midpoints until its longest edge is at most h, the pieces whose boxes miss the region
// dropped, and f(point) called for the three corners of every piece kept (a corner shared by
// pieces once per piece), so every point of the surface inside the region lies within h of a
// sample. Returns the samples' count (with f = nullptr only counts) and sets `max_edge` to the
// longest edge of a whole triangle meeting the region: from h = max_edge on, the pieces are the
// triangles themselves.
template <class F>
uint64_t surface_samples(const NodeGeometry& g, const Bounds3f& region, double h, F&& f, double& max_edge) {
  struct Piece {
    DVec3 a, b, c;
    int level;
  };
  auto misses = [&](const Piece& p) {
    return std::max({p.a.x, p.b.x, p.c.x}) < region.lo.x || std::min({p.a.x, p.b.x, p.c.x}) > region.hi.x ||
           std::max({p.a.y, p.b.y, p.c.y}) < region.lo.y || std::min({p.a.y, p.b.y, p.c.y}) > region.hi.y ||
           std::max({p.a.z, p.b.z, p.c.z}) < region.lo.z || std::min({p.a.z, p.b.z, p.c.z}) > region.hi.z;
  };
  auto longest = [](const Piece& p) {
    return std::max({length(p.b - p.a), length(p.c - p.b), length(p.a - p.c)});
  };
  uint64_t count = 0;
  max_edge = 0;
  std::vector<Piece> stack;
  for (size_t t = 0; t + 2 < g.triangles.size(); t += 3) {
    const Piece whole{g.points[g.triangles[t]], g.points[g.triangles[t + 1]], g.points[g.triangles[t + 2]],
                      0};
    if (misses(whole)) continue;
    max_edge = std::max(max_edge, longest(whole));
    stack.push_back(whole);
    while (!stack.empty()) {
      const Piece p = stack.back();
      stack.pop_back();
      if (p.level > 0 && misses(p)) continue;
      // A piece is kept when short enough, or past 40 halvings (or not finite).
      if (!(longest(p) > h) || p.level >= 40) {
        count += 3;
        if constexpr (!std::is_same_v<std::decay_t<F>, std::nullptr_t>) f(p.a), f(p.b), f(p.c);
        continue;
      }
      const DVec3 ab = (p.a + p.b) * 0.5, bc = (p.b + p.c) * 0.5, ca = (p.c + p.a) * 0.5;
      const int l = p.level + 1;
      stack.insert(stack.end(), {{p.a, ab, ca, l}, {ab, p.b, bc, l}, {ca, bc, p.c, l}, {ab, bc, ca, l}});
    }
  }
  return count;
}

}  // namespace

std::vector<int8_t> outward_orientation(const NodeGeometry& g) {
  std::vector<int8_t> out(g.triangles.size() / 3, 1);
  const size_t n = g.instance_to_world.size();
  std::vector<uint8_t> taken(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (taken[i]) continue;
    std::vector<size_t> group;
    for (size_t j = i; j < n; ++j)
      if (!taken[j] && std::memcmp(&g.instance_to_world[i], &g.instance_to_world[j], sizeof(Affine3f)) == 0)
        taken[j] = 1, group.push_back(j);
    // The signed volume relative to one of the group's corners, so that the terms stay of the
    // mesh's size far from the origin.
    double volume = 0;
    bool have_ref = false;
    DVec3 ref{};
    for (size_t j : group)
      for (size_t t = g.instance_triangles[j]; t + 2 < g.instance_triangles[j + 1]; t += 3) {
        if (!have_ref) ref = g.points[g.triangles[t]], have_ref = true;
        volume += dot(g.points[g.triangles[t]] - ref,
                      cross(g.points[g.triangles[t + 1]] - ref, g.points[g.triangles[t + 2]] - ref));
      }
    if (volume >= 0) continue;
    for (size_t j : group)
      for (size_t t = g.instance_triangles[j]; t < g.instance_triangles[j + 1]; t += 3) out[t / 3] = -1;
  }
  return out;
}

const DVec3* vertex_inside(const NodeGeometry& from, const NodeGeometry& into, const ContactTree& into_tree,
                           std::span<const int8_t> into_orientation) {
  const Bounds3f box = points_box(into.points);
  const ContactMesh mesh{into.points, into.triangles};
  for (const DVec3& p : from.points) {
    if (p.x < box.lo.x || p.x > box.hi.x || p.y < box.lo.y || p.y > box.hi.y || p.z < box.lo.z ||
        p.z > box.hi.z)
      continue;
    int winding = 0;
    if (mesh_winding(mesh, into_tree, into_orientation, p, winding) && winding > 0) return &p;
  }
  return nullptr;
}

namespace {

// A closed node as a solid: its triangles, their tree and outward orientation.
struct NodeSolid {
  ContactMesh mesh;
  const ContactTree* tree = nullptr;
  std::span<const int8_t> orientation;
};

// The deepest sample of one node's surface inside another's solid (the union of its closed
// meshes: a positive winding number).
struct Deepest {
  bool inside = false;  // some sample lies inside
  double depth = 0;     // its distance to the nearest surface of the solid
  DVec3 point{};        // the sample
  DVec3 toward{};       // unit, from the sample to that nearest surface point (zero on it)
};

Deepest deepest_inside(const NodeGeometry& from, const NodeSolid& into, const Bounds3f& region, double h) {
  Deepest best;
  double max_edge = 0;
  surface_samples(
      from, region, h,
      [&](DVec3 p) {
        int winding = 0;
        if (!mesh_winding(into.mesh, *into.tree, into.orientation, p, winding) || winding <= 0) return;
        const MeshClosest c = mesh_closest(into.mesh, *into.tree, p);
        if (best.inside && c.distance <= best.depth) return;
        best.inside = true, best.depth = c.distance, best.point = p;
        best.toward = c.distance > 0 ? (c.point - p) * (1 / c.distance) : DVec3{0, 0, 0};
      },
      max_edge);
  return best;
}

// Mesh penetration depth of two closed nodes: the deepest sample of either surface inside the
// other over `region` (the part both boxes share), the spacing h grown from 1/64 of the
// region's largest side until the samples fit the budget (or, when the triangles' corners alone
// exceed it, those). Sets depth, depth_error (the spacing) and direction, and when no sample lies
// inside (surfaces that only touch) depth 0; sets the point when `set_point` and one does.
void mesh_depth(const NodeGeometry& a, const NodeSolid& sa, const NodeGeometry& b, const NodeSolid& sb,
                const Bounds3f& region, uint64_t budget, bool set_point, NodeContact& contact) {
  const Vec3f extent = region.hi - region.lo;
  double h = std::max(double(std::max({extent.x, extent.y, extent.z})) / 64, 1e-12);
  for (;;) {
    double edge_a = 0, edge_b = 0;
    const uint64_t n =
        surface_samples(a, region, h, nullptr, edge_a) + surface_samples(b, region, h, nullptr, edge_b);
    if (n <= budget || h >= std::max(edge_a, edge_b)) break;
    h *= 1.5;
  }
  contact.depth = 0;
  contact.depth_error = h;
  const Deepest in_b = deepest_inside(a, sb, region, h);  // a's surface inside b
  const Deepest in_a = deepest_inside(b, sa, region, h);  // b's surface inside a
  if (!in_b.inside && !in_a.inside) return;
  const bool use_b = in_b.inside && (!in_a.inside || in_b.depth >= in_a.depth);
  const Deepest& d = use_b ? in_b : in_a;
  contact.depth = d.depth;
  // a's point in b: moving b by depth against `toward` brings b's nearest surface onto it;
  // b's point in a: moving b along `toward` carries it onto a's surface.
  contact.direction = use_b ? d.toward * -1.0 : d.toward;
  if (set_point) contact.point = d.point;
}

}  // namespace

CollideReport collide_scene(const Scene& scene, const NodeLinks& links, const CollideConfig& config) {
  CollideReport report;
  std::vector<NodeGeometry> nodes = node_geometry(scene, links.parents, -1, config.shapes);
  nodes.erase(
      std::remove_if(nodes.begin(), nodes.end(), [](const NodeGeometry& g) { return g.points.empty(); }),
      nodes.end());
  report.nodes = nodes.size();
  std::vector<Bounds3f> boxes;
  for (const NodeGeometry& g : nodes) boxes.push_back(points_box(g.points));
  const std::vector<std::pair<uint32_t, uint32_t>> candidates = sweep_and_prune(boxes);
  report.broad_pairs = candidates.size();
  // Narrow-phase data, made once per node on first use.
  std::vector<ContactTree> trees(nodes.size());
  std::vector<uint8_t> have_tree(nodes.size(), 0);
  std::vector<Proxy> proxies(nodes.size());
  std::vector<uint8_t> have_proxy(nodes.size(), 0);
  std::vector<std::vector<SolidMesh>> solids(nodes.size());  // per node, one per placement
  std::vector<uint8_t> have_solid(nodes.size(), 0);
  std::vector<std::vector<int8_t>> orientation(nodes.size());  // closed nodes' outward_orientation
  for (const auto& [i, j] : candidates) {
    const NodeGeometry& ga = nodes[i];
    const NodeGeometry& gb = nodes[j];
    if (!config.include_children && nodes_joined(ga.node, gb.node, links)) {
      ++report.family_pairs;
      continue;
    }
    ++report.narrow_tests;
    NodeContact contact;
    contact.a = std::min(ga.node, gb.node);
    contact.b = std::max(ga.node, gb.node);
    const NodeGeometry& first = ga.node < gb.node ? ga : gb;
    const NodeGeometry& second = ga.node < gb.node ? gb : ga;
    const uint32_t fi = ga.node < gb.node ? i : j, si = ga.node < gb.node ? j : i;
    if (config.mesh) {
      for (uint32_t k : {fi, si})
        if (!have_tree[k])
          trees[k] = build_contact_tree({nodes[k].points, nodes[k].triangles}), have_tree[k] = 1;
      const ContactMesh ma{first.points, first.triangles}, mb{second.points, second.triangles};
      const MeshContacts found = mesh_contacts(ma, trees[fi], mb, trees[si], kMaxKeptPairs);
      report.triangle_tests += found.triangle_pairs;
      const bool met = !found.pairs.empty();
      // Closed nodes are solids: one may hold the other without their surfaces meeting, and
      // their contact has a depth.
      const bool closed = std::isfinite(first.enclosed_volume) && std::isfinite(second.enclosed_volume);
      if (!met && !closed) continue;
      if (met) {
        contact.triangle_pairs = found.meeting;
        const auto [s, t] = found.pairs.front();
        auto corner = [](const ContactMesh& m, uint32_t tri, int k) {
          return m.points[m.triangles[3 * tri + k]];
        };
        contact.point = triangle_contact_point(corner(ma, s, 0), corner(ma, s, 1), corner(ma, s, 2),
                                               corner(mb, t, 0), corner(mb, t, 1), corner(mb, t, 2));
      }
      if (closed) {
        for (uint32_t k : {fi, si})
          if (orientation[k].empty()) orientation[k] = outward_orientation(nodes[k]);
        // Surfaces that do not meet: each connected part of one lies wholly inside or outside
        // the other, so a vertex decides.
        if (!met) {
          const DVec3* held = vertex_inside(first, second, trees[si], orientation[si]);
          if (!held) held = vertex_inside(second, first, trees[fi], orientation[fi]);
          if (!held) continue;
          contact.point = *held;
        }
        const NodeSolid sa{ma, &trees[fi], orientation[fi]}, sb{mb, &trees[si], orientation[si]};
        if (config.depth_samples > 0)
          mesh_depth(first, sa, second, sb, intersect(points_box(first.points), points_box(second.points)),
                     config.depth_samples, !met, contact);
      }
      contact.shape_error = std::max(first.shape_error, second.shape_error);
      if (config.volumes) {
        for (uint32_t k : {fi, si})
          if (!have_solid[k]) {
            try {
              solids[k] = placement_solids(nodes[k], config.solid);
            } catch (const std::invalid_argument& e) {
              throw std::invalid_argument("node " + std::to_string(nodes[k].node) + ": " + e.what());
            }
            have_solid[k] = 1;
          }
        if (!solids[fi].empty() && !solids[si].empty())
          contact.volume = mesh_intersection_volume(solids[fi], solids[si], config.volume);
      }
    } else {
      for (uint32_t k : {fi, si})
        if (!have_proxy[k]) {
          try {
            proxies[k] = fit_proxy(config.kind, nodes[k].points, nodes[k].triangles, config.fit);
          } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("node " + std::to_string(nodes[k].node) + ": " + e.what());
          }
          have_proxy[k] = 1;
        }
      const Penetration p = penetration(proxies[fi], proxies[si]);
      if (!p.intersect) continue;
      contact.depth = p.depth;
      contact.direction = p.direction;
      contact.point = proxy_contact_point(proxies[si], p);
      if (config.volumes) contact.volume = proxy_intersection_volume(proxies[fi], proxies[si], config.volume);
    }
    report.contacts.push_back(contact);
  }
  std::sort(report.contacts.begin(), report.contacts.end(), [](const NodeContact& x, const NodeContact& y) {
    return x.a < y.a || (x.a == y.a && x.b < y.b);
  });
  return report;
}

}  // namespace penumbra
