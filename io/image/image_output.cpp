// EXR and display-image writers.
#include "io/image/image_output.h"

#include <OpenColorIO/OpenColorIO.h>
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/half.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "io/files/atomic_file.h"
#include "io/files/checked_file.h"
#include "io/files/error.h"
#include "io/files/file_checks.h"
#include "io/image/exr_parts.h"

namespace OCIO = OCIO_NAMESPACE;

namespace penumbra {

namespace {

/// A crop or tile: the film is the data window inside the full display window.
void set_frame_window(OIIO::ImageSpec& spec, const Film& film) {
  spec.x = film.origin_x;
  spec.y = film.origin_y;
  spec.full_x = 0;
  spec.full_y = 0;
  spec.full_width = film.full_width > 0 ? film.full_width : film.width;
  spec.full_height = film.full_height > 0 ? film.full_height : film.height;
}

void write_with_oiio(const std::filesystem::path& final_path, const std::filesystem::path& temp,
                     const OIIO::ImageSpec& spec, const void* pixels, OIIO::TypeDesc pixel_type) {
  auto out = OIIO::ImageOutput::create(final_path.string());
  if (!out)
    throw std::runtime_error(final_path.string() + ": no image writer for this extension (" +
                             OIIO::geterror() + ")");
  write_through_checked_file(out, temp, final_path, [&] {
    if (!out->open(temp.string(), spec))
      throw std::runtime_error(final_path.string() + ": cannot open for writing: " + out->geterror());
    if (!out->write_image(pixel_type, pixels))
      throw std::runtime_error(final_path.string() + ": write failed: " + out->geterror());
    if (!out->close()) throw std::runtime_error(final_path.string() + ": close failed: " + out->geterror());
  });
}

/// The spec of `film` as one EXR part: R, G, B, A in half or float, then options.extra, each in
/// its own format; the frame window and the attributes. Throws std::invalid_argument naming
/// `path` if an extra channel does not match the image size.
OIIO::ImageSpec exr_spec(const Film& film, const std::filesystem::path& path, const ExrOptions& options) {
  const int nc = 4 + int(options.extra.size());
  const OIIO::TypeDesc colour = options.half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT;
  OIIO::ImageSpec spec(film.width, film.height, nc, colour);
  spec.channelnames = {"R", "G", "B", "A"};
  const size_t pixels = size_t(film.width) * size_t(film.height);
  for (const auto& c : options.extra) {
    if (!c.data || c.stride < 1 || c.offset < 0 || c.offset >= c.stride ||
        c.data->size() != pixels * size_t(c.stride))
      throw std::invalid_argument(path.string() + ": channel " + c.name + " does not match the image size");
    spec.channelnames.push_back(c.name);
  }
  if (!options.extra.empty()) {
    spec.channelformats.assign(size_t(nc), colour);
    for (size_t i = 0; i < options.extra.size(); ++i) {
      const ChannelType t = options.extra[i].type;
      spec.channelformats[4 + i] = t == ChannelType::Half   ? OIIO::TypeDesc::HALF
                                   : t == ChannelType::Uint ? OIIO::TypeDesc::UINT
                                                            : OIIO::TypeDesc::FLOAT;
    }
  }
  spec.alpha_channel = 3;
  set_frame_window(spec, film);
  spec.attribute("compression", options.compression);
  exr_parts::set_attributes(spec, options);
  return spec;
}

/// Every channel of a spec interleaved per pixel, each in its channel's file format.
struct PackedPixels {
  std::vector<unsigned char> bytes;
  std::vector<size_t> offsets;  ///< per channel: its first byte within a pixel
  size_t stride = 0;            ///< bytes per pixel
};

/// Stores `v` at `dst` as `type`: half, float, or a raw uint32 (OIIO's float -> uint conversion
/// would normalise integer ids): non-finite and non-positive values 0, truncated, clamped.
void put_channel_value(unsigned char* dst, OIIO::TypeDesc type, float v) {
  if (type == OIIO::TypeDesc::HALF) {
    const half h(v);
    std::memcpy(dst, &h, sizeof h);
  } else if (type == OIIO::TypeDesc::UINT) {
    const uint32_t u = std::isfinite(v) && v > 0 ? uint32_t(std::min(v, 4294967295.0f)) : 0u;
    std::memcpy(dst, &u, sizeof u);
  } else {
    std::memcpy(dst, &v, sizeof v);
  }
}

/// The film's R, G, B, A and options.extra packed in the formats of `spec` (from exr_spec()).
PackedPixels pack_channels(const Film& film, const ExrOptions& options, const OIIO::ImageSpec& spec) {
  const size_t nc = size_t(spec.nchannels);
  const size_t pixels = size_t(film.width) * size_t(film.height);
  PackedPixels p;
  p.offsets.resize(nc);
  for (size_t k = 0; k < nc; ++k) {
    p.offsets[k] = p.stride;
    p.stride += spec.channelformat(int(k)).size();
  }
  p.bytes.resize(pixels * p.stride);
  for (size_t i = 0; i < pixels; ++i) {
    unsigned char* px = &p.bytes[i * p.stride];
    for (size_t k = 0; k < 4; ++k)
      put_channel_value(px + p.offsets[k], spec.channelformat(int(k)), film.rgba[i * 4 + k]);
    for (size_t k = 0; k < options.extra.size(); ++k) {
      const ExrChannel& c = options.extra[k];
      put_channel_value(px + p.offsets[4 + k], spec.channelformat(int(4 + k)),
                        (*c.data)[i * size_t(c.stride) + size_t(c.offset)]);
    }
  }
  return p;
}

/// The parts of a multi-part EXR: each one's name, spec and interleaved pixels.
struct ExrParts {
  std::vector<std::string> names;
  std::vector<OIIO::ImageSpec> specs;
  std::vector<std::vector<unsigned char>> pixels;
};

/// The parts' names and channels (indices into the spec of exr_spec()): "rgba" with R, G, B, A,
/// then one part per layer of options.extra (the channel name's prefix before '.', or a lone
/// channel such as Z), in first-appearance order.
void group_layers(const ExrOptions& options, std::vector<std::string>& names,
                  std::vector<std::vector<size_t>>& members) {
  names = {"rgba"};
  members = {{0, 1, 2, 3}};
  for (size_t k = 0; k < options.extra.size(); ++k) {
    const std::string& name = options.extra[k].name;
    const std::string key = name.substr(0, name.find('.'));
    auto it = std::find(names.begin(), names.end(), key);
    if (it == names.end()) {
      names.push_back(key);
      members.emplace_back();
      it = names.end() - 1;
    }
    members[size_t(it - names.begin())].push_back(4 + k);
  }
}

/// `spec` and `packed` (pixels x its channels) split into the parts of group_layers(). Each part
/// keeps the attributes; the first holds the alpha channel; lossy codecs apply only to parts
/// with a half channel (colour), data parts (float N, P, Z, ids) are written with zip.
ExrParts split_parts(const ExrOptions& options, const OIIO::ImageSpec& spec, const PackedPixels& packed,
                     size_t pixels) {
  ExrParts parts;
  std::vector<std::vector<size_t>> members;
  group_layers(options, parts.names, members);
  const std::string& c = options.compression;
  const bool lossy = c == "dwaa" || c == "dwab" || c == "b44" || c == "b44a" || c == "pxr24";
  for (size_t part = 0; part < parts.names.size(); ++part) {
    OIIO::ImageSpec ps = spec;
    ps.nchannels = int(members[part].size());
    ps.channelnames.clear();
    ps.channelformats.clear();
    bool colour_part = part == 0;
    size_t part_stride = 0;
    for (size_t ch : members[part]) {
      ps.channelnames.push_back(spec.channelnames[ch]);
      ps.channelformats.push_back(spec.channelformat(int(ch)));
      colour_part |= spec.channelformat(int(ch)) == OIIO::TypeDesc::HALF;
      part_stride += spec.channelformat(int(ch)).size();
    }
    ps.alpha_channel = part == 0 ? 3 : -1;
    ps.attribute("name", parts.names[part]);
    if (lossy && !colour_part) ps.attribute("compression", "zip");
    std::vector<unsigned char> buf(pixels * part_stride);
    for (size_t i = 0; i < pixels; ++i) {
      size_t o = 0;
      for (size_t ch : members[part]) {
        const size_t n = spec.channelformat(int(ch)).size();
        std::memcpy(&buf[i * part_stride + o], &packed.bytes[i * packed.stride + packed.offsets[ch]], n);
        o += n;
      }
    }
    parts.specs.push_back(ps);
    parts.pixels.push_back(std::move(buf));
  }
  return parts;
}

/// Writes `pixels` (of `pixel_type`, or each channel in its own format for UNKNOWN) as a
/// single-part image with `spec` at `path`, atomically.
void write_single_part(const std::filesystem::path& path, const OIIO::ImageSpec& spec, const void* pixels,
                       OIIO::TypeDesc pixel_type, std::string* sha256) {
  write_atomically(
      path, [&](const std::filesystem::path& temp) { write_with_oiio(path, temp, spec, pixels, pixel_type); },
      sha256);
}

/// Writes `parts` as one multi-part EXR at `path` (atomically, as write_exr() does).
void write_multipart(const std::filesystem::path& path, const ExrParts& parts, std::string* sha256) {
  write_atomically(
      path,
      [&](const std::filesystem::path& temp) {
        auto out = OIIO::ImageOutput::create(path.string());
        if (!out || !out->supports("multiimage"))
          throw std::runtime_error(path.string() + ": no multi-part image writer for this extension");
        write_through_checked_file(out, temp, path, [&] {
          if (!out->open(temp.string(), int(parts.specs.size()), parts.specs.data()))
            throw std::runtime_error(path.string() + ": cannot open for writing: " + out->geterror());
          for (size_t part = 0; part < parts.specs.size(); ++part) {
            if (part > 0 && !out->open(temp.string(), parts.specs[part], OIIO::ImageOutput::AppendSubimage))
              throw std::runtime_error(path.string() + ": cannot start part " + parts.names[part] + ": " +
                                       out->geterror());
            if (!out->write_image(OIIO::TypeDesc::UNKNOWN, parts.pixels[part].data()))
              throw std::runtime_error(path.string() + ": write failed: " + out->geterror());
          }
          if (!out->close()) throw std::runtime_error(path.string() + ": close failed: " + out->geterror());
        });
      },
      sha256);
}

}  // namespace

void exr_parts::set_attributes(OIIO::ImageSpec& spec, const ExrOptions& options) {
  spec.attribute("oiio:ColorSpace", "lin_rec709");
  spec.attribute("Software", "Penumbra " PENUMBRA_VERSION);
  for (const auto& [k, v] : options.metadata) spec.attribute(k, v);
  for (const auto& [k, v] : options.float_metadata) spec.attribute(k, v);
  for (const auto& [k, m] : options.matrix_metadata)
    spec.attribute(k, OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, OIIO::TypeDesc::MATRIX44), m.data());
}

