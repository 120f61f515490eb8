// Mesh against mesh: the pairs of triangles of two meshes that touch or cross, found by a
// simultaneous descent of two bounding-volume trees (Gottschalk, Lin & Manocha, "OBBTree",
// SIGGRAPH 1996, with axis-aligned boxes) and an exact test per candidate pair in double
// precision: two triangles meet when an edge of one meets the other, or, coplanar, when their
// projections overlap (the edge-crossing form of Moeller, "A fast triangle-triangle
// intersection test", JGT 2(2), 1997, with orientation determinants as Devillers & Guigue,
// "Faster triangle-triangle intersection tests", INRIA RR-4488, 2002). Touching counts.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include "renderer/accel/polytope.h"

namespace penumbra {

/// A triangle mesh in world space: 3 indices per triangle into `points`.
struct ContactMesh {
  std::span<const DVec3> points;
  std::span<const uint32_t> triangles;
};

/// A bounding-box tree over a mesh's triangles: leaves of at most 4, split at the median of the
/// longest axis of the centroids' box. Built from the triangles' boxes only.
struct ContactTree {
  struct Node {
    DVec3 lo{}, hi{};
    uint32_t first = 0, count = 0;  ///< leaf: order[first, first + count); inner: count 0
    uint32_t left = 0, right = 0;   ///< inner: the children
  };
  std::vector<Node> nodes;      ///< root first; empty for a mesh without triangles
  std::vector<uint32_t> order;  ///< triangle indices, leaf after leaf
};

ContactTree build_contact_tree(const ContactMesh& mesh);

/// The simultaneous descent of two trees: calls leaf(s, t) for every pair of a triangle s of
/// ta and t of tb whose leaves' boxes overlap, descending the node with the larger box first
/// when both are inner nodes; a leaf callback that returns bool ends the descent by returning
/// false. Returns the box pairs tested. Holds a stack of node pairs.
template <class Leaf>
uint64_t for_overlapping_leaves(const ContactTree& ta, const ContactTree& tb, Leaf&& leaf) {
  if (ta.nodes.empty() || tb.nodes.empty()) return 0;
  auto meet = [](const ContactTree::Node& a, const ContactTree::Node& b) {
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y && a.lo.z <= b.hi.z &&
           b.lo.z <= a.hi.z;
  };
  auto half_area = [](const ContactTree::Node& n) {
    const DVec3 d = n.hi - n.lo;
    return d.x * d.y + d.y * d.z + d.z * d.x;
  };
  uint64_t tested = 0;
  std::vector<std::pair<uint32_t, uint32_t>> stack{{0, 0}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    const ContactTree::Node& na = ta.nodes[i];
    const ContactTree::Node& nb = tb.nodes[j];
    ++tested;
    if (!meet(na, nb)) continue;
    const bool leaf_a = na.count > 0, leaf_b = nb.count > 0;
    if (leaf_a && leaf_b) {
      for (uint32_t x = na.first; x < na.first + na.count; ++x)
        for (uint32_t y = nb.first; y < nb.first + nb.count; ++y) {
          if constexpr (std::is_same_v<decltype(leaf(ta.order[x], tb.order[y])), bool>) {
            if (!leaf(ta.order[x], tb.order[y])) return tested;
          } else {
            leaf(ta.order[x], tb.order[y]);
          }
        }
    } else if (leaf_b || (!leaf_a && half_area(na) >= half_area(nb))) {
      stack.push_back({na.left, j});
      stack.push_back({na.right, j});
    } else {
      stack.push_back({i, nb.left});
      stack.push_back({i, nb.right});
    }
  }
  return tested;
}

/// True if triangles abc and def share a point.
bool triangles_meet(DVec3 a, DVec3 b, DVec3 c, DVec3 d, DVec3 e, DVec3 f);

/// A point two meeting triangles share: the mean of the points where an edge of one crosses
/// the other (triangles in one plane: the mean of the corners of each lying in the other; when
/// only their edges cross, the first triangle's centroid, which may lie outside the second).
DVec3 triangle_contact_point(DVec3 a, DVec3 b, DVec3 c, DVec3 d, DVec3 e, DVec3 f);

/// What mesh_contacts found.
struct MeshContacts {
  std::vector<std::pair<uint32_t, uint32_t>> pairs;  ///< (triangle of a, triangle of b), sorted
  uint64_t node_pairs = 0;                           ///< box pairs tested (the broad phase)
  uint64_t triangle_pairs = 0;                       ///< triangle pairs tested exactly
  uint64_t meeting = 0;                              ///< pairs that meet (kept or not)
};

/// Every pair of a triangle of `a` and one of `b` that meet, with their trees (built by
/// build_contact_tree over the same meshes). Keeps at most `max_pairs` pairs, the first met in
/// the descent (the counts go on).
MeshContacts mesh_contacts(const ContactMesh& a, const ContactTree& ta, const ContactMesh& b,
                           const ContactTree& tb, size_t max_pairs = SIZE_MAX);

/// The nearest point of a mesh's surface to p (distance INFINITY for a mesh without triangles).
struct MeshClosest {
  double distance = INFINITY;
  DVec3 point{};
  uint32_t triangle = 0;
};

/// The closest point of `mesh` to p by a walk of its tree (nearer box first, boxes farther than
/// the best so far skipped; point-triangle distances as Ericson, "Real-Time Collision
/// Detection", 2005, 5.1.5). Never allocates or throws.
MeshClosest mesh_closest(const ContactMesh& mesh, const ContactTree& tree, DVec3 p);

/// The winding number of closed meshes around p: the signed count of their triangles that a ray
/// from p crosses (+1 where the ray leaves through a triangle's front, the side its winding
/// faces), each triangle's sign multiplied by `orientation` (+1 or -1 per triangle; empty: all
/// +1). For closed outward-wound solids it counts the solids holding p, so p lies in their
/// union when it is positive. The ray test is the watertight one of Woop, Benthin & Wald
/// (JCGT 2(1), 2013) in double precision; a ray through an edge or a vertex is cast again along
/// another of a fixed set of directions. Returns false (winding unset) if every direction
/// grazes, or p lies on a triangle. Never allocates or throws.
bool mesh_winding(const ContactMesh& mesh, const ContactTree& tree, std::span<const int8_t> orientation,
                  DVec3 p, int& winding);

}  // namespace penumbra
