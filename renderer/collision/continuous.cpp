// Continuous collision detection: conservative advancement on proxies, the swept meshes'
// first contacts on triangles.
#include "renderer/collision/continuous.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "renderer/collision/mesh_ccd.h"
#include "renderer/collision/mesh_contact.h"
#include "renderer/collision/scene_proxies.h"
#include "renderer/core/quaternion.h"

namespace penumbra {

namespace {

// The rotation matrix of the fraction u of m's turn.
Transform turn_at(const RigidMotion& m, double u) {
  return rotate(slerp(Quat{}, m.rotation, u));
}

DVec3 apply3(const Transform& r, DVec3 v) {
  const auto& a = r.m;
  return {a[0][0] * v.x + a[0][1] * v.y + a[0][2] * v.z, a[1][0] * v.x + a[1][1] * v.y + a[1][2] * v.z,
          a[2][0] * v.x + a[2][1] * v.y + a[2][2] * v.z};
}

// The largest distance of the cores' points from `center`, and the largest core radius.
void reach(const MovingCores& c, DVec3 center, double& points, double& radius) {
  points = 0, radius = 0;
  for (size_t i = 0; i < c.rest.size(); ++i) {
    for (const DVec3& p : c.rest[i]) points = std::max(points, length(p - center));
    radius = std::max(radius, c.cores[i].radius);
  }
}

}  // namespace

RigidMotion make_rigid_motion(DVec3 center0, DVec3 center1, const Quat& rotation) {
  RigidMotion m;
  m.center0 = center0;
  m.center1 = center1;
  Quat q = normalize(rotation);
  if (q.w < 0) q = {-q.x, -q.y, -q.z, -q.w};
  m.rotation = q;
  m.angle = 2 * std::atan2(std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z), q.w);
  return m;
}

DVec3 move_point(const RigidMotion& m, DVec3 p, double u) {
  return m.center0 + (m.center1 - m.center0) * u + apply3(turn_at(m, u), p - m.center0);
}

MovingCores::MovingCores(const ProxyCores& from) {
  for (const ConvexCore& c : from.cores) {
    rest.emplace_back(c.points.begin(), c.points.end());
    posed.push_back(rest.back());
  }
  for (size_t i = 0; i < posed.size(); ++i) cores.push_back({posed[i], from.cores[i].radius});
}

void MovingCores::pose(const RigidMotion& motion, double u) {
  const Transform r = turn_at(motion, u);
  const DVec3 c = motion.center0 + (motion.center1 - motion.center0) * u;
  for (size_t i = 0; i < rest.size(); ++i)
    for (size_t k = 0; k < rest[i].size(); ++k) posed[i][k] = c + apply3(r, rest[i][k] - motion.center0);
}