void write_exr(const Film& film, const std::filesystem::path& path, const ExrOptions& options,
               std::string* sha256) {
  const OIIO::ImageSpec spec = exr_spec(film, path, options);
  if (options.extra.empty()) {
    write_single_part(path, spec, film.rgba.data(), OIIO::TypeDesc::FLOAT, sha256);
    return;
  }
  // Pixels in each channel's own file format: half, float or uint per channel, interleaved.
  const PackedPixels packed = pack_channels(film, options, spec);
  if (!options.multipart) {
    write_single_part(path, spec, packed.bytes.data(), OIIO::TypeDesc::UNKNOWN, sha256);
    return;
  }
  write_multipart(path, split_parts(options, spec, packed, size_t(film.width) * size_t(film.height)), sha256);
}

namespace {

/// 5 x 7 pixel glyphs (rows top to bottom, bit 4 = leftmost column) for the heat-map legend.
struct Glyph {
  char c;
  uint8_t rows[7];
};
constexpr Glyph kFont[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'A', {0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11}}, {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
    {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}}, {'D', {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C}},
    {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}}, {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
    {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}}, {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
    {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}}, {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
    {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}}, {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
    {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}}, {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
    {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
    {'Q', {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}}, {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
    {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}}, {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}},
    {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}}, {'X', {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}},
    {'Y', {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04}}, {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}},
    {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}}, {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}}, {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}}, {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}},
};

