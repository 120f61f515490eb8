// Animation at a time: channels and samplers validated and sampled into node poses; morph
// weights chosen per placement; skin joint matrices from the joints' world transforms.
#include "io/gltf/animation.h"

#include <tiny_gltf.h>

#include <cmath>

#include "io/gltf/accessors.h"
#include "io/gltf/nodes.h"
#include "renderer/scene/animation.h"

namespace penumbra::gltf {

namespace {

// Channel ci of animations[ai] sampled at `time` into poses (nothing for a channel without a
// target node or with an unsupported path, which is warned about; KHR_animation_pointer
// channels are applied by animation_pointer.h).
void sample_channel(const GltfContext& ctx, size_t ai, size_t ci, double time, std::vector<NodePose>& poses) {
  const auto& anim = ctx.model.animations[ai];
  const auto& ch = anim.channels[ci];
  const std::string aw = idx("animations", ai);
  const std::string cw = aw + "." + idx("channels", ci);
  if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
    ctx.fail(cw + ".sampler", "sampler index " + std::to_string(ch.sampler) + " out of range (" +
                                  std::to_string(anim.samplers.size()) + " samplers)");
  if (ch.target_path == "pointer") return;
  if (ch.target_node < 0) return;  // no target node: nothing to animate (spec allows it)
  if (size_t(ch.target_node) >= ctx.model.nodes.size())
    ctx.fail(cw + ".target.node", "node index " + std::to_string(ch.target_node) + " out of range (" +
                                      std::to_string(ctx.model.nodes.size()) + " nodes)");
  const std::string& path = ch.target_path;
  size_t width = 0;
  if (path == "translation" || path == "scale")
    width = 3;
  else if (path == "rotation")
    width = 4;
  else if (path == "weights")
    width = 0;  // from the counts
  else {
    ctx.warn(cw + ".target.path", "path '" + path + "' is not supported; channel ignored");
    return;
  }
  const std::vector<double> v = sample_animation(ctx, ai, ch.sampler, width, path == "rotation", time);
  NodePose& pose = poses[size_t(ch.target_node)];
  if (path == "translation") {
    pose.has_t = true;
    pose.t = {v[0], v[1], v[2]};
  } else if (path == "scale") {
    pose.has_s = true;
    pose.s = {v[0], v[1], v[2]};
  } else if (path == "rotation") {
    pose.has_r = true;
    pose.r = {v[0], v[1], v[2], v[3]};
  } else {
    pose.has_w = true;
    pose.weights = v;
  }
}

}  // namespace

std::vector<double> sample_animation(const GltfContext& ctx, size_t ai, int sampler, size_t width,
                                     bool rotation, double time) {
  const auto& anim = ctx.model.animations[ai];
  const auto& smp = anim.samplers[size_t(sampler)];
  const std::string sw = idx("animations", ai) + "." + idx("samplers", size_t(sampler));
  Interpolation interp = Interpolation::Linear;
  if (smp.interpolation == "STEP")
    interp = Interpolation::Step;
  else if (smp.interpolation == "CUBICSPLINE")
    interp = Interpolation::CubicSpline;
  else if (smp.interpolation != "LINEAR" && !smp.interpolation.empty())
    ctx.fail(sw + ".interpolation", "'" + smp.interpolation + "' is not STEP, LINEAR or CUBICSPLINE");
  const int type = width == 2   ? TINYGLTF_TYPE_VEC2
                   : width == 3 ? TINYGLTF_TYPE_VEC3
                   : width == 4 ? TINYGLTF_TYPE_VEC4
                                : TINYGLTF_TYPE_SCALAR;
  const auto in = read_accessor(ctx, smp.input, sw + ".input", {TINYGLTF_TYPE_SCALAR},
                                {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
  const auto outv = read_accessor(
      ctx, smp.output, sw + ".output", {type},
      {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
       TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
      true);
  std::vector<float> times(in.begin(), in.end()), values(outv.begin(), outv.end());
  if (times.empty()) ctx.fail(sw + ".input", "has no keys");
  for (size_t k = 0; k < times.size(); ++k)
    if (!std::isfinite(times[k]) || (k > 0 && times[k] < times[k - 1]))
      ctx.fail(sw + ".input", "key times must be finite and non-decreasing (key " + std::to_string(k) + ")");
  for (float v : values)
    if (!std::isfinite(v)) ctx.fail(sw + ".output", "values must be finite");
  const size_t per_key = interp == Interpolation::CubicSpline ? 3 : 1;
  if (width == 0) {  // e.g. weights: one value per morph target per key
    if (values.size() % (times.size() * per_key) != 0)
      ctx.fail(sw + ".output", "count " + std::to_string(values.size()) + " is not a multiple of " +
                                   std::to_string(times.size() * per_key) + " (keys x values per key)");
    width = values.size() / (times.size() * per_key);
  } else if (values.size() != times.size() * per_key * width) {
    ctx.fail(sw + ".output", "has " + std::to_string(values.size() / width) + " elements; " +
                                 std::to_string(times.size() * per_key) + " expected for " +
                                 std::to_string(times.size()) + " keys");
  }
  std::vector<double> v(width);
  if (width > 0) sample_track(times, values, width, interp, rotation, time, v.data());
  return v;
}

std::vector<NodePose> evaluate_animations(const GltfContext& ctx, double time) {
  std::vector<NodePose> poses(ctx.model.nodes.size());
  for (size_t ai = 0; ai < ctx.model.animations.size(); ++ai)
    for (size_t ci = 0; ci < ctx.model.animations[ai].channels.size(); ++ci)
      sample_channel(ctx, ai, ci, time, poses);
  return poses;
}

std::vector<double> morph_weights(const GltfContext& ctx, const std::vector<NodePose>& poses, int mesh,
                                  int node) {
  const auto& gnode = ctx.model.nodes[size_t(node)];
  std::vector<double> morph = ctx.model.meshes[size_t(mesh)].weights;
  if (!gnode.weights.empty()) morph = gnode.weights;
  if (size_t(node) < poses.size() && poses[size_t(node)].has_w) morph = poses[size_t(node)].weights;
  // A non-finite weight contributes nothing; zeroing it keeps the weights usable as a map key
  // (NaN has no order).
  for (double& w : morph)
    if (!std::isfinite(w)) w = 0;
  return morph;
}

std::vector<Transform> joint_matrices(const GltfContext& ctx, NodeTransforms& nodes, int skin_index,
                                      const std::string& node_where) {
  if (skin_index < 0 || size_t(skin_index) >= ctx.model.skins.size())
    ctx.fail(node_where + ".skin", "skin index " + std::to_string(skin_index) + " out of range (" +
                                       std::to_string(ctx.model.skins.size()) + " skins)");
  const auto& skin = ctx.model.skins[size_t(skin_index)];
  const std::string sw = idx("skins", size_t(skin_index));
  if (skin.joints.empty()) ctx.fail(sw + ".joints", "must not be empty");
  std::vector<double> ibm;
  if (skin.inverseBindMatrices >= 0) {
    ibm = read_accessor(ctx, skin.inverseBindMatrices, sw + ".inverseBindMatrices", {TINYGLTF_TYPE_MAT4},
                        {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
    if (ibm.size() < skin.joints.size() * 16)
      ctx.fail(sw + ".inverseBindMatrices", "has fewer matrices than the skin has joints");
  }
  std::vector<Transform> joint_mats;
  for (size_t k = 0; k < skin.joints.size(); ++k) {
    const int j = skin.joints[k];
    if (j < 0 || size_t(j) >= ctx.model.nodes.size())
      ctx.fail(sw + ".joints", "node index " + std::to_string(j) + " out of range");
    Transform inv_bind;
    if (!ibm.empty()) inv_bind = from_column_major(&ibm[k * 16]);
    joint_mats.push_back(world_transform(ctx, nodes, j) * inv_bind);
  }
  return joint_mats;
}

}  // namespace penumbra::gltf