FirstContact first_contact(MovingCores& a, const RigidMotion& ma, MovingCores& b, const RigidMotion& mb,
                           const AdvancementConfig& config) {
  double rho_a, rad_a, rho_b, rad_b;
  reach(a, ma.center0, rho_a, rad_a);
  reach(b, mb.center0, rho_b, rad_b);
  // Velocities per unit u: b's approach to a along n is dot(va - vb, n) from the centres plus
  // at most angle x rho from each turn (a chord is no longer than its arc).
  const DVec3 va = ma.center1 - ma.center0, vb = mb.center1 - mb.center0;
  // (1 + 1e-4): slerp turns nearly equal orientations by normalised linear interpolation, whose
  // speed exceeds the constant rate by a relative angle^2 / 8 at most.
  const double spin = (ma.angle * rho_a + mb.angle * rho_b) * (1 + 1e-4);
  const double size = rho_a + rad_a + rho_b + rad_b + length(va - vb);
  const double touch = config.tolerance * std::max(size, 1e-300);
  FirstContact out;
  double u = 0;
  DVec3 normal{0, 0, 0};  // the nearest pair's, at the last step
  double previous = -1;   // the last step's u (none yet)
  const uint64_t pairs = uint64_t(a.cores.size()) * b.cores.size();
  const int steps = int(
      std::min<uint64_t>(uint64_t(config.max_steps), config.max_distances / std::max<uint64_t>(pairs, 1)));
  if (steps == 0) {  // not even one step fits the budget: undecided from the start
    out.converged = false;
    out.u = 0;
    return out;
  }
  for (int step = 0; step < steps; ++step) {
    out.steps = step + 1;
    a.pose(ma, u);
    b.pose(mb, u);
    double advance = INFINITY, nearest = INFINITY;
    DVec3 nearest_normal{0, 0, 0};
    for (size_t i = 0; i < a.cores.size(); ++i)
      for (size_t j = 0; j < b.cores.size(); ++j) {
        const ConvexDistance d = gjk_distance(a.cores[i], b.cores[j]);
        if (d.intersect || d.distance <= touch) {
          out.hit = true;
          out.u = u;
          out.point = (d.a + d.b) * 0.5;
          if (previous >= 0) {
            // The normal of the pair that touches, from the last step (before contact).
            a.pose(ma, previous);
            b.pose(mb, previous);
            const ConvexDistance before = gjk_distance(a.cores[i], b.cores[j]);
            const DVec3 gap = before.b - before.a;
            const double g = length(gap);
            out.normal = g > 0 ? gap * (1 / g) : normal;
          }
          return out;
        }
        const DVec3 gap = d.b - d.a;
        const double g = length(gap);
        const DVec3 n = g > 0 ? gap * (1 / g) : DVec3{0, 0, 0};
        const double mu = dot(va - vb, n) + spin;
        if (mu > 0) advance = std::min(advance, d.distance / mu);
        if (d.distance < nearest) nearest = d.distance, nearest_normal = n;
      }
    normal = nearest_normal;
    if (!std::isfinite(advance)) return out;  // nothing approaches
    // Touching exactly at the interval's end is a contact; beyond it (to rounding) there is none.
    const double next = u + advance;
    if (u >= 1 || next > 1 + 1e-12) {
      out.u = 1;
      return out;
    }
    previous = u;
    u = std::min(next, 1.0);
  }
  out.converged = false;  // undecided: no contact before u, none proved after it
  out.u = u;
  out.normal = normal;
  return out;
}

namespace {

// Each glTF node's first mesh instance (nullptr for none).
std::vector<const Instance*> first_instances(const Scene& scene) {
  std::vector<const Instance*> out;
  for (const Instance& inst : scene.instances) {
    if (inst.mesh < 0 || size_t(inst.mesh) >= scene.meshes.size()) continue;
    const int node = inst.node >= 0 ? inst.node : scene.meshes[size_t(inst.mesh)].node;
    if (node < 0) continue;
    if (size_t(node) >= out.size()) out.resize(size_t(node) + 1, nullptr);
    if (!out[size_t(node)]) out[size_t(node)] = &inst;
  }
  return out;
}

// The rigid motion that carries a node's start points p0 to its end points p1, from the map
// between its first instance's placements, checked on every point; false when the map is not
// a rotation and a translation or some point does not follow it.
bool rigid_motion_of(const Instance* i0, const Instance* i1, const NodeGeometry& g0, const NodeGeometry& g1,
                     RigidMotion& motion) {
  if (g0.points.size() != g1.points.size() || g0.points.empty()) return false;
  if (!i0 || !i1) return false;
  Transform inv0;
  if (!inverse(to_transform(i0->to_world), inv0)) return false;
  const Transform map = to_transform(i1->to_world) * inv0;
  // The linear part must be a rotation (to the rounding of single-precision placements).
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += map.m[k][r] * map.m[k][c];
      if (std::abs(s - (r == c ? 1 : 0)) > 1e-4) return false;
    }
  if (determinant3x3(map) <= 0) return false;
  DVec3 lo = g0.points[0], hi = g0.points[0];
  for (const DVec3& p : g0.points) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const DVec3 c0 = (lo + hi) * 0.5;
  // Every point where it was: still (the map between equal placements is the identity only to
  // rounding, which would count as a motion).
  bool still = true;
  for (size_t k = 0; k < g0.points.size() && still; ++k)
    still = g0.points[k].x == g1.points[k].x && g0.points[k].y == g1.points[k].y &&
            g0.points[k].z == g1.points[k].z;
  if (still) {
    motion = make_rigid_motion(c0, c0, Quat{});
    return true;
  }
  const DVec3 c1 = apply3(map, c0) + DVec3{map.m[0][3], map.m[1][3], map.m[2][3]};
  motion = make_rigid_motion(c0, c1, quat_from_matrix(map));
  const Transform r = rotate(motion.rotation);
  // Single-precision placements round each point by about 6e-8 of its distance from the origin.
  const double tolerance = 1e-5 * length(hi - lo) + 1e-6 * (length(c0) + length(c1));
  for (size_t k = 0; k < g0.points.size(); ++k)
    if (length(c1 + apply3(r, g0.points[k] - c0) - g1.points[k]) > tolerance) return false;
  return true;
}