/// An 8-bit RGB canvas for the legend.
struct Canvas {
  int w, h;
  std::vector<uint8_t> rgb;
  void set(int x, int y, const uint8_t c[3]) {
    if (x < 0 || y < 0 || x >= w || y >= h) return;
    std::copy(c, c + 3, &rgb[(size_t(y) * size_t(w) + size_t(x)) * 3]);
  }
  /// Draws `text` (upper-cased; unknown characters as spaces) at scale `s`; returns its width.
  int text(int x, int y, const std::string& t, int s, const uint8_t c[3], bool draw = true) {
    int cx = x;
    for (char ch : t) {
      const char u = char(std::toupper(static_cast<unsigned char>(ch)));
      for (const Glyph& g : kFont) {
        if (g.c != u || !draw) continue;
        for (int r = 0; r < 7; ++r)
          for (int col = 0; col < 5; ++col)
            if (g.rows[r] & (0x10 >> col))
              for (int dy = 0; dy < s; ++dy)
                for (int dx = 0; dx < s; ++dx) set(cx + col * s + dx, y + r * s + dy, c);
      }
      cx += 6 * s;
    }
    return cx - x;
  }
};

/// The viridis colour map (van der Walt & Smith, matplotlib 2015), five sRGB stops.
void viridis(float t, uint8_t out[3]) {
  static const float stops[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  t = std::clamp(std::isfinite(t) ? t : 0.0f, 0.0f, 1.0f) * 4;
  const int i = std::min(int(t), 3);
  const float f = t - float(i);
  for (int k = 0; k < 3; ++k)
    out[k] = uint8_t(std::lround(stops[i][k] + (stops[i + 1][k] - stops[i][k]) * f));
}

std::string legend_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, v >= 100 || v == std::floor(v) ? "%.0f" : "%.1f", v);
  return buf;
}

}  // namespace

