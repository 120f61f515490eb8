// A bounding volume hierarchy over lights for choosing one in proportion to an estimate of
// what it contributes at a shading point (Conty Estevez & Kulla 2018, "Importance Sampling of
// Many Lights with Adaptive Tree Splitting"; pbrt-v4 12.6.3, BVHLightSampler). Each node
// bounds its lights' positions, the cone of their emission directions and their total power;
// sampling descends from the root choosing a child in proportion to its importance, and the
// probability of any light is recomputed by walking down the same path (its bit trail).
// The builder sees only the lights' bounds.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "renderer/core/math.h"

namespace penumbra {

/// What a light (or a set of lights) can send: positions within `bounds`, surface normals
/// within angle theta_o of `w`, emission within theta_e beyond that (pi/2 for diffuse
/// emitters), total power `phi` (> 0).
struct LightBounds {
  Bounds3f bounds;
  Vec3f w{0, 0, 1};        ///< unit axis of the normal cone
  float phi = 0;           ///< power (any consistent unit)
  float cos_o = 1;         ///< cos theta_o; -1: normals in every direction
  float cos_e = 0;         ///< cos theta_e; 0 for diffuse emission
  bool two_sided = false;  ///< emits from both sides (the cone and its opposite)
};

/// pbrt-v4 LightBounds::Importance: phi times a bound on cos(theta') over the subtended
/// directions, over the squared distance to the box centre (at least half its diagonal),
/// times a bound on the receiver's cosine when `n` is non-zero (|cos|: both sides of the
/// surface receive). 0 only where no light in the bounds can reach p.
float light_importance(const LightBounds& b, Vec3f p, Vec3f n);

/// The bounds of two sets together: boxes and powers added, the smallest cone holding both
/// cones (pbrt-v4 DirectionCone Union), the wider emission angle.
LightBounds merge(const LightBounds& a, const LightBounds& b);

struct LightTreeNode {
  LightBounds lb;
  uint32_t index = 0;  ///< interior: its second child (the first is the next node); leaf: the light
  bool leaf = false;
  // What light_importance() derives from lb, kept so that sampling does not derive it again.
  Vec3f centre;       ///< of lb.bounds
  float radius2 = 0;  ///< squared radius of the bounding sphere of lb.bounds
  float min_d2 = 0;   ///< the squared distance's floor: half the box's diagonal (pbrt-v4's)
  float sin_o = 0;    ///< sin theta_o
};

/// Nodes in depth-first order (node 0 the root). Lights of zero or non-finite power are left out.
struct LightTree {
  std::vector<LightTreeNode> nodes;
  /// Per light: bit d set when the path from the root takes the second child at depth d;
  /// kNotInTree for a light left out.
  std::vector<uint64_t> trail;
  static constexpr uint64_t kNotInTree = ~uint64_t(0);
};

/// Builds the tree over `lights` by the surface area orientation heuristic (12 buckets per axis
/// over the centroids, cost phi x M_omega x box area x the box's aspect along the axis), median
/// splits below depth 32 so that no path is longer than 63. Allocates.
LightTree build_light_tree(std::span<const LightBounds> lights);

/// Chooses a light for shading point p (normal n, or zero) with u in [0,1): the index of the
/// light and its probability. False if no light can reach p. Never allocates.
bool sample_light_tree(const LightTree& tree, Vec3f p, Vec3f n, float u, uint32_t& light, float& pmf);

/// The probability that sample_light_tree(tree, p, n, ...) returns `light`. Never allocates.
float light_tree_pmf(const LightTree& tree, Vec3f p, Vec3f n, uint32_t light);

}  // namespace penumbra
