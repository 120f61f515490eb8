// Denoising an EXR: the file is checked as merge checks a part, its halves channels are decoded
// and checked, the denoiser runs, and the parts are written back in their native channel types
// with the second beauty added.
#include "io/image/exr_denoise.h"

#include <OpenImageIO/half.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "io/files/atomic_file.h"
#include "io/files/error.h"
#include "io/files/file_checks.h"
#include "io/image/exr_merge.h"
#include "io/image/exr_parts.h"

namespace penumbra {

std::string denoise_channel_name(int half, int k) {
  const std::string h = half ? "odd" : "even";
  if (k < 3) return h + "." + "RGB"[k];
  if (k < 6) return h + "_albedo." + "RGB"[k - 3];
  if (k < 9) return h + "_N." + "XYZ"[k - 6];
  return h + "_Z.Z";
}

namespace {

using exr_parts::image_bytes;

// Where a channel lives: its part, its index there and its byte offset within a pixel.
struct ChannelRef {
  int part = -1, index = -1;
  size_t offset = 0;
  OIIO::TypeDesc type;
};

float load_value(const unsigned char* p, OIIO::TypeDesc type) {
  if (type == OIIO::TypeDesc::HALF) {
    half h;
    std::memcpy(&h, p, sizeof h);
    return float(h);
  }
  if (type == OIIO::TypeDesc::FLOAT) {
    float f;
    std::memcpy(&f, p, sizeof f);
    return f;
  }
  uint32_t u;
  std::memcpy(&u, p, sizeof u);
  return float(u);
}

void store_value(unsigned char* p, OIIO::TypeDesc type, float v) {
  if (type == OIIO::TypeDesc::HALF) {
    const half h(v);
    std::memcpy(p, &h, sizeof h);
  } else {
    std::memcpy(p, &v, sizeof v);
  }
}

// Every channel of every part by name (the first part's wins for a name repeated).
std::map<std::string, ChannelRef> channel_map(const std::vector<OIIO::ImageSpec>& specs) {
  std::map<std::string, ChannelRef> refs;
  for (size_t sub = 0; sub < specs.size(); ++sub) {
    size_t offset = 0;
    for (int c = 0; c < specs[sub].nchannels; ++c) {
      const std::string& name = specs[sub].channelnames[size_t(c)];
      refs.emplace(name, ChannelRef{int(sub), c, offset, specs[sub].channelformat(c)});
      offset += specs[sub].channelformat(c).size();
    }
  }
  return refs;
}

// Throws unless the file has the beauty and every halves channel and is not denoised already.
void check_channels(const std::string& name, const std::vector<OIIO::ImageSpec>& specs,
                    const std::map<std::string, ChannelRef>& refs) {
  if (const OIIO::ParamValue* p = specs[0].find_attribute(kDenoiserAttribute))
    throw InputError(name, kDenoiserAttribute, "is already denoised ('" + p->get_string() + "')");
  for (const char* layer : {"noisy", "denoised"})
    if (refs.count(std::string(layer) + ".R"))
      throw InputError(name, std::string(layer) + ".R",
                       std::string("is already denoised: it has a ") + layer + " layer");
  for (const char* c : {"R", "G", "B", "A"}) {
    const auto it = refs.find(c);
    if (it == refs.end() || it->second.part != 0)
      throw InputError(name, c, "has no beauty channel " + std::string(c) + " in its first part");
    if (it->second.type != OIIO::TypeDesc::HALF && it->second.type != OIIO::TypeDesc::FLOAT)
      throw InputError(name, c, "the beauty is neither half nor float");
  }
  std::set<std::string> missing;
  for (int h = 0; h < 2; ++h)
    for (int k = 0; k < kDenoiseChannelsPerHalf; ++k) {
      const std::string ch = denoise_channel_name(h, k);
      const auto it = refs.find(ch);
      if (it == refs.end())
        missing.insert(ch.substr(0, ch.find('.')));
      else if (it->second.type != OIIO::TypeDesc::HALF && it->second.type != OIIO::TypeDesc::FLOAT)
        throw InputError(name, ch, "is neither half nor float");
    }
  if (!missing.empty()) {
    std::string list;
    for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
    throw InputError(name, "",
                     "lacks the layers the denoiser needs: " + list +
                         " (render with --denoise, or --aov halves to denoise later)");
  }
}

// The denoiser's input from the decoded parts; throws InputError naming the channel and pixel of
// a NaN or infinity (a depth may be +inf: nothing was hit).
DenoiseInput decode_input(const std::string& name, const std::vector<OIIO::ImageSpec>& specs,
                          const std::map<std::string, ChannelRef>& refs,
                          const std::vector<std::vector<unsigned char>>& pixels) {
  const OIIO::ImageSpec& s0 = specs[0];
  DenoiseInput in;
  in.width = s0.width;
  in.height = s0.height;
  const size_t n = size_t(s0.width) * size_t(s0.height);
  for (int h = 0; h < 2; ++h) {
    in.color[h].resize(n * 3);
    in.features[h].resize(n * kDenoiseFeatures);
    for (int k = 0; k < kDenoiseChannelsPerHalf; ++k) {
      const std::string ch = denoise_channel_name(h, k);
      const ChannelRef& r = refs.at(ch);
      const size_t stride = specs[size_t(r.part)].pixel_bytes(true);
      const unsigned char* base = pixels[size_t(r.part)].data() + r.offset;
      float* dst = k < 3 ? &in.color[h][size_t(k)] : &in.features[h][size_t(k - 3)];
      const size_t step = k < 3 ? 3 : kDenoiseFeatures;
      const bool depth = k == kDenoiseChannelsPerHalf - 1;
      for (size_t i = 0; i < n; ++i) {
        const float v = load_value(base + i * stride, r.type);
        if (!(std::isfinite(v) || (depth && v > 0)))
          throw InputError(name, ch,
                           "holds " + std::to_string(v) + " at pixel " +
                               std::to_string(s0.x + int64_t(i % size_t(s0.width))) + "," +
                               std::to_string(s0.y + int64_t(i / size_t(s0.width))) +
                               " (the denoiser needs finite values; a depth may be +inf)");
        dst[i * step] = v;
      }
    }
  }
  return in;
}

// The four channels of the second beauty ("noisy" or "denoised") in the beauty's types.
std::vector<std::pair<std::string, OIIO::TypeDesc>> second_channels(
    const std::string& layer, const std::map<std::string, ChannelRef>& refs) {
  std::vector<std::pair<std::string, OIIO::TypeDesc>> out;
  for (const char* c : {"R", "G", "B", "A"}) out.push_back({layer + "." + c, refs.at(c).type});
  return out;
}

// denoise_exr reading `in_path` (named `name` in errors) and writing `write_to`; the Cryptomatte
// sidecars are named after `named_as`, the path the output ends up at.
Film denoise_file(const std::filesystem::path& in_path, const std::string& name,
                  const std::filesystem::path& write_to, const std::filesystem::path& named_as,
                  const ExrDenoiseOptions& options, std::string* sha256) {
  if (const char* problem = validate(options.config); *problem)
    throw std::invalid_argument(std::string("denoise: ") + problem);
  const uint64_t size = check_input_file(in_path, "", kMaxMergePartBytes);
  exr_parts::check_exr_header(in_path, size);
  auto input = exr_parts::open_part(in_path.string());
  std::vector<OIIO::ImageSpec> specs = exr_parts::read_specs(*input, name);
  const std::map<std::string, ChannelRef> refs = channel_map(specs);
  check_channels(name, specs, refs);
  const OIIO::ImageSpec s0 = specs[0];
  const size_t n = size_t(s0.width) * size_t(s0.height);

  // The file's pixels (twice: read and written, with the second beauty), the denoiser's input
  // and output and its buffers.
  double bytes = double(exr_denoise_bytes(s0.width, s0.height, options.config));
  for (const auto& sp : specs) bytes += 2 * image_bytes(sp, false);
  if (bytes > double(options.max_memory_bytes))
    throw InputError(name, "",
                     "denoising its " + std::to_string(s0.width) + "x" + std::to_string(s0.height) +
                         " pixels needs " + format_bytes(uint64_t(bytes)) + ", over the " +
                         format_bytes(options.max_memory_bytes) + " limit (--max-memory)");

  std::vector<std::vector<unsigned char>> pixels(specs.size());
  for (size_t sub = 0; sub < specs.size(); ++sub) {
    pixels[sub].resize(size_t(image_bytes(specs[sub], false)));
    if (!input->read_image(int(sub), 0, 0, specs[sub].nchannels, OIIO::TypeDesc::UNKNOWN, pixels[sub].data()))
      throw InputError(name, "", "cannot decode: " + input->geterror());
  }
  input->close();
  const std::vector<float> rgb =
      denoise_nfor(decode_input(name, specs, refs, pixels), options.config, options.progress);

  // The beauty as read, and the denoised one (alpha kept).
  const size_t stride0 = s0.pixel_bytes(true);
  Film noisy{s0.width, s0.height, std::vector<float>(n * 4), s0.x, s0.y, s0.full_width, s0.full_height};
  const char* rgba[4] = {"R", "G", "B", "A"};
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 4; ++c) {
      const ChannelRef& r = refs.at(rgba[c]);
      noisy.rgba[i * 4 + size_t(c)] = load_value(&pixels[0][i * stride0 + r.offset], r.type);
    }
  Film denoised = noisy;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) denoised.rgba[i * 4 + size_t(c)] = rgb[i * 3 + size_t(c)];
  const Film& main = options.noisy_main ? noisy : denoised;
  const Film& second = options.noisy_main ? denoised : noisy;
  const auto extra = second_channels(options.noisy_main ? "denoised" : "noisy", refs);

