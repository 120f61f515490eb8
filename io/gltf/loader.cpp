// glTF 2.0 loading: the public entry points and the order of the phases. parse.h reads and
// parses the file; then the model is described (GltfInfo), validated and converted by
// accessors, images, materials, meshes, animation and nodes, each in its own file.
#include "io/gltf/loader.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <new>

#include "io/files/file_checks.h"
#include "io/gltf/accessors.h"
#include "io/gltf/animation.h"
#include "io/gltf/animation_pointer.h"
#include "io/gltf/compression.h"
#include "io/gltf/context.h"
#include "io/gltf/file_access.h"
#include "io/gltf/image_light.h"
#include "io/gltf/images.h"
#include "io/gltf/materials.h"
#include "io/gltf/meshes.h"
#include "io/gltf/nodes.h"
#include "io/gltf/parse.h"
#include "io/gltf/pose.h"
#include "io/gltf/shapes.h"
#include "io/gltf/splats.h"

namespace penumbra {

std::vector<std::string> supported_gltf_extensions() {
  std::vector<std::string> out = {"KHR_lights_punctual"};
  for (auto& e : gltf::material_extensions()) out.push_back(std::move(e));
  for (auto& e : gltf::compression_extensions()) out.push_back(std::move(e));
  out.push_back("EXT_mesh_gpu_instancing");
  out.push_back("KHR_materials_variants");
  out.push_back("KHR_animation_pointer");
  out.push_back("EXT_lights_image_based");
  out.push_back("KHR_materials_pbrSpecularGlossiness");
  out.push_back("EXT_texture_webp");
  out.push_back("KHR_texture_basisu");
  out.push_back(gltf::kShapesExtension);
  out.push_back(gltf::kProceduralExtension);
  out.push_back(gltf::kPointsExtension);
  out.push_back(gltf::kGaussianSplatting);
  return out;
}

std::vector<std::pair<std::string, std::string>> partial_gltf_extensions() {
  return {{"KHR_texture_basisu",
           "KTX2 images are not decoded (no decoder in Debian 12): the texture's "
           "fallback source is used, else the material's factors"},
          {"KHR_materials_pbrSpecularGlossiness",
           "converted to metallic-roughness from its factors and diffuse texture; the "
           "specular-glossiness texture is not used"},
          {"KHR_meshopt_compression",
           "Debian 12's meshoptimizer 0.18 decodes version-0 streams only; version-1 streams and the COLOR "
           "filter are errors"}};
}

int json_nesting_depth(std::string_view json, int limit) {
  int depth = 0, max_depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (c == '\\')
        ++i;  // skip the escaped character
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      max_depth = std::max(max_depth, ++depth);
      if (max_depth > limit) return limit + 1;
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
  return max_depth;
}

namespace gltf {
namespace {

// The descriptive facts of GltfInfo that come straight from the model.
void describe(const tinygltf::Model& model, GltfInfo& info) {
  info.generator = model.asset.generator;
  info.version = model.asset.version;
  info.scene_count = int(model.scenes.size());
  for (size_t i = 0; i < model.scenes.size(); ++i)
    info.scene_names.push_back(model.scenes[i].name.empty() ? idx("scenes", i) : model.scenes[i].name);
  info.node_count = int(model.nodes.size());
  for (size_t i = 0; i < model.nodes.size(); ++i)
    info.node_names.push_back(model.nodes[i].name.empty() ? idx("nodes", i) : model.nodes[i].name);
  info.node_parents.assign(model.nodes.size(), -1);
  for (size_t i = 0; i < model.nodes.size(); ++i)
    for (int c : model.nodes[i].children)
      if (c >= 0 && size_t(c) < model.nodes.size() && size_t(c) != i) info.node_parents[size_t(c)] = int(i);
  info.node_skin_joints.assign(model.nodes.size(), {});
  for (size_t i = 0; i < model.nodes.size(); ++i) {
    const int skin = model.nodes[i].skin;
    if (skin < 0 || size_t(skin) >= model.skins.size()) continue;
    for (int j : model.skins[size_t(skin)].joints)
      if (j >= 0 && size_t(j) < model.nodes.size()) info.node_skin_joints[i].push_back(j);
  }
  info.mesh_count = int(model.meshes.size());
  for (size_t i = 0; i < model.meshes.size(); ++i) {
    const auto& m = model.meshes[i];
    info.primitive_count += int(m.primitives.size());
    info.meshes.push_back({m.name.empty() ? idx("meshes", i) : m.name, int(m.primitives.size()), 0});
  }
  info.gltf_camera_count = int(model.cameras.size());
  info.gltf_light_count = int(model.lights.size());
  info.image_count = int(model.images.size());
  info.animation_count = int(model.animations.size());
  info.extensions_used = model.extensionsUsed;
  info.extensions_required = model.extensionsRequired;
}

// KHR_materials_variants: the variant names, and the index of the one the options ask for.
void select_variant(const GltfContext& ctx) {
  GltfInfo& info = ctx.out.info;
  const std::string where = "extensions.KHR_materials_variants.variants";
  if (auto it = ctx.model.extensions.find("KHR_materials_variants"); it != ctx.model.extensions.end()) {
    const auto& variants = it->second.Get("variants");
    if (!variants.IsArray()) ctx.fail(where, "must be an array");
    for (size_t i = 0; i < variants.ArrayLen(); ++i) {
      const auto& name = variants.Get(int(i)).Get("name");
      if (!name.IsString()) ctx.fail(where + "[" + std::to_string(i) + "].name", "must be a string");
      info.variants.push_back(name.Get<std::string>());
    }
  }
  if (ctx.options.variant.empty()) return;
  const auto found = std::find(info.variants.begin(), info.variants.end(), ctx.options.variant);
  if (found == info.variants.end()) {
    std::string list;
    for (const auto& v : info.variants) list += (list.empty() ? "" : ", ") + ("'" + v + "'");
    ctx.fail(where, "no variant '" + ctx.options.variant + "'; " +
                        (list.empty() ? std::string("the file defines no variants") : "variants: " + list));
  }
  info.variant = int(found - info.variants.begin());
}

// The asset version and the extensions: a required one outside supported_gltf_extensions() is
// an error, a used one a warning.
void check_version_and_extensions(const GltfContext& ctx) {
  const tinygltf::Model& model = ctx.model;
  if (!model.asset.version.empty() && model.asset.version.rfind("2.", 0) != 0)
    ctx.fail("asset.version", "version '" + model.asset.version + "' is not glTF 2.x");
  const auto supported = supported_gltf_extensions();
  for (const auto& e : model.extensionsRequired)
    if (std::find(supported.begin(), supported.end(), e) == supported.end())
      ctx.fail("extensionsRequired", "extension " + e + " is required by the file but not supported");
  for (const auto& e : model.extensionsUsed)
    if (std::find(supported.begin(), supported.end(), e) == supported.end())
      ctx.warn("extensionsUsed", "extension " + e + " is not supported and will be ignored");
}

// The conversion phases, in order: whole-model validation, materials (with their textures),
// meshes in local space, the animated pose, then the node walk that places cameras, lights,
// meshes and the shapes read with the raw JSON. Returns what posing the scene at another time
// needs when a time and keep_animation are asked for and the file has animations, else null.
std::shared_ptr<GltfAnimation> convert(const GltfContext& ctx, VendorExtensions& vendor) {
  describe(ctx.model, ctx.out.info);
  check_version_and_extensions(ctx);
  select_variant(ctx);
  validate_accessors(ctx);
  validate_textures(ctx);
  validate_material_textures(ctx);
  TextureCache textures;
  convert_materials(ctx, textures);
  attach_procedurals(ctx.out.scene, vendor.procedurals);
  validate_cameras(ctx);
  validate_lights(ctx);
  const std::vector<std::vector<LocalPrimitive>> meshes = decode_meshes(ctx);
  for (size_t m = 0; m < meshes.size(); ++m)
    for (const LocalPrimitive& p : meshes[m])
      if (p.usable) ctx.out.info.meshes[m].triangles += p.indices.size() / 3;
  std::vector<NodePose> poses;
  if (ctx.options.time) poses = evaluate_animations(ctx, *ctx.options.time);
  const std::vector<int> roots = scene_roots(ctx);
  load_image_light(ctx, textures);
  NodeTransforms nodes = link_nodes(ctx, poses);
  if (ctx.options.time) mark_moving_nodes(ctx, nodes);
  const NodeUses uses = place_nodes(ctx, nodes, roots);
  place_meshes(ctx, meshes, nodes, uses.meshes);
  place_shapes(ctx, vendor.shapes, nodes, uses.shapes);
  const int scene = ctx.out.info.scene_index;
  if (ctx.out.scene.meshes.empty() && ctx.out.scene.shapes.empty())
    ctx.warn(scene >= 0 ? idx("scenes", size_t(scene)) : "scenes",
             "no renderable triangles or shapes; the image shows only the background");
  if (!ctx.options.time || !ctx.options.keep_animation || ctx.model.animations.empty()) return nullptr;
  std::shared_ptr<GltfAnimation> animation = describe_animation(ctx, nodes, uses);
  return animation->rigid ? animation : nullptr;  // a scene that cannot be posed is loaded again
}

}  // namespace
}  // namespace gltf

LoadedScene load_gltf(const std::filesystem::path& file, const GltfLoadOptions& options) {
  const std::string name = file.string();
  // Another 3D format is named before its bytes reach the JSON parser.
  const uint64_t size = check_input_file(file, "", options.max_file_bytes);
  const std::vector<unsigned char> head =
      gltf::read_input_file(file, "", options.max_file_bytes, kSceneSniffBytes);
  check_gltf_file_format(file, {reinterpret_cast<const char*>(head.data()), head.size()}, size);
  gltf::MemoryBudget budget(name, options.max_memory_bytes);
  LoadedScene out;
  tinygltf::Model model;
  gltf::VendorExtensions vendor;
  gltf::parse_gltf(file, options, budget, out, model, vendor);
  std::shared_ptr<GltfAnimation> animation;
  try {
    gltf::decompress_model(model, name, budget);
    if (options.time && gltf::has_animation_pointers(model))
      gltf::apply_animation_pointers(gltf::GltfContext{model, name, options, budget, out}, model,
                                     *options.time);
    animation = gltf::convert(gltf::GltfContext{model, name, options, budget, out}, vendor);
  } catch (const std::bad_alloc&) {
    throw InputError(name, "", "out of memory while converting the scene");
  }
  if (animation) {
    for (const auto& b : model.buffers) out.animation_bytes += b.data.size();
    for (const auto& i : model.images) out.animation_bytes += i.image.size();
    animation->model = std::move(model);
    out.animation = std::move(animation);
  }
  return out;
}

}  // namespace penumbra