void write_heatmap(const std::vector<float>& values, int width, int height, const std::filesystem::path& path,
                   const std::string& title, std::string* sha256) {
  if (values.size() != size_t(width) * size_t(height))
    throw std::invalid_argument(path.string() + ": heat map values do not match the image size");
  float vmax = 0;
  for (float v : values)
    if (std::isfinite(v)) vmax = std::max(vmax, v);
  const float scale = vmax > 0 ? 1.0f / vmax : 0.0f;
  const int s = width >= 480 ? 2 : 1;  // font scale
  const int legend = 7 * s * 2 + 12 * s + 14;
  Canvas c{width, height + legend, std::vector<uint8_t>(size_t(width) * size_t(height + legend) * 3, 255)};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      uint8_t col[3];
      viridis(values[size_t(y) * size_t(width) + size_t(x)] * scale, col);
      c.set(x, y, col);
    }
  const uint8_t black[3] = {0, 0, 0};
  const int margin = 4 * s, y_title = height + 3, y_bar = y_title + 7 * s + 3, bar_h = 8 * s;
  const int ts =
      c.text(0, 0, title, s, black, false) <= width - 2 * margin ? s : 1;  // a long title: small font
  c.text(margin, y_title + (s - ts) * 7, title, ts, black);
  const int x0 = margin, x1 = std::max(x0 + 1, width - margin);
  for (int x = x0; x < x1; ++x) {
    uint8_t col[3];
    viridis(float(x - x0) / float(std::max(1, x1 - x0 - 1)), col);
    for (int y = y_bar; y < y_bar + bar_h; ++y) c.set(x, y, col);
  }
  // Ticks at 0, 1/4, 1/2, 3/4 and the maximum, fewer on narrow images so labels never overlap.
  const int label_w = c.text(0, 0, legend_number(double(vmax)), s, black, false) + 6 * s;
  int intervals = std::clamp((x1 - x0) / std::max(1, 2 * label_w), 1, 4);
  if (intervals == 3) intervals = 2;  // keep ticks at round fractions
  for (int q = 0; q <= intervals; ++q) {
    const int x = x0 + (x1 - 1 - x0) * q / intervals;
    for (int y = y_bar + bar_h; y < y_bar + bar_h + 3; ++y) c.set(x, y, black);
    const std::string label = legend_number(double(vmax) * q / intervals);
    const int w = c.text(0, 0, label, s, black, false);
    const int lx = std::clamp(x - w / 2, 0, std::max(0, width - w));
    c.text(lx, y_bar + bar_h + 4, label, s, black);
  }
  OIIO::ImageSpec spec(width, height + legend, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  spec.attribute("Software", "Penumbra " PENUMBRA_VERSION);
  write_atomically(
      path,
      [&](const std::filesystem::path& temp) {
        write_with_oiio(path, temp, spec, c.rgb.data(), OIIO::TypeDesc::UINT8);
      },
      sha256);
}

