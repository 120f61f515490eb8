// Animation for the glTF loader: every animation's channels sampled at one time into per-node
// poses (glTF 2.0 spec 3.11), morph target weights (3.7.2.2) and skin joint matrices (3.7.3).
// The poses feed nodes.h (local transforms); weights and joints feed meshes.h.
#pragma once

#include <array>
#include <vector>

#include "io/gltf/context.h"
#include "renderer/core/math.h"

namespace penumbra::gltf {

struct NodeTransforms;

/// Animated values of one node at the requested time (unset fields keep the file's).
struct NodePose {
  bool has_t = false, has_r = false, has_s = false, has_w = false;
  std::array<double, 3> t{}, s{};
  Quat r;
  std::vector<double> weights;
};

/// The value of animations[a].samplers[sampler] (a valid index) at `time` seconds: `width`
/// components per key (0: the output count over the key count), a quaternion normalised if
/// `rotation`. Throws InputError naming the sampler for malformed keys or values.
std::vector<double> sample_animation(const GltfContext& ctx, size_t a, int sampler, size_t width,
                                     bool rotation, double time);

/// One pose per node: every channel of every animation sampled at `time` seconds. Throws
/// InputError naming the animation element for malformed channels or samplers.
std::vector<NodePose> evaluate_animations(const GltfContext& ctx, double time);

/// The morph weights of mesh `mesh` placed by `node`: animated, else the node's, else the mesh's
/// defaults; non-finite weights are 0. `poses` is empty when no time is asked for.
std::vector<double> morph_weights(const GltfContext& ctx, const std::vector<NodePose>& poses, int mesh,
                                  int node);

/// Joint matrices J_k = world(joint k) x inverseBindMatrix k of skins[skin], for `node_where`.
/// Throws InputError naming the skin.
std::vector<Transform> joint_matrices(const GltfContext& ctx, NodeTransforms& nodes, int skin,
                                      const std::string& node_where);

}  // namespace penumbra::gltf