  // The main beauty into the first part's R, G, B.
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const ChannelRef& r = refs.at(rgba[c]);
      store_value(&pixels[0][i * stride0 + r.offset], r.type, main.rgba[i * 4 + size_t(c)]);
    }
  // The second beauty: four more channels of a single-part file, a part of its own otherwise.
  size_t extra_bytes = 0;
  for (const auto& e : extra) extra_bytes += e.second.size();
  const auto pack_second = [&](std::vector<unsigned char>& dst, size_t stride, size_t offset) {
    for (size_t i = 0; i < n; ++i) {
      size_t o = offset;
      for (int c = 0; c < 4; ++c) {
        store_value(&dst[i * stride + o], extra[size_t(c)].second, second.rgba[i * 4 + size_t(c)]);
        o += extra[size_t(c)].second.size();
      }
    }
  };
  if (specs.size() == 1) {
    OIIO::ImageSpec& sp = specs[0];
    std::vector<OIIO::TypeDesc> formats;
    for (int c = 0; c < sp.nchannels; ++c) formats.push_back(sp.channelformat(c));
    for (const auto& e : extra) {
      sp.channelnames.push_back(e.first);
      formats.push_back(e.second);
    }
    sp.nchannels += 4;
    sp.channelformats = formats;
    const size_t stride = stride0 + extra_bytes;
    std::vector<unsigned char> widened(n * stride);
    for (size_t i = 0; i < n; ++i) std::memcpy(&widened[i * stride], &pixels[0][i * stride0], stride0);
    pack_second(widened, stride, stride0);
    pixels[0] = std::move(widened);
  } else {
    OIIO::ImageSpec sp = specs[0];
    sp.nchannels = 4;
    sp.channelnames.clear();
    sp.channelformats.clear();
    for (const auto& e : extra) {
      sp.channelnames.push_back(e.first);
      sp.channelformats.push_back(e.second);
    }
    sp.alpha_channel = -1;
    const char* part_name = options.noisy_main ? "denoised" : "noisy";
    sp.attribute("name", part_name);
    sp.attribute("oiio:subimagename", part_name);
    std::vector<unsigned char> part(n * extra_bytes);
    pack_second(part, extra_bytes, 0);
    specs.push_back(sp);
    pixels.push_back(std::move(part));
  }
  for (auto& sp : specs) {
    sp.attribute(kDenoiserAttribute, "nfor");
    sp.attribute(kDenoiseMainAttribute, options.noisy_main ? "noisy" : "denoised");
    // The input's capture date; OpenImageIO reads an empty one as none and would stamp the
    // time of writing.
    if (!sp.find_attribute("DateTime")) sp.attribute("DateTime", "");
  }
  exr_parts::move_crypto_sidecars(in_path, named_as, specs);
  exr_parts::write_frame(write_to, specs, pixels, false, sha256);
  return main;
}

}  // namespace

uint64_t exr_denoise_bytes(int width, int height, const DenoiseConfig& config) {
  const uint64_t n = uint64_t(std::max(0, width)) * uint64_t(std::max(0, height));
  // Two films (noisy, denoised), the halves as floats, the denoised colour.
  return n * (2 * 4 * 4 + 4 * (2 * kDenoiseChannelsPerHalf + 3)) + denoise_bytes(width, height, config);
}

Film denoise_exr(const std::filesystem::path& in, const std::filesystem::path& out,
                 const ExrDenoiseOptions& options, std::string* sha256) {
  return denoise_file(in, in.string(), out, out, options, sha256);
}

Film denoise_through_file(const std::filesystem::path& out,
                          const std::function<void(const std::filesystem::path&)>& write_noisy,
                          const ExrDenoiseOptions& options, std::string* sha256) {
  // The noisy frame is the atomic write's own temporary (removed on failure and by the signal
  // handlers), denoised in place: the file is read whole before it is written.
  Film main;
  write_atomically(
      out,
      [&](const std::filesystem::path& temp) {
        write_noisy(temp);
        main = denoise_file(temp, out.string() + " (noisy frame)", temp, out, options, nullptr);
      },
      sha256);
  return main;
}

}  // namespace penumbra
