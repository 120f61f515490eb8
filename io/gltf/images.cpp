// Images and samplers: encoded bytes located and sniffed, decoded through OpenImageIO under the
// memory budget, expanded to RGBA, and glTF textures made into Scene textures.
#include "io/gltf/images.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <tiny_gltf.h>

#include <cstring>
#include <span>

#include "io/gltf/accessors.h"

namespace penumbra::gltf {

namespace {

// Images are decoded later through OpenImageIO. For URI images (files, data URIs) tinygltf hands
// over the bytes it read: keep them, encoded, in Image::image. For bufferView images it passes a
// pointer computed without a bounds check, so those bytes are not touched here.
bool capture_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                   const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0 && bytes && size > 0) image->image.assign(bytes, bytes + size);
  return true;
}

// The encoded bytes of an image: a validated bufferView, or what tinygltf read from the URI.
std::span<const unsigned char> encoded_bytes(const GltfContext& ctx, const tinygltf::Image& img,
                                             const std::string& where) {
  if (img.bufferView >= 0) return buffer_view_bytes(ctx, img.bufferView, where + ".bufferView");
  return {img.image.data(), img.image.size()};
}

// "png" or "jpg" from the magic bytes (the mimeType and file extension are only hints); "" else.
std::string sniff_format(std::span<const unsigned char> data) {
  if (data.size() >= 8 && std::memcmp(data.data(), "\x89PNG\r\n\x1a\n", 8) == 0) return "png";
  if (data.size() >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF) return "jpg";
  if (data.size() >= 12 && std::memcmp(data.data(), "RIFF", 4) == 0 &&
      std::memcmp(data.data() + 8, "WEBP", 4) == 0)
    return "webp";
  if (data.size() >= 12 && std::memcmp(data.data(), "\xABKTX 20\xBB\r\n\x1A\n", 12) == 0) return "ktx2";
  return "";
}

// nc-channel pixels to RGBA: grey (+ alpha) is replicated, a missing alpha is 1.
void expand_to_rgba(const std::vector<float>& pixels, int nc, size_t texels, std::vector<float>& rgba) {
  rgba.resize(texels * 4);
  for (size_t i = 0; i < texels; ++i) {
    const float* p = &pixels[i * size_t(nc)];
    float* q = &rgba[i * 4];
    if (nc <= 2) {
      q[0] = q[1] = q[2] = p[0];
      q[3] = nc == 2 ? p[1] : 1.0f;
    } else {
      q[0] = p[0];
      q[1] = p[1];
      q[2] = p[2];
      q[3] = nc >= 4 ? p[3] : 1.0f;
    }
  }
}

// Decodes `data` (format `ext`) into `out`; a warning and out.ok == false if it cannot be used.
void decode_into(const GltfContext& ctx, std::span<const unsigned char> data, const std::string& ext,
                 const std::string& where, DecodedImage& out) {
  OIIO::Filesystem::IOMemReader reader(data.data(), data.size());
  OIIO::ImageSpec config;  // glTF colour is not premultiplied: keep RGB where alpha is 0
  config.attribute("oiio:UnassociatedAlpha", 1);
  OIIO::Filesystem::IOProxy* proxy = &reader;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto in = OIIO::ImageInput::open("image." + ext, &config, &reader);
  if (!in) {
    ctx.warn(where,
             "cannot decode " + ext + " image: " + OIIO::geterror() + "; textures using it are ignored");
    return;
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.width > kMaxTextureSize || spec.height > kMaxTextureSize ||
      spec.nchannels < 1 || spec.nchannels > 64) {
    ctx.warn(where, "image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " with " +
                        std::to_string(spec.nchannels) + " channels (limit " +
                        std::to_string(kMaxTextureSize) + " per side); textures using it are ignored");
    return;
  }
  const uint64_t texels = uint64_t(spec.width) * uint64_t(spec.height);
  ctx.charge(
      texels * uint64_t(spec.nchannels) * 4 + texels * 16, where,
      "decoding the " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " image needs");
  std::vector<float> pixels(size_t(texels) * size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data())) {
    ctx.warn(where, "cannot decode " + ext + " image: " + in->geterror() + "; textures using it are ignored");
    return;
  }
  in->close();
  ctx.budget.release(texels * uint64_t(spec.nchannels) * 4);  // the channel buffer is freed below
  expand_to_rgba(pixels, spec.nchannels, size_t(texels), out.rgba);
  out.width = spec.width;
  out.height = spec.height;
  out.ok = true;
}

// The sampler of a texture (glTF 2.0 spec 3.8.3, "Samplers"); the default one without.
TextureSampler texture_sampler(const GltfContext& ctx, int sampler) {
  TextureSampler smp;
  if (sampler < 0 || size_t(sampler) >= ctx.model.samplers.size()) return smp;
  const auto& s = ctx.model.samplers[size_t(sampler)];
  const std::string sw = idx("samplers", size_t(sampler));
  auto wrap = [&](int mode, const char* field) {
    switch (mode) {
      case TINYGLTF_TEXTURE_WRAP_REPEAT:
        return TextureWrap::Repeat;
      case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
        return TextureWrap::ClampToEdge;
      case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
        return TextureWrap::MirroredRepeat;
      default:
        ctx.warn(sw + "." + field, "unknown wrap mode " + std::to_string(mode) + "; REPEAT used");
        return TextureWrap::Repeat;
    }
  };
  smp.wrap_s = wrap(s.wrapS, "wrapS");
  smp.wrap_t = wrap(s.wrapT, "wrapT");
  if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) smp.mag = TextureFilter::Nearest;
  switch (s.minFilter) {
    case TINYGLTF_TEXTURE_FILTER_NEAREST:
      smp.min = TextureFilter::Nearest;
      smp.mipmaps = false;
      break;
    case TINYGLTF_TEXTURE_FILTER_LINEAR:
      smp.mipmaps = false;
      break;
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
      smp.min = TextureFilter::Nearest;
      smp.mip = TextureFilter::Nearest;
      break;
    case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
      smp.mip = TextureFilter::Nearest;
      break;
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR:
      smp.min = TextureFilter::Nearest;
      break;
    default:
      break;  // LINEAR_MIPMAP_LINEAR or unspecified: trilinear
  }
  return smp;
}

}  // namespace

