// Images and samplers for the glTF loader: encoded image bytes (files, data URIs or bufferViews)
// decoded through OpenImageIO, and glTF textures (image + sampler) turned into the scene's
// MIP-mapped textures, each made once per (texture, colour space). Material texture infos and
// KHR_texture_transform are in materials.h.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "io/gltf/context.h"

namespace tinygltf {
class TinyGLTF;
}

namespace penumbra::gltf {

/// Largest texture edge accepted (larger images are ignored with a warning).
constexpr int kMaxTextureSize = 16384;

/// Switches tinygltf's image decoding off: URI images keep their encoded bytes in Image::image
/// for decoded_image(); bufferView images are read from the validated bufferView instead.
void keep_encoded_images(tinygltf::TinyGLTF& parser);

/// Decoded image: RGBA floats in [0,1] exactly as stored in the file (sRGB not decoded).
struct DecodedImage {
  bool ok = false;  ///< false: unreadable, with a warning; textures using it are ignored
  int width = 0, height = 0;
  std::vector<float> rgba;
};

/// Images decoded so far and the scene textures made from them.
struct TextureCache {
  std::map<int, DecodedImage> images;            ///< glTF image -> decoded, on first use
  std::map<std::pair<int, bool>, int> textures;  ///< (glTF texture, sRGB) -> Scene::textures, -1 unusable
};

/// images[image] decoded (once; later calls return the cached result). `user` names the texture
/// info asking, for warnings. Charges the decoded texels.
const DecodedImage& decoded_image(const GltfContext& ctx, TextureCache& cache, int image,
                                  const std::string& user);

/// The Scene::textures index of textures[texture] made from images[image] (its source, or an
/// extension's: texture_image()) with its sampler, sRGB-decoded if `srgb`, made on first use; -1
/// if the image is unusable. `texture` and `image` are valid indices.
int scene_texture(const GltfContext& ctx, TextureCache& cache, int texture, int image, bool srgb,
                  const std::string& where);

/// The image textures[texture] reads: EXT_texture_webp's source when present (OpenImageIO
/// decodes WebP), else the core source; under KHR_texture_basisu the core source is the
/// fallback (KTX2 is not decoded), and without one a warning names the texture. -1 (with a
/// warning) if there is none usable; `texture` is a valid index.
int texture_image(const GltfContext& ctx, int texture);

/// Warns about textures whose source or sampler index is out of range (they are ignored or use
/// the default sampler).
void validate_textures(const GltfContext& ctx);

}  // namespace penumbra::gltf