namespace {

constexpr uint64_t kMaxOcioConfigBytes = 64ull << 20;

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

bool contains_srgb(std::string name) {
  for (auto& ch : name) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  return name.find("srgb") != std::string::npos;
}

/// The one place that turns DisplayOptions into a CPU processor (config, display, view); fills
/// `described` (if not null) with what was resolved.
OCIO::ConstCPUProcessorRcPtr display_processor(const DisplayOptions& options,
                                               DisplayDescription* described = nullptr) {
  const char* env = std::getenv("OCIO");
  const std::string source = !options.ocio_config.empty() ? options.ocio_config
                             : (env && *env)              ? std::string(env)
                                                          : std::string("<shipped config>");
  // A config is a small text file; a FIFO or device named here must not block the run.
  if (!options.ocio_config.empty())
    check_input_file(options.ocio_config, "--ocio-config", kMaxOcioConfigBytes);
  else if (env && *env)
    check_input_file(env, "$OCIO", kMaxOcioConfigBytes);
  OCIO::ConstConfigRcPtr config;
  try {
    if (!options.ocio_config.empty()) {
      config = OCIO::Config::CreateFromFile(options.ocio_config.c_str());
    } else if (env && *env) {
      config = OCIO::Config::CreateFromEnv();
    } else {
      std::istringstream in(shipped_ocio_config());
      config = OCIO::Config::CreateFromStream(in);
    }
  } catch (const OCIO::Exception& e) {
    throw InputError(source, "OpenColorIO config", e.what());
  }
  const std::string display = options.display.empty() ? config->getDefaultDisplay() : options.display;
  std::string displays;
  bool display_found = false;
  for (int i = 0; i < config->getNumDisplays(); ++i) {
    displays += std::string(displays.empty() ? "" : ", ") + config->getDisplay(i);
    display_found |= display == config->getDisplay(i);
  }
  if (!display_found)
    throw InputError(source, "--display", "no display '" + display + "' (available: " + displays + ")");
  const std::string view = options.view.empty() ? config->getDefaultView(display.c_str()) : options.view;
  std::string views;
  bool view_found = false;
  for (int i = 0; i < config->getNumViews(display.c_str()); ++i) {
    views += std::string(views.empty() ? "" : ", ") + config->getView(display.c_str(), i);
    view_found |= view == config->getView(display.c_str(), i);
  }
  if (!view_found)
    throw InputError(source, "--view",
                     "display '" + display + "' has no view '" + view + "' (available: " + views + ")");
  if (!options.look.empty() && !config->getLook(options.look.c_str())) {
    std::string looks;
    for (int i = 0; i < config->getNumLooks(); ++i)
      looks += std::string(looks.empty() ? "" : ", ") + config->getLookNameByIndex(i);
    throw InputError(source, "--look",
                     "no look '" + options.look + "' (available: " + (looks.empty() ? "none" : looks) + ")");
  }
  if (described) {
    DisplayDescription& d = *described;
    d.source = !options.ocio_config.empty() ? options.ocio_config
               : (env && *env)              ? "$OCIO=" + std::string(env)
                                            : std::string("<shipped config>");
    const char* name = config->getName();
    d.config = name && *name                  ? name
               : !options.ocio_config.empty() ? options.ocio_config
               : (env && *env)                ? std::string(env)
                                              : std::string("penumbra-default");
    d.display = display;
    d.view = view;
    d.look = options.look;
    d.exposure = options.exposure;
    const char* cs_name = config->getDisplayViewColorSpaceName(display.c_str(), view.c_str());
    d.colorspace = cs_name ? cs_name : "";
    const auto cs = config->getColorSpace(d.colorspace.c_str());
    const bool data = cs && cs->isData();
    d.srgb = !data && (contains_srgb(d.colorspace) || contains_srgb(display));
  }
  try {
    if (options.look.empty())
      return config
          ->getProcessor(OCIO::ROLE_SCENE_LINEAR, display.c_str(), view.c_str(), OCIO::TRANSFORM_DIR_FORWARD)
          ->getDefaultCPUProcessor();
    // The look in scene-linear, then the display/view transform.
    auto look = OCIO::LookTransform::Create();
    look->setSrc(OCIO::ROLE_SCENE_LINEAR);
    look->setDst(OCIO::ROLE_SCENE_LINEAR);
    look->setLooks(options.look.c_str());
    auto dv = OCIO::DisplayViewTransform::Create();
    dv->setSrc(OCIO::ROLE_SCENE_LINEAR);
    dv->setDisplay(display.c_str());
    dv->setView(view.c_str());
    auto group = OCIO::GroupTransform::Create();
    group->appendTransform(look);
    group->appendTransform(dv);
    return config->getProcessor(group)->getDefaultCPUProcessor();
  } catch (const OCIO::Exception& e) {
    throw InputError(source, "OpenColorIO", e.what());
  }
}

}  // namespace