void keep_encoded_images(tinygltf::TinyGLTF& parser) {
  parser.SetImageLoader(capture_image, nullptr);
}

const DecodedImage& decoded_image(const GltfContext& ctx, TextureCache& cache, int image_index,
                                  const std::string& user) {
  if (auto it = cache.images.find(image_index); it != cache.images.end()) return it->second;
  DecodedImage& out = cache.images[image_index];
  const auto& img = ctx.model.images[size_t(image_index)];
  const std::string where =
      idx("images", size_t(image_index)) + (img.name.empty() ? "" : " '" + img.name + "'");
  const std::span<const unsigned char> data = encoded_bytes(ctx, img, where);
  if (data.empty()) {
    ctx.warn(where, "image data could not be read" +
                        (img.uri.empty() ? std::string() : " from '" + img.uri + "'") +
                        "; textures using it (" + user + ") are ignored");
    return out;
  }
  const std::string ext = sniff_format(data);
  if (ext == "ktx2") {
    ctx.warn(where,
             "a KTX2 image (KHR_texture_basisu), which this build cannot decode (Debian 12 ships no KTX2 "
             "decoder) and which has no fallback source; textures using it (" +
                 user + ") are ignored, the material's factors apply");
    return out;
  }
  if (ext.empty()) {
    ctx.warn(where, "not a PNG, JPEG or WebP image; textures using it (" + user + ") are ignored");
    return out;
  }
  decode_into(ctx, data, ext, where, out);
  return out;
}

int scene_texture(const GltfContext& ctx, TextureCache& cache, int texture, int image, bool srgb,
                  const std::string& where) {
  if (auto it = cache.textures.find({texture, srgb}); it != cache.textures.end()) return it->second;
  const auto& t = ctx.model.textures[size_t(texture)];
  const DecodedImage& img = decoded_image(ctx, cache, image, where);
  if (!img.ok) {
    cache.textures[{texture, srgb}] = -1;
    return -1;
  }
  const TextureSampler smp = texture_sampler(ctx, t.sampler);
  const uint64_t copy_bytes = uint64_t(img.rgba.size()) * sizeof(float);
  ctx.charge(copy_bytes, where, "a working copy of its texels needs");
  std::vector<float> rgba = img.rgba;
  if (srgb)
    for (size_t i = 0; i < rgba.size(); i += 4)
      for (size_t c = 0; c < 3; ++c) rgba[i + c] = srgb_to_linear(std::clamp(rgba[i + c], 0.0f, 1.0f));
  const auto& source = ctx.model.images[size_t(image)];
  ctx.charge(texture_bytes_for(img.width, img.height), where, "its MIP-mapped texture needs");
  const int index = int(ctx.out.scene.textures.size());
  ctx.out.scene.textures.push_back(
      make_texture(idx("textures", size_t(texture)) + " (" + idx("images", size_t(image)) +
                       (source.name.empty() ? (source.uri.empty() ? "" : " '" + source.uri + "'")
                                            : " '" + source.name + "'") +
                       ")",
                   img.width, img.height, rgba, smp));
  ctx.budget.release(copy_bytes);  // rgba is freed on return
  cache.textures[{texture, srgb}] = index;
  return index;
}

int texture_image(const GltfContext& ctx, int texture) {
  const auto& t = ctx.model.textures[size_t(texture)];
  const std::string where = idx("textures", size_t(texture));
  const int images = int(ctx.model.images.size());
  auto extension_source = [&](const char* name) {
    const auto it = t.extensions.find(name);
    if (it == t.extensions.end()) return -2;  // absent
    const auto& s = it->second.Get("source");
    if (!s.IsInt() || s.GetNumberAsInt() < 0 || s.GetNumberAsInt() >= images) {
      ctx.warn(where + ".extensions." + name + ".source", "image index out of range (" +
                                                              std::to_string(images) +
                                                              " images); the texture's own source is used");
      return -1;
    }
    return s.GetNumberAsInt();
  };
  if (const int webp = extension_source("EXT_texture_webp"); webp >= 0) return webp;
  const bool basisu = extension_source("KHR_texture_basisu") != -2;
  if (t.source >= 0 && t.source < images) return t.source;
  if (basisu)
    ctx.warn(where,
             "KHR_texture_basisu image without a fallback source: this build cannot decode KTX2 (Debian 12 "
             "ships no decoder); the material's factors apply");
  else if (t.source < 0)
    ctx.warn(where, "has no image source; ignored");
  return -1;
}

void validate_textures(const GltfContext& ctx) {
  for (size_t i = 0; i < ctx.model.textures.size(); ++i) {
    const auto& t = ctx.model.textures[i];
    if (t.source < -1 || t.source >= int(ctx.model.images.size()))
      ctx.warn(idx("textures", i) + ".source",
               "image index " + std::to_string(t.source) + " out of range; texture ignored");
    if (t.sampler < -1 || t.sampler >= int(ctx.model.samplers.size()))
      ctx.warn(idx("textures", i) + ".sampler",
               "sampler index " + std::to_string(t.sampler) + " out of range; default sampler used");
  }
}

}  // namespace penumbra::gltf