// The box a node's proxy sweeps: its centre's path grown by the cores' reach from it.
Bounds3f swept_box(const MovingCores& cores, const RigidMotion& m) {
  double points, radius;
  reach(cores, m.center0, points, radius);
  const double rho = (points + radius) * (1 + 1e-6) + 1e-30;
  const DVec3 lo{std::min(m.center0.x, m.center1.x) - rho, std::min(m.center0.y, m.center1.y) - rho,
                 std::min(m.center0.z, m.center1.z) - rho};
  const DVec3 hi{std::max(m.center0.x, m.center1.x) + rho, std::max(m.center0.y, m.center1.y) + rho,
                 std::max(m.center0.z, m.center1.z) + rho};
  return {{std::nextafter(float(lo.x), -INFINITY), std::nextafter(float(lo.y), -INFINITY),
           std::nextafter(float(lo.z), -INFINITY)},
          {std::nextafter(float(hi.x), INFINITY), std::nextafter(float(hi.y), INFINITY),
           std::nextafter(float(hi.z), INFINITY)}};
}

}  // namespace

namespace {

void sort_by_nodes(ContinuousReport& report) {
  for (std::vector<SweptContact>* list : {&report.contacts, &report.undecided})
    std::sort(list->begin(), list->end(), [](const SweptContact& x, const SweptContact& y) {
      return x.a < y.a || (x.a == y.a && x.b < y.b);
    });
}

// Meshes: every node whose triangles are the same in both poses, its vertices moving on
// straight lines; the broad phase over the boxes of both poses; a contact at the start by the
// static test, else the first by mesh_first_contact.
ContinuousReport continuous_meshes(const Scene& start, const Scene& end, const NodeLinks& links,
                                   const CollideConfig& config) {
  ContinuousReport report;
  const std::vector<NodeGeometry> all0 = node_geometry(start, links.parents, -1, config.shapes);
  const std::vector<NodeGeometry> all1 = node_geometry(end, links.parents, -1, config.shapes);
  std::vector<const NodeGeometry*> at_end;  // glTF node -> its geometry at the end
  for (const NodeGeometry& g : all1) {
    if (size_t(g.node) >= at_end.size()) at_end.resize(size_t(g.node) + 1, nullptr);
    at_end[size_t(g.node)] = &g;
  }
  std::vector<std::pair<const NodeGeometry*, const NodeGeometry*>> nodes;
  std::vector<uint8_t> moving;
  std::vector<Bounds3f> boxes;
  for (const NodeGeometry& g : all0) {
    if (g.points.empty()) continue;
    const NodeGeometry* e = size_t(g.node) < at_end.size() ? at_end[size_t(g.node)] : nullptr;
    if (!e || e->points.empty()) continue;
    ++report.nodes;
    if (e->points.size() != g.points.size() || e->triangles != g.triangles) {
      report.nonrigid_nodes.push_back(g.node);
      continue;
    }
    nodes.push_back({&g, e});
    bool moves = false;
    for (size_t k = 0; k < g.points.size() && !moves; ++k)
      moves = g.points[k].x != e->points[k].x || g.points[k].y != e->points[k].y ||
              g.points[k].z != e->points[k].z;
    moving.push_back(moves);
    report.moving_nodes += moves;
    boxes.push_back(merge(points_box(g.points), points_box(e->points)));
  }
  // Per node, made on first use: the contact tree at the start, the outward orientation (closed
  // nodes) and the swept tree.
  std::vector<ContactTree> trees(nodes.size());
  std::vector<uint8_t> have_tree(nodes.size(), 0);
  std::vector<std::vector<int8_t>> orientation(nodes.size());
  std::vector<SweptTree> swept(nodes.size());
  std::vector<uint8_t> have_swept(nodes.size(), 0);
  for (const auto& [i, j] : sweep_and_prune(boxes)) {
    if (!moving[i] && !moving[j]) continue;  // neither moves: the static test at the start decides
    ++report.broad_pairs;
    const int na = nodes[i].first->node, nb = nodes[j].first->node;
    if (!config.include_children && nodes_joined(na, nb, links)) {
      ++report.family_pairs;
      continue;
    }
    ++report.narrow_tests;
    const uint32_t first = na < nb ? i : j, second = na < nb ? j : i;
    const NodeGeometry &a0 = *nodes[first].first, &a1 = *nodes[first].second;
    const NodeGeometry &b0 = *nodes[second].first, &b1 = *nodes[second].second;
    SweptContact s;
    s.a = std::min(na, nb);
    s.b = std::max(na, nb);
    for (uint32_t k : {first, second})
      if (!have_tree[k])
        trees[k] = build_contact_tree({nodes[k].first->points, nodes[k].first->triangles}), have_tree[k] = 1;
    const ContactMesh ma{a0.points, a0.triangles}, mb{b0.points, b0.triangles};
    const MeshContacts at_start = mesh_contacts(ma, trees[first], mb, trees[second], 1);
    s.u = 0;
    if (!at_start.pairs.empty()) {
      const auto [x, y] = at_start.pairs.front();
      auto corner = [](const ContactMesh& m, uint32_t t, int k) {
        return m.points[m.triangles[3 * size_t(t) + size_t(k)]];
      };
      s.point = triangle_contact_point(corner(ma, x, 0), corner(ma, x, 1), corner(ma, x, 2), corner(mb, y, 0),
                                       corner(mb, y, 1), corner(mb, y, 2));
      report.contacts.push_back(s);
      continue;
    }
    // Closed nodes: one may start wholly inside the other.
    if (std::isfinite(a0.enclosed_volume) && std::isfinite(b0.enclosed_volume)) {
      for (uint32_t k : {first, second})
        if (orientation[k].empty()) orientation[k] = outward_orientation(*nodes[k].first);
      const DVec3* held = vertex_inside(a0, b0, trees[second], orientation[second]);
      if (!held) held = vertex_inside(b0, a0, trees[first], orientation[first]);
      if (held) {
        s.point = *held;
        report.contacts.push_back(s);
        continue;
      }
    }
    const MovingMesh ma01{a0.points, a1.points, a0.triangles}, mb01{b0.points, b1.points, b0.triangles};
    for (uint32_t k : {first, second})
      if (!have_swept[k])
        swept[k] =
            build_swept_tree({nodes[k].first->points, nodes[k].second->points, nodes[k].first->triangles}),
        have_swept[k] = 1;
    const MeshFirstContact c = mesh_first_contact(ma01, swept[first], mb01, swept[second]);
    report.steps += c.triangle_pairs;
    if (!c.converged) {
      s.converged = false;  // u = 0: nothing decided
      report.undecided.push_back(s);
      continue;
    }
    if (!c.hit) continue;
    s.u = c.u;
    s.point = c.point;
    s.normal = c.normal;
    report.contacts.push_back(s);
  }
  std::sort(report.nonrigid_nodes.begin(), report.nonrigid_nodes.end());
  sort_by_nodes(report);
  return report;
}

}  // namespace