void check_display_output(const std::filesystem::path& path, const DisplayOptions& options) {
  const std::string ext = lower_extension(path);
  if (ext != ".png" && ext != ".jpg" && ext != ".jpeg" && ext != ".tif" && ext != ".tiff")
    throw InputError(path.string(), "",
                     "unsupported display image format '" + ext + "' (use .png, .jpg, .jpeg, .tif or .tiff)");
  if (options.alpha && (ext == ".jpg" || ext == ".jpeg"))
    throw InputError(path.string(), "",
                     "JPEG has no alpha channel: --png-alpha needs a .png or .tif display image");
  display_processor(options);
}

DisplayDescription describe_display(const DisplayOptions& options) {
  DisplayDescription d;
  display_processor(options, &d);
  return d;
}

std::vector<std::pair<std::string, std::string>> display_metadata(const DisplayDescription& d) {
  char exposure[32];
  std::snprintf(exposure, sizeof exposure, "%g", double(d.exposure));
  return {{"penumbra:ocio_config", d.config},
          {"penumbra:ocio_display", d.display},
          {"penumbra:ocio_view", d.view},
          {"penumbra:ocio_look", d.look.empty() ? "none" : d.look},
          {"penumbra:ocio_colorspace", d.colorspace},
          {"penumbra:exposure", exposure}};
}

void apply_display_transform(std::vector<float>& rgb, int width, int height, const DisplayOptions& options) {
  const auto cpu = display_processor(options);
  OCIO::PackedImageDesc desc(rgb.data(), width, height, 3);
  cpu->apply(desc);
}

