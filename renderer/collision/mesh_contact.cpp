// Mesh-mesh contacts: box trees, their simultaneous descent and the triangle-triangle test.
#include "renderer/collision/mesh_contact.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

namespace {

DVec3 min3(DVec3 a, DVec3 b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
DVec3 max3(DVec3 a, DVec3 b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
double axis(DVec3 v, int k) {
  return k == 0 ? v.x : k == 1 ? v.y : v.z;
}

double orient(DVec3 a, DVec3 b, DVec3 c, DVec3 d) {
  return dot(cross(b - a, c - a), d - a);
}

// Segment pq (crossing or touching the plane of abc, not lying in it) meets triangle abc.
bool segment_meets(DVec3 p, DVec3 q, DVec3 a, DVec3 b, DVec3 c) {
  const double s1 = orient(a, b, c, p), s2 = orient(a, b, c, q);
  if ((s1 > 0 && s2 > 0) || (s1 < 0 && s2 < 0) || (s1 == 0 && s2 == 0)) return false;
  const double t1 = orient(p, q, a, b), t2 = orient(p, q, b, c), t3 = orient(p, q, c, a);
  return (t1 >= 0 && t2 >= 0 && t3 >= 0) || (t1 <= 0 && t2 <= 0 && t3 <= 0);
}

// 2-d: the signed area of (a, b, c).
double orient2(double ax, double ay, double bx, double by, double cx, double cy) {
  return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

bool segments_meet_2d(const double* p, const double* q, const double* r, const double* s) {
  const double d1 = orient2(r[0], r[1], s[0], s[1], p[0], p[1]),
               d2 = orient2(r[0], r[1], s[0], s[1], q[0], q[1]);
  const double d3 = orient2(p[0], p[1], q[0], q[1], r[0], r[1]),
               d4 = orient2(p[0], p[1], q[0], q[1], s[0], s[1]);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  auto on = [](const double* a, const double* b, const double* c, double o) {  // c on segment ab
    return o == 0 && std::min(a[0], b[0]) <= c[0] && c[0] <= std::max(a[0], b[0]) &&
           std::min(a[1], b[1]) <= c[1] && c[1] <= std::max(a[1], b[1]);
  };
  return on(r, s, p, d1) || on(r, s, q, d2) || on(p, q, r, d3) || on(p, q, s, d4);
}

bool point_in_triangle_2d(const double* p, const double (*t)[2]) {
  const double o1 = orient2(t[0][0], t[0][1], t[1][0], t[1][1], p[0], p[1]);
  const double o2 = orient2(t[1][0], t[1][1], t[2][0], t[2][1], p[0], p[1]);
  const double o3 = orient2(t[2][0], t[2][1], t[0][0], t[0][1], p[0], p[1]);
  return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

// Two triangles in one plane (normal n) projected on the plane's two dominant axes.
void project_2d(const DVec3 (&t1)[3], const DVec3 (&t2)[3], DVec3 n, double (&p)[3][2], double (&q)[3][2]) {
  const double ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
  const int drop = ax >= ay && ax >= az ? 0 : ay >= az ? 1 : 2;
  const int u = drop == 0 ? 1 : 0, v = drop == 2 ? 1 : 2;
  for (int i = 0; i < 3; ++i) {
    p[i][0] = axis(t1[i], u), p[i][1] = axis(t1[i], v);
    q[i][0] = axis(t2[i], u), q[i][1] = axis(t2[i], v);
  }
}

// Two triangles in one plane (normal n): their projections on the plane's dominant axes overlap.
bool coplanar_meet(const DVec3 (&t1)[3], const DVec3 (&t2)[3], DVec3 n) {
  double p[3][2], q[3][2];
  project_2d(t1, t2, n, p, q);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (segments_meet_2d(p[i], p[(i + 1) % 3], q[j], q[(j + 1) % 3])) return true;
  return point_in_triangle_2d(p[0], q) || point_in_triangle_2d(q[0], p);
}

}  // namespace

bool triangles_meet(DVec3 a, DVec3 b, DVec3 c, DVec3 d, DVec3 e, DVec3 f) {
  const double s1 = orient(a, b, c, d), s2 = orient(a, b, c, e), s3 = orient(a, b, c, f);
  if ((s1 > 0 && s2 > 0 && s3 > 0) || (s1 < 0 && s2 < 0 && s3 < 0)) return false;  // def beside abc's plane
  const double r1 = orient(d, e, f, a), r2 = orient(d, e, f, b), r3 = orient(d, e, f, c);
  if ((r1 > 0 && r2 > 0 && r3 > 0) || (r1 < 0 && r2 < 0 && r3 < 0)) return false;
  const DVec3 n1 = cross(b - a, c - a), n2 = cross(e - d, f - d);
  if (s1 == 0 && s2 == 0 && s3 == 0) {  // one plane (or abc degenerate): the 2-d test
    const DVec3 t1[3] = {a, b, c}, t2[3] = {d, e, f};
    const DVec3 n = dot(n1, n1) >= dot(n2, n2) ? n1 : n2;
    return dot(n, n) > 0 && coplanar_meet(t1, t2, n);
  }
  return segment_meets(a, b, d, e, f) || segment_meets(b, c, d, e, f) || segment_meets(c, a, d, e, f) ||
         segment_meets(d, e, a, b, c) || segment_meets(e, f, a, b, c) || segment_meets(f, d, a, b, c);
}

DVec3 triangle_contact_point(DVec3 a, DVec3 b, DVec3 c, DVec3 d, DVec3 e, DVec3 f) {
  DVec3 sum{0, 0, 0};
  int n = 0;
  const DVec3 t1[3] = {a, b, c}, t2[3] = {d, e, f};
  const bool coplanar = orient(a, b, c, d) == 0 && orient(a, b, c, e) == 0 && orient(a, b, c, f) == 0;
  if (!coplanar) {
    auto crossings = [&](const DVec3(&s)[3], const DVec3(&t)[3]) {
      for (int i = 0; i < 3; ++i) {
        const DVec3 p = s[i], q = s[(i + 1) % 3];
        if (!segment_meets(p, q, t[0], t[1], t[2])) continue;
        const double sp = orient(t[0], t[1], t[2], p), sq = orient(t[0], t[1], t[2], q);
        const double u = sp == sq ? 0.5 : sp / (sp - sq);
        sum = sum + p + (q - p) * u;
        ++n;
      }
    };
    crossings(t1, t2);
    crossings(t2, t1);
  } else {
    double p[3][2], q[3][2];
    project_2d(t1, t2, cross(b - a, c - a), p, q);
    for (int i = 0; i < 3; ++i) {
      if (point_in_triangle_2d(p[i], q)) sum = sum + t1[i], ++n;
      if (point_in_triangle_2d(q[i], p)) sum = sum + t2[i], ++n;
    }
  }
  if (n == 0) return (a + b + c) * (1.0 / 3);
  return sum * (1.0 / n);
}

ContactTree build_contact_tree(const ContactMesh& mesh) {
  ContactTree tree;
  const uint32_t n = uint32_t(mesh.triangles.size() / 3);
  if (n == 0) return tree;
  std::vector<DVec3> lo(n), hi(n), centre(n);
  for (uint32_t t = 0; t < n; ++t) {
    const DVec3 a = mesh.points[mesh.triangles[3 * t]], b = mesh.points[mesh.triangles[3 * t + 1]],
                c = mesh.points[mesh.triangles[3 * t + 2]];
    lo[t] = min3(a, min3(b, c));
    hi[t] = max3(a, max3(b, c));
    centre[t] = (lo[t] + hi[t]) * 0.5;
  }
  tree.order.resize(n);
  for (uint32_t t = 0; t < n; ++t) tree.order[t] = t;
  struct Task {
    uint32_t node, first, count;
  };
  std::vector<Task> stack{{0, 0, n}};
  tree.nodes.emplace_back();
  while (!stack.empty()) {
    const Task task = stack.back();
    stack.pop_back();
    ContactTree::Node node;
    node.lo = lo[tree.order[task.first]];
    node.hi = hi[tree.order[task.first]];
    DVec3 clo = centre[tree.order[task.first]], chi = clo;
    for (uint32_t i = task.first; i < task.first + task.count; ++i) {
      const uint32_t t = tree.order[i];
      node.lo = min3(node.lo, lo[t]);
      node.hi = max3(node.hi, hi[t]);
      clo = min3(clo, centre[t]);
      chi = max3(chi, centre[t]);
    }
    if (task.count <= 4) {
      node.first = task.first;
      node.count = task.count;
      tree.nodes[task.node] = node;
      continue;
    }
    const DVec3 ext = chi - clo;
    const int k = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    const uint32_t half = task.count / 2;
    std::nth_element(tree.order.begin() + task.first, tree.order.begin() + task.first + half,
                     tree.order.begin() + task.first + task.count, [&](uint32_t x, uint32_t y) {
                       const double cx = axis(centre[x], k), cy = axis(centre[y], k);
                       return cx < cy || (cx == cy && x < y);
                     });
    node.left = uint32_t(tree.nodes.size());
    node.right = node.left + 1;
    tree.nodes.emplace_back();
    tree.nodes.emplace_back();
    tree.nodes[task.node] = node;
    stack.push_back({node.left, task.first, half});
    stack.push_back({node.right, task.first + half, task.count - half});
  }
  return tree;
}

MeshContacts mesh_contacts(const ContactMesh& a, const ContactTree& ta, const ContactMesh& b,
                           const ContactTree& tb, size_t max_pairs) {
  MeshContacts out;
  auto corner = [](const ContactMesh& m, uint32_t t, int k) {
    return m.points[m.triangles[3 * size_t(t) + size_t(k)]];
  };
  out.node_pairs = for_overlapping_leaves(ta, tb, [&](uint32_t s, uint32_t t) {
    ++out.triangle_pairs;
    if (!triangles_meet(corner(a, s, 0), corner(a, s, 1), corner(a, s, 2), corner(b, t, 0), corner(b, t, 1),
                        corner(b, t, 2)))
      return;
    ++out.meeting;
    if (out.pairs.size() < max_pairs) out.pairs.push_back({s, t});
  });
  std::sort(out.pairs.begin(), out.pairs.end());
  return out;
}

namespace {

double box_distance2(const ContactTree::Node& n, DVec3 p) {
  const double dx = std::max({n.lo.x - p.x, 0.0, p.x - n.hi.x}),
               dy = std::max({n.lo.y - p.y, 0.0, p.y - n.hi.y}),
               dz = std::max({n.lo.z - p.z, 0.0, p.z - n.hi.z});
  return dx * dx + dy * dy + dz * dz;
}

constexpr int kTreeStack = 128;  // the median split halves each level: depth <= log2(triangles) + 1

// Which of abc the ray (p, d) crosses (Woop, Benthin & Wald 2013, in double): 0 none, +1 or -1
// as it leaves through the front or the back, 2 when it passes through an edge or a corner
// (or p lies on the triangle's plane inside it). kx, ky, kz and the shear s come from d.
int ray_crossing(DVec3 p, DVec3 a, DVec3 b, DVec3 c, int kx, int ky, int kz, const double (&s)[3]) {
  const DVec3 ra = a - p, rb = b - p, rc = c - p;
  const double az = axis(ra, kz), bz = axis(rb, kz), cz = axis(rc, kz);
  const double ax = axis(ra, kx) - s[0] * az, ay = axis(ra, ky) - s[1] * az;
  const double bx = axis(rb, kx) - s[0] * bz, by = axis(rb, ky) - s[1] * bz;
  const double cx = axis(rc, kx) - s[0] * cz, cy = axis(rc, ky) - s[1] * cz;
  const double u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
  if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return 0;
  const double det = u + v + w;
  if (det == 0) return 0;  // the ray runs in the triangle's plane: its neighbours decide
  const double t = (u * az + v * bz + w * cz) * s[2];
  if (t * det < 0) return 0;  // behind p
  if (u == 0 || v == 0 || w == 0 || t == 0) return 2;
  // det > 0: the corners run counter-clockwise seen from the ray's origin: the winding's front
  // faces p, and the ray enters through it.
  return det > 0 ? -1 : 1;
}

}  // namespace

MeshClosest mesh_closest(const ContactMesh& mesh, const ContactTree& tree, DVec3 p) {
  MeshClosest best;
  if (tree.nodes.empty()) return best;
  double best2 = INFINITY;
  uint32_t stack[kTreeStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const ContactTree::Node& n = tree.nodes[stack[--top]];
    if (box_distance2(n, p) >= best2) continue;
    if (n.count > 0) {
      for (uint32_t k = n.first; k < n.first + n.count; ++k) {
        const uint32_t t = tree.order[k];
        const DVec3 q =
            closest_on_triangle(p, mesh.points[mesh.triangles[3 * t]], mesh.points[mesh.triangles[3 * t + 1]],
                                mesh.points[mesh.triangles[3 * t + 2]]);
        const DVec3 d = q - p;
        if (dot(d, d) < best2) best2 = dot(d, d), best.point = q, best.triangle = t;
      }
      continue;
    }
    const double dl = box_distance2(tree.nodes[n.left], p), dr = box_distance2(tree.nodes[n.right], p);
    if (top + 2 > kTreeStack) continue;  // unreachable for trees of fewer than 2^126 triangles
    // The nearer child is popped first.
    stack[top++] = dl <= dr ? n.right : n.left;
    stack[top++] = dl <= dr ? n.left : n.right;
  }
  best.distance = std::sqrt(best2);
  return best;
}

bool mesh_winding(const ContactMesh& mesh, const ContactTree& tree, std::span<const int8_t> orientation,
                  DVec3 p, int& winding) {
  // Directions with no simple ratio between their components, so that rays from points on a
  // grid graze edges only by accident.
  static constexpr DVec3 kDirections[] = {{0.5773912, 0.6194032, 0.5318711},
                                          {-0.3861104, 0.8342313, -0.3935311},
                                          {0.7210447, -0.2491683, -0.6465149}};
  if (tree.nodes.empty()) {
    winding = 0;
    return true;
  }
  for (const DVec3& d : kDirections) {
    // Woop et al.'s per-ray set-up: the dominant axis becomes z, x and y follow it cyclically
    // (swapped when d.z < 0 to keep the winding), and the shear constants.
    const double ad[3] = {std::abs(d.x), std::abs(d.y), std::abs(d.z)};
    const int kz = ad[0] >= ad[1] && ad[0] >= ad[2] ? 0 : ad[1] >= ad[2] ? 1 : 2;
    int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
    if (axis(d, kz) < 0) std::swap(kx, ky);
    const double s[3] = {axis(d, kx) / axis(d, kz), axis(d, ky) / axis(d, kz), 1 / axis(d, kz)};
    const DVec3 inv{1 / d.x, 1 / d.y, 1 / d.z};
    int count = 0;
    bool grazed = false;
    uint32_t stack[kTreeStack];
    int top = 0;
    stack[top++] = 0;
    while (top > 0 && !grazed) {
      const ContactTree::Node& n = tree.nodes[stack[--top]];
      // The slab test for the ray (t >= 0), widened by a relative margin so that rounding
      // never drops a box the ray touches.
      double t0 = 0, t1 = INFINITY;
      for (int k = 0; k < 3 && t0 <= t1; ++k) {
        const double o = axis(p, k), i = axis(inv, k);
        double a = (axis(n.lo, k) - o) * i, b = (axis(n.hi, k) - o) * i;
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a - 1e-9 * std::abs(a)), t1 = std::min(t1, b + 1e-9 * std::abs(b));
      }
      if (t0 > t1) continue;
      if (n.count > 0) {
        for (uint32_t k = n.first; k < n.first + n.count; ++k) {
          const uint32_t t = tree.order[k];
          const int c =
              ray_crossing(p, mesh.points[mesh.triangles[3 * t]], mesh.points[mesh.triangles[3 * t + 1]],
                           mesh.points[mesh.triangles[3 * t + 2]], kx, ky, kz, s);
          if (c == 2) {
            grazed = true;
            break;
          }
          count += c * (orientation.empty() ? 1 : orientation[t]);
        }
        continue;
      }
      if (top + 2 > kTreeStack) continue;
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
    if (!grazed) {
      winding = count;
      return true;
    }
  }
  return false;
}

}  // namespace penumbra
