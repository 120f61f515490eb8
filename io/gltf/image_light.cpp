// EXT_lights_image_based: cube map faces decoded, unpacked and resampled into an environment.
#include "io/gltf/image_light.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>

#include "renderer/lights/environment.h"

namespace penumbra::gltf {

namespace {

constexpr const char* kExt = "EXT_lights_image_based";

// Face image `image` as linear RGB: sRGB decoded, then divided by alpha (RGBD; an opaque face,
// alpha 1, is plain LDR). False (with a warning) if it cannot be decoded.
bool face_texels(const GltfContext& ctx, TextureCache& cache, int image, const std::string& where, int& size,
                 std::vector<Vec3f>& out) {
  const DecodedImage& img = decoded_image(ctx, cache, image, where);
  if (!img.ok) return false;
  if (img.width != img.height)
    ctx.fail(where,
             "cube face is " + std::to_string(img.width) + "x" + std::to_string(img.height) + ", not square");
  if (size >= 0 && img.width != size)
    ctx.fail(where, "cube faces differ in size (" + std::to_string(img.width) + " and " +
                        std::to_string(size) + ")");
  size = img.width;
  out.resize(size_t(size) * size_t(size));
  for (size_t i = 0; i < out.size(); ++i) {
    const float* p = &img.rgba[i * 4];
    const float d = p[3];
    for (int c = 0; c < 3; ++c) out[i][c] = d > 0 ? srgb_to_linear(std::clamp(p[c], 0.0f, 1.0f)) / d : 0.0f;
  }
  return true;
}

// The light's number `key` (absent: `fallback`).
float light_number(const GltfContext& ctx, const tinygltf::Value& light, const char* key, float fallback,
                   const std::string& where) {
  const auto& v = light.Get(key);
  if (v.Type() == tinygltf::NULL_TYPE) return fallback;
  if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()) || v.GetNumberAsDouble() < 0)
    ctx.fail(where + "." + key, "must be a finite number >= 0");
  return float(v.GetNumberAsDouble());
}

// The light's rotation quaternion (x, y, z, w), normalised; the identity when absent.
Vec4f light_rotation(const GltfContext& ctx, const tinygltf::Value& light, const std::string& where) {
  const auto& r = light.Get("rotation");
  if (r.Type() == tinygltf::NULL_TYPE) return {0, 0, 0, 1};
  double q[4];
  if (!r.IsArray() || r.ArrayLen() != 4) ctx.fail(where + ".rotation", "must be 4 numbers");
  for (int k = 0; k < 4; ++k) {
    if (!r.Get(k).IsNumber()) ctx.fail(where + ".rotation", "must be 4 numbers");
    q[k] = r.Get(k).GetNumberAsDouble();
  }
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(n > 1e-6) || !std::isfinite(n)) ctx.fail(where + ".rotation", "is not a unit quaternion");
  return {float(q[0] / n), float(q[1] / n), float(q[2] / n), float(q[3] / n)};
}

}  // namespace

void load_image_light(const GltfContext& ctx, TextureCache& cache) {
  const int scene = ctx.out.info.scene_index;
  if (scene < 0 || size_t(scene) >= ctx.model.scenes.size()) return;
  const auto se = ctx.model.scenes[size_t(scene)].extensions.find(kExt);
  if (se == ctx.model.scenes[size_t(scene)].extensions.end()) return;
  const std::string sw = idx("scenes", size_t(scene)) + ".extensions." + kExt + ".light";
  const auto& root = ctx.model.extensions.find(kExt);
  const tinygltf::Value* lights = root != ctx.model.extensions.end() ? &root->second.Get("lights") : nullptr;
  const size_t count = lights && lights->IsArray() ? lights->ArrayLen() : 0;
  const auto& index = se->second.Get("light");
  if (!index.IsInt() || index.GetNumberAsInt() < 0 || size_t(index.GetNumberAsInt()) >= count)
    ctx.fail(sw, "must be an image-based light index below " + std::to_string(count));
  const size_t li = size_t(index.GetNumberAsInt());
  const tinygltf::Value& light = lights->Get(int(li));
  const std::string lw = std::string("extensions.") + kExt + ".lights[" + std::to_string(li) + "]";
  const auto& mips = light.Get("specularImages");
  if (!mips.IsArray() || mips.ArrayLen() < 1 || !mips.Get(0).IsArray() || mips.Get(0).ArrayLen() != 6)
    ctx.fail(lw + ".specularImages", "must hold at least one mip of 6 cube faces");
  std::vector<Vec3f> faces[6];
  int size = -1;
  for (int f = 0; f < 6; ++f) {
    const auto& img = mips.Get(0).Get(f);
    const std::string fw = lw + ".specularImages[0][" + std::to_string(f) + "]";
    if (!img.IsInt() || img.GetNumberAsInt() < 0 || size_t(img.GetNumberAsInt()) >= ctx.model.images.size())
      ctx.fail(fw, "image index out of range (" + std::to_string(ctx.model.images.size()) + " images)");
    if (!face_texels(ctx, cache, img.GetNumberAsInt(), fw, size, faces[f])) {
      ctx.warn(lw, "a cube face could not be decoded; the image-based light is not used");
      return;
    }
  }
  const float intensity = light_number(ctx, light, "intensity", 1, lw);
  const Vec4f rotation = light_rotation(ctx, light, lw);
  const int width = 4 * size, height = 2 * size;
  ctx.charge(uint64_t(width) * uint64_t(height) * (sizeof(Vec3f) + 3 * sizeof(float)), lw,
             "its " + std::to_string(width) + "x" + std::to_string(height) + " environment map needs");
  std::vector<Vec3f> texels = equirect_from_cube(faces, size, width, height, rotation);
  ctx.out.environment = std::make_shared<const Environment>(
      make_map_environment(width, height, std::move(texels), intensity, 0));
  ctx.out.info.image_light = light.Get("name").IsString() ? light.Get("name").Get<std::string>() : lw;
}

}  // namespace penumbra::gltf
