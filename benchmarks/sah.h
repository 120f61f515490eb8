// The surface area heuristic as penumbra-bench reports it: ONE set of cost constants for every
// structure, applied to the node boxes of the tree each structure actually built, so SAH values
// of different builders compare. Builders score their own trees with their own constants
// (AccelStats::sah_cost: the BVH with 1 and 1 per block of four triangles, the kD-tree with
// Wald & Havran's 15 and 20); those figures do not compare and are not what the table shows.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "renderer/accel/accelerator.h"
#include "renderer/accel/bvh_build.h"
#include "renderer/accel/factory.h"

namespace penumbra::bench {

/// Cost of one node visit (C_T) and of one primitive test (C_I), in the same arbitrary unit.
struct SahConstants {
  double traversal = 1.0;
  double intersection = 1.0;
};

/// The constants of every SAH the benchmark reports.
inline constexpr SahConstants kSahConstants{};

/// A tree's SAH without its constants (MacDonald & Booth 1990; Goldsmith & Salmon 1987): for a
/// random ray through the root box, the expected interior nodes visited and primitives tested if
/// traversal never stops early. SAH = C_T interior_area + C_I leaf_area.
struct SahTerms {
  double interior_area = 0;  ///< sum over interior nodes of area(node) / area(root)
  double leaf_area = 0;      ///< sum over leaves of area(leaf) / area(root) x its charge (see below)
};

/// C_T t.interior_area + C_I t.leaf_area.
double sah_cost(const SahTerms& t, const SahConstants& c = kSahConstants);

/// The terms of the BVH made from build tree `root` in nodes of `width` children: 2 is the binary
/// tree itself; 4 and 8 are the tree collapsed as accel/bvh.cpp collapses it (each wide node opens
/// its interior child of largest area, the first on ties, until it has `width` children or only
/// leaves; a leaf root is one wide node holding one leaf). Each interior node (binary or wide)
/// counts once; a leaf is charged per block of `block` (>= 1) references, rounded up: block 1 is
/// per reference, the benchmark's unit. Areas are relative to root's box (1 if it has no area).
SahTerms bvh_sah_terms(const BvhBuildNode& root, int width, int block = 1);

/// The uniform SAH of one built structure, or why it has none.
struct StructureSah {
  std::optional<double> cost;     ///< under the constants asked for; nullopt: n/a
  std::optional<SahTerms> terms;  ///< set iff cost is
  std::string note;               ///< why n/a (empty when cost is set)
};

/// The SAH under `constants` of `built`, the structure make_accelerator(name, views, instances,
/// config) returned:
///  - "bvh": the build tree made again by build_bvh_tree() from the same primitives, bounds, clipper
///    and settings (its shape never depends on scheduling), at the width `built` reports; used only
///    if those terms under the builder's own constants and leaf blocks give its
///    AccelStats::sah_cost (relative 1e-6), so the figure is the measured tree's.
///  - "kdtree", "octree", "bsp": the constant-free terms their statistics report
///    (AccelStats::sah_node_area and sah_leaf_area, summed over their nodes as they flatten
///    them; the BSP's areas are those of its convex cells).
///  - "embree" (no access to its nodes), "grid", "brute" (no tree): n/a.
///  - Two-level builds (some instance not the identity): n/a (the top level is not visible).
///  - Deforming meshes (motion steps): n/a (the boxes a ray tests depend on its time).
/// Throws what make_accelerator throws for these inputs.
StructureSah measure_structure_sah(std::string_view name, std::span<const GeometryView> views,
                                   std::span<const InstanceView> instances, const AccelConfig& config,
                                   const Accelerator& built, const SahConstants& constants = kSahConstants);

}  // namespace penumbra::bench
