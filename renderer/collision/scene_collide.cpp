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

namespace {

// Triangle pairs kept per node pair (the contact point comes from the first; all are counted).
constexpr size_t kMaxKeptPairs = 1;

Bounds3f box_of(std::span<const DVec3> points) {
  Bounds3f b;
  for (const DVec3& p : points) {
    b = merge(b, Vec3f{std::nextafter(float(p.x), -INFINITY), std::nextafter(float(p.y), -INFINITY),
                       std::nextafter(float(p.z), -INFINITY)});
    b = merge(b, Vec3f{std::nextafter(float(p.x), INFINITY), std::nextafter(float(p.y), INFINITY),
                       std::nextafter(float(p.z), INFINITY)});
  }
  return b;
}

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

}  // namespace

CollideReport collide_scene(const Scene& scene, std::span<const int> parents, const CollideConfig& config) {
  CollideReport report;
  std::vector<NodeGeometry> nodes = node_geometry(scene, parents, -1);
  nodes.erase(
      std::remove_if(nodes.begin(), nodes.end(), [](const NodeGeometry& g) { return g.points.empty(); }),
      nodes.end());
  report.nodes = nodes.size();
  std::vector<Bounds3f> boxes;
  for (const NodeGeometry& g : nodes) boxes.push_back(box_of(g.points));
  const std::vector<std::pair<uint32_t, uint32_t>> candidates = sweep_and_prune(boxes);
  report.broad_pairs = candidates.size();
  // Narrow-phase data, made once per node on first use.
  std::vector<ContactTree> trees(nodes.size());
  std::vector<uint8_t> have_tree(nodes.size(), 0);
  std::vector<Proxy> proxies(nodes.size());
  std::vector<uint8_t> have_proxy(nodes.size(), 0);
  std::vector<std::vector<SolidMesh>> solids(nodes.size());  // per node, one per placement
  std::vector<uint8_t> have_solid(nodes.size(), 0);
  for (const auto& [i, j] : candidates) {
    const NodeGeometry& ga = nodes[i];
    const NodeGeometry& gb = nodes[j];
    if (!config.include_children &&
        (node_in_subtree(ga.node, gb.node, parents) || node_in_subtree(gb.node, ga.node, parents))) {
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
      if (found.pairs.empty()) continue;
      contact.triangle_pairs = found.meeting;
      const auto [s, t] = found.pairs.front();
      auto corner = [](const ContactMesh& m, uint32_t tri, int k) {
        return m.points[m.triangles[3 * tri + k]];
      };
      contact.point = triangle_contact_point(corner(ma, s, 0), corner(ma, s, 1), corner(ma, s, 2),
                                             corner(mb, t, 0), corner(mb, t, 1), corner(mb, t, 2));
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
