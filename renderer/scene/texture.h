// Textures: MIP-mapped RGBA images (linear values in [0,1], 16 bits per channel) with glTF
// sampler state, looked up with nearest/bilinear magnification and trilinear minification
// at a level chosen from screen-space UV derivatives (ray differentials). Decoding files is
// io/'s job; this module only stores and filters texels.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "renderer/core/math.h"

namespace penumbra {

enum class TextureWrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };
enum class TextureFilter : uint8_t { Nearest, Linear };

/// glTF sampler state. The default (no sampler in the file) is repeat + trilinear.
struct TextureSampler {
  TextureWrap wrap_s = TextureWrap::Repeat, wrap_t = TextureWrap::Repeat;
  TextureFilter mag = TextureFilter::Linear;  ///< texel filter when magnifying (lod <= 0)
  TextureFilter min = TextureFilter::Linear;  ///< texel filter within a level when minifying
  bool mipmaps = true;                        ///< minification reads the MIP pyramid
  TextureFilter mip = TextureFilter::Linear;  ///< nearest level, or blend of the two nearest
};

/// One level: width x height texels, 4 channels each, row 0 is the image's top row (v = 0).
struct MipLevel {
  int width = 0, height = 0;
  std::vector<uint16_t> texels;  ///< RGBA unorm16, row-major
};

struct Texture {
  std::string name;              ///< for messages: "textures[3] (images[1] 'wood.png')"
  std::vector<MipLevel> levels;  ///< level 0 = full resolution, each next halves (ceil) down to 1x1
  TextureSampler sampler;
};

/// Builds a texture from linear RGBA floats (clamped to [0,1]); the pyramid is made by 2x2
/// box filtering in linear space (odd sizes clamp the last row/column). width, height >= 1,
/// rgba.size() == 4 * width * height.
Texture make_texture(std::string name, int width, int height, const std::vector<float>& rgba,
                     const TextureSampler& sampler);

/// Bytes held by the texture's levels.
uint64_t texture_bytes(const Texture& tex);

/// Bytes make_texture() would need for a width x height image (for budgets before decoding).
uint64_t texture_bytes_for(int width, int height);

/// sRGB transfer function decode (IEC 61966-2-1), v in [0,1].
float srgb_to_linear(float v);

/// Level of detail of a footprint: log2 of the longer of the two screen-space derivative
/// vectors measured in level-0 texels (pbrt's isotropic MIP map, Williams 1983). A zero
/// footprint gives -inf (magnification).
float texture_lod(const Texture& tex, Vec2f duvdx, Vec2f duvdy);

/// Filtered lookup at texture coordinate uv (glTF convention: (0,0) is the top-left corner of
/// the image, texel centres at (i + 0.5) / width) for level of detail `lod`:
/// lod <= 0 or no mipmaps: the magnification or minification texel filter on level 0;
/// otherwise trilinear (or nearest-level) between the levels around lod.
/// Never allocates; NaN uv returns the texel at (0,0).
Vec4f sample_texture(const Texture& tex, Vec2f uv, float lod);

}  // namespace penumbra