ContinuousReport collide_continuous(const Scene& start, const Scene& end, const NodeLinks& links,
                                    const CollideConfig& config, const AdvancementConfig& advance) {
  if (config.mesh) return continuous_meshes(start, end, links, config);
  ContinuousReport report;
  std::vector<NodeGeometry> all0 = node_geometry(start, links.parents, -1, config.shapes);
  std::vector<NodeGeometry> all1 = node_geometry(end, links.parents, -1, config.shapes);
  std::vector<const NodeGeometry*> at_end;  // glTF node -> its geometry at the end
  for (const NodeGeometry& g : all1) {
    if (size_t(g.node) >= at_end.size()) at_end.resize(size_t(g.node) + 1, nullptr);
    at_end[size_t(g.node)] = &g;
  }
  const std::vector<const Instance*> placed0 = first_instances(start), placed1 = first_instances(end);
  auto placement = [](const std::vector<const Instance*>& v, int node) {
    return size_t(node) < v.size() ? v[size_t(node)] : nullptr;
  };
  std::vector<const NodeGeometry*> nodes;
  std::vector<RigidMotion> motions;
  for (const NodeGeometry& g : all0) {
    if (g.points.empty()) continue;
    const NodeGeometry* e = size_t(g.node) < at_end.size() ? at_end[size_t(g.node)] : nullptr;
    if (!e || e->points.empty()) continue;
    ++report.nodes;
    RigidMotion m;
    if (!rigid_motion_of(placement(placed0, g.node), placement(placed1, g.node), g, *e, m)) {
      report.nonrigid_nodes.push_back(g.node);
      continue;
    }
    nodes.push_back(&g);
    motions.push_back(m);
  }
  // Every rigid node's proxy, so that the broad phase bounds what the proxies sweep (they may
  // reach beyond the vertices).
  std::vector<uint8_t> moving(nodes.size());
  std::vector<std::unique_ptr<MovingCores>> cores(nodes.size());
  std::vector<Bounds3f> boxes;
  for (size_t i = 0; i < nodes.size(); ++i) {
    const RigidMotion& m = motions[i];
    moving[i] =
        m.angle > 0 || m.center0.x != m.center1.x || m.center0.y != m.center1.y || m.center0.z != m.center1.z;
    report.moving_nodes += moving[i];
    try {
      const Proxy proxy = fit_proxy(config.kind, nodes[i]->points, nodes[i]->triangles, config.fit);
      cores[i] = std::make_unique<MovingCores>(ProxyCores(proxy));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("node " + std::to_string(nodes[i]->node) + ": " + e.what());
    }
    boxes.push_back(swept_box(*cores[i], m));
  }
  std::sort(report.nonrigid_nodes.begin(), report.nonrigid_nodes.end());
  const std::vector<std::pair<uint32_t, uint32_t>> candidates = sweep_and_prune(boxes);
  for (const auto& [i, j] : candidates) {
    if (!moving[i] && !moving[j]) continue;  // neither moves: the static test at the start decides
    ++report.broad_pairs;
    const int na = nodes[i]->node, nb = nodes[j]->node;
    if (!config.include_children && nodes_joined(na, nb, links)) {
      ++report.family_pairs;
      continue;
    }
    ++report.narrow_tests;
    const bool swap = na > nb;
    const uint32_t first = swap ? j : i, second = swap ? i : j;
    const FirstContact c =
        first_contact(*cores[first], motions[first], *cores[second], motions[second], advance);
    report.steps += uint64_t(c.steps);
    if (!c.hit && c.converged) continue;
    SweptContact s;
    s.a = std::min(na, nb);
    s.b = std::max(na, nb);
    s.u = c.u;
    s.point = c.point;
    s.normal = c.normal;
    s.converged = c.converged;
    (c.hit ? report.contacts : report.undecided).push_back(s);
  }
  sort_by_nodes(report);
  return report;
}

}  // namespace penumbra