void write_display_image(const Film& film, const std::filesystem::path& path, const DisplayOptions& options,
                         std::string* sha256) {
  const size_t n = size_t(film.width) * size_t(film.height);
  std::vector<float> rgb(n * 3);
  const float gain = std::exp2(options.exposure);
  for (size_t i = 0; i < n; ++i) {
    const float a = options.half_beauty ? float(half(film.rgba[i * 4 + 3])) : film.rgba[i * 4 + 3];
    // With alpha the view applies to the straight colour; over black, to the premultiplied one.
    const float unpremultiply = options.alpha ? (a > 0 ? 1 / a : 0.0f) : 1.0f;
    for (int c = 0; c < 3; ++c) {
      const float v = film.rgba[i * 4 + size_t(c)];
      rgb[i * 3 + size_t(c)] = (options.half_beauty ? float(half(v)) : v) * gain * unpremultiply;
    }
  }
  DisplayDescription described;
  const auto cpu = display_processor(options, &described);
  OCIO::PackedImageDesc desc(rgb.data(), film.width, film.height, 3);
  cpu->apply(desc);
  const std::string ext = lower_extension(path);
  const bool sixteen = ext == ".tif" || ext == ".tiff";
  const int channels = options.alpha ? 4 : 3;
  OIIO::ImageSpec spec(film.width, film.height, channels,
                       sixteen ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8);
  if (options.alpha) spec.alpha_channel = 3;
  set_frame_window(spec, film);  // PNG oFFs, TIFF XPosition / YPosition
  if (described.srgb) spec.attribute("oiio:ColorSpace", "sRGB");
  spec.attribute("Software", "Penumbra " PENUMBRA_VERSION);
  for (const auto& [k, v] : display_metadata(described)) spec.attribute(k, v);
  std::vector<float> pixels(n * size_t(channels));
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < channels; ++c) {
      const float alpha = options.half_beauty ? float(half(film.rgba[i * 4 + 3])) : film.rgba[i * 4 + 3];
      const float v = c < 3 ? rgb[i * 3 + size_t(c)] : alpha;
      pixels[i * size_t(channels) + size_t(c)] = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    }
  write_atomically(
      path,
      [&](const std::filesystem::path& temp) {
        write_with_oiio(path, temp, spec, pixels.data(), OIIO::TypeDesc::FLOAT);
      },
      sha256);
}

Film read_exr_beauty(const std::filesystem::path& path, uint64_t max_bytes) {
  const std::string name = path.string();
  check_input_file(path, "", uint64_t(16) << 30);
  auto in = OIIO::ImageInput::open(name);
  if (!in) throw InputError(name, "", "cannot be read as an image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  int channel[4];
  for (int c = 0; c < 4; ++c) {
    channel[c] = spec.channelindex(std::string(1, "RGBA"[c]));
    if (channel[c] < 0) throw InputError(name, "", std::string("has no channel ") + "RGBA"[c]);
  }
  const uint64_t pixels = uint64_t(spec.full_width) * uint64_t(spec.full_height);
  const uint64_t floats = pixels * (4 + uint64_t(std::max(spec.nchannels, 0)));  // the film and the read
  if (spec.full_width <= 0 || spec.full_height <= 0 || spec.width > spec.full_width ||
      spec.height > spec.full_height || floats * sizeof(float) > max_bytes)
    throw InputError(name, "",
                     "its " + std::to_string(spec.full_width) + "x" + std::to_string(spec.full_height) +
                         " pixels exceed the " + format_bytes(max_bytes) + " budget");
  std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw InputError(name, "", "cannot decode: " + in->geterror());
  Film film = make_film(spec.full_width, spec.full_height);
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) {
      const int fx = spec.x + x, fy = spec.y + y;
      if (fx < 0 || fy < 0 || fx >= film.width || fy >= film.height) continue;
      const float* src = &all[(size_t(y) * size_t(spec.width) + size_t(x)) * size_t(spec.nchannels)];
      for (int c = 0; c < 4; ++c) film.pixel(fx, fy)[c] = src[channel[c]];
    }
  return film;
}

}  // namespace penumbra
