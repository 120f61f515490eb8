// Merging crops and tiles into one EXR (single- or multi-part): every part is checked as a file,
// then for its Penumbra identity, then for its windows and channels, before its pixels are
// copied into the frame.
#include "io/image/exr_merge.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>

#include "io/farm/render_settings.h"
#include "io/files/atomic_file.h"
#include "io/files/checked_file.h"
#include "io/files/error.h"
#include "io/files/file_checks.h"
#include "io/image/exr_denoise.h"
#include "io/image/exr_parts.h"

namespace penumbra {

namespace {
constexpr const char* kForceHint = "use --force to merge parts from other tools";
}  // namespace

namespace exr_parts {

namespace {
constexpr int64_t kMaxSide = 65536;
}  // namespace

// Bytes of one EXR part's pixels: its data window, or its display window when `full`.
double image_bytes(const OIIO::ImageSpec& spec, bool full) {
  const double pixels =
      full ? double(spec.full_width) * double(spec.full_height) : double(spec.width) * double(spec.height);
  return pixels * double(spec.pixel_bytes(true));
}

// Reads a NUL-terminated name of at most 255 bytes; false at end of file or if longer.
bool read_name(std::istream& in, std::string& name) {
  name.clear();
  for (char c; in.get(c);) {
    if (c == '\0') return true;
    if (name.size() == 255) return false;
    name += c;
  }
  return false;
}

// Size in bytes of the OpenEXR attribute types whose values have a fixed size (OpenEXR's reader
// reads that many bytes whatever the size field says), or 0 for other types.
int fixed_attribute_size(const std::string& type) {
  // clang-format off
  static const std::pair<const char*, int> sizes[] = {
      {"box2i", 16}, {"box2f", 16}, {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1},
      {"double", 8}, {"envmap", 1}, {"float", 4}, {"int", 4}, {"keycode", 28}, {"lineOrder", 1},
      {"m33d", 72}, {"m33f", 36}, {"m44d", 128}, {"m44f", 64}, {"rational", 8}, {"tiledesc", 9},
      {"timecode", 8}, {"v2d", 16}, {"v2f", 8}, {"v2i", 8}, {"v3d", 24}, {"v3f", 12}, {"v3i", 12}};
  // clang-format on
  for (const auto& [name, size] : sizes)
    if (type == name) return size;
  return 0;
}

int32_t int32_at(const std::string& bytes, size_t at) {
  int32_t v = 0;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;
}

// Why the value of an attribute of variable size that OpenEXR's reader parses further (channel
// lists, previews, string vectors) does not describe exactly its `value.size()` bytes, or "".
std::string variable_attribute_problem(const std::string& type, const std::string& value) {
  if (type == "chlist") {  // entries of name, NUL, pixel type, linear, 3 reserved, x and y sampling; a NUL
    size_t at = 0;
    while (at < value.size() && value[at] != '\0') {
      const size_t end = value.find('\0', at);
      if (end == std::string::npos || end - at > 255 || end + 17 > value.size())
        return "a channel is cut off";
      const std::string channel = "channel '" + value.substr(at, end - at) + "'";
      const int32_t pixel_type = int32_at(value, end + 1);
      if (pixel_type < 0 || pixel_type > 2)
        return channel + " has unknown pixel type " + std::to_string(pixel_type);
      if (int32_at(value, end + 9) != 1 || int32_at(value, end + 13) != 1)
        return channel + " is subsampled, which merge does not support";
      at = end + 17;
    }
    return at + 1 == value.size() ? "" : "the channel list does not fill its size";
  }
  if (type == "preview") {  // width, height, then 4 bytes per pixel
    if (value.size() < 8) return "a preview is cut off";
    const uint64_t w = uint32_t(int32_at(value, 0)), h = uint32_t(int32_at(value, 4));
    return w <= kMaxSide && h <= kMaxSide && 8 + 4 * w * h == value.size() ? ""
                                                                           : "the preview's size is wrong";
  }
  if (type == "stringvector") {  // (length, bytes) pairs
    for (size_t at = 0; at < value.size();) {
      if (at + 4 > value.size()) return "a string is cut off";
      const int32_t n = int32_at(value, at);
      if (n < 0 || uint64_t(n) > value.size() - at - 4) return "a string is cut off";
      at += 4 + size_t(n);
    }
  }
  return "";
}

// Walks the OpenEXR header(s) of `path` (`size` bytes) before OpenImageIO opens it, so a few
// hostile bytes cannot make the EXR reader allocate what the file does not hold: every
// attribute must fit in the rest of the file with the size its type has, channel lists,
// previews and string vectors must describe their own bytes, and every data and display window
// must be at most kMaxSide pixels per side. Throws InputError naming the file otherwise.
ExrHeaderInfo check_exr_header(const std::filesystem::path& path, uint64_t size, bool deep) {
  ExrHeaderInfo info;
  const std::string name = path.string();
  std::ifstream in(path, std::ios::binary);
  unsigned char start[8] = {};
  if (!in.read(reinterpret_cast<char*>(start), sizeof start) || start[0] != 0x76 || start[1] != 0x2f ||
      start[2] != 0x31 || start[3] != 0x01)
    throw InputError(name, "", "is not an OpenEXR file");
  const uint32_t flags = uint32_t(start[5]) << 8 | uint32_t(start[6]) << 16 | uint32_t(start[7]) << 24;
  const bool multipart = flags & 0x1000;
  info.multipart = multipart;
  if ((flags & 0x800) && !deep) throw InputError(name, "", "is a deep image, the first part is not");
  if (!(flags & 0x800) && deep) throw InputError(name, "", "is not a deep image, the first part is");
  const auto bad = [&](const std::string& what) {
    return InputError(name, "", "invalid OpenEXR header: " + what);
  };
  for (int header = 0;; ++header) {
    std::string attribute, type;
    int attributes = 0;
    for (;; ++attributes) {
      if (!read_name(in, attribute)) throw bad("cut off, or an attribute name over 255 bytes");
      if (attribute.empty()) break;
      int32_t bytes = 0;
      if (!read_name(in, type) || !in.read(reinterpret_cast<char*>(&bytes), 4))
        throw bad("attribute '" + attribute + "' is cut off");
      const uint64_t left = size - uint64_t(in.tellg());
      if (bytes < 0 || uint64_t(bytes) > left)
        throw bad("attribute '" + attribute + "' claims " + std::to_string(bytes) + " bytes, " +
                  std::to_string(left) + " are left");
      const int fixed = fixed_attribute_size(type);
      if (fixed > 0 && bytes != fixed)
        throw bad("attribute '" + attribute + "' of type " + type + " has " + std::to_string(bytes) +
                  " bytes, not " + std::to_string(fixed));
      if (header == 0 && type == "int" && attribute == "chunkCount" && bytes == 4) {
        int32_t count = 0;
        in.read(reinterpret_cast<char*>(&count), 4);
        info.chunk_count = count;
      } else if (type == "box2i" && (attribute == "dataWindow" || attribute == "displayWindow")) {
        int32_t box[4];
        in.read(reinterpret_cast<char*>(box), sizeof box);
        const int64_t w = int64_t(box[2]) - box[0] + 1, h = int64_t(box[3]) - box[1] + 1;
        if (w < 1 || h < 1 || w > kMaxSide || h > kMaxSide)
          throw bad(attribute + " of " + std::to_string(w) + "x" + std::to_string(h) + " pixels");
      } else if (type == "chlist" || type == "preview" || type == "stringvector") {
        std::string value(size_t(bytes), '\0');
        in.read(value.data(), bytes);
        const std::string problem = variable_attribute_problem(type, value);
        if (!problem.empty()) throw bad("attribute '" + attribute + "': " + problem);
      } else {
        in.seekg(bytes, std::ios::cur);
      }
    }
    if (!in) throw bad("cut off");
    if (!multipart || attributes == 0) {
      if (header == 0 && attributes == 0) throw bad("no attributes");
      info.end = uint64_t(in.tellg());
      return info;
    }
  }
}

std::unique_ptr<OIIO::ImageInput> open_part(const std::string& name) {
  auto in = OIIO::ImageInput::create("openexr");
  if (!in) throw std::runtime_error("OpenImageIO has no OpenEXR reader: " + OIIO::geterror());
  OIIO::ImageSpec spec;
  if (!in->open(name, spec)) throw InputError(name, "", "cannot read as OpenEXR: " + in->geterror());
  return in;
}

// The specs of every EXR part in `in`, checked to share one non-empty data window inside one
// display window at the origin.
std::vector<OIIO::ImageSpec> read_specs(OIIO::ImageInput& in, const std::string& name) {
  std::vector<OIIO::ImageSpec> specs;
  for (int sub = 0; in.seek_subimage(sub, 0); ++sub) specs.push_back(in.spec());
  if (specs.empty()) throw InputError(name, "", "has no image");
  const OIIO::ImageSpec& s0 = specs[0];
  if (s0.full_x != 0 || s0.full_y != 0 || s0.full_width < 1 || s0.full_height < 1 ||
      s0.full_width > kMaxSide || s0.full_height > kMaxSide)
    throw InputError(name, "", "unsupported display window");
  if (s0.x < 0 || s0.y < 0 || s0.width < 1 || s0.height < 1 || int64_t(s0.x) + s0.width > s0.full_width ||
      int64_t(s0.y) + s0.height > s0.full_height)
    throw InputError(name, "", "data window lies outside the display window");
  for (const auto& sp : specs) {
    if (sp.x != s0.x || sp.y != s0.y || sp.width != s0.width || sp.height != s0.height || sp.full_x != 0 ||
        sp.full_y != 0 || sp.full_width != s0.full_width || sp.full_height != s0.full_height ||
        sp.depth != 1 || sp.z != 0)
      throw InputError(name, "", "its parts have different windows");
    if (sp.deep && specs.size() > 1) throw InputError(name, "", "multi-part deep images cannot be merged");
    if (sp.nchannels < 1) throw InputError(name, "", "a part has no channels");
  }
  return specs;
}

}  // namespace exr_parts

namespace {

using namespace exr_parts;

const OIIO::ParamValue* string_attribute(const OIIO::ImageSpec& spec, const char* name) {
  return spec.find_attribute(name, OIIO::TypeDesc::STRING);
}

// The settings a part was rendered with; throws InputError naming the part if they are absent
// or malformed.
RenderSettings part_settings(const std::string& name, const OIIO::ImageSpec& spec) {
  const OIIO::ParamValue* p = string_attribute(spec, kSettingsAttribute);
  if (!p)
    throw InputError(
        name, "",
        std::string("has no ") + kSettingsAttribute + " metadata (not a Penumbra tile?); " + kForceHint);
  try {
    return parse_canonical_text(p->get_string());
  } catch (const std::invalid_argument& e) {
    throw InputError(name, kSettingsAttribute, std::string("malformed (") + e.what() + "); " + kForceHint);
  }
}

std::string part_scene(const std::string& name, const OIIO::ImageSpec& spec) {
  const OIIO::ParamValue* p = string_attribute(spec, kSceneHashAttribute);
  if (!p)
    throw InputError(
        name, "",
        std::string("has no ") + kSceneHashAttribute + " metadata (not a Penumbra tile?); " + kForceHint);
  return p->get_string();
}

// Whether the parts' settings ask for the frame to be denoised, and with the noisy beauty as
// the main layer: (denoise, noisy_main). Parts without settings (--force) are not denoised.
std::pair<bool, bool> requested_denoise(const OIIO::ImageSpec& spec) {
  const OIIO::ParamValue* p = string_attribute(spec, kSettingsAttribute);
  if (!p) return {false, false};
  try {
    const RenderSettings s = parse_canonical_text(p->get_string());
    const auto d = s.entries.find("denoise");
    const auto m = s.entries.find("denoise_main");
    return {d != s.entries.end() && d->second == "1", m != s.entries.end() && m->second == "noisy"};
  } catch (const std::invalid_argument&) {
    return {false, false};
  }
}

// What makes tiles parts of one frame: the scene and the settings they were rendered with.
struct PartIdentity {
  std::string scene;
  RenderSettings settings;
};

// The identity recorded in a part's first EXR part; throws InputError naming the part if absent.
PartIdentity part_identity(const std::string& name, const OIIO::ImageSpec& spec) {
  return {part_scene(name, spec), part_settings(name, spec)};
}

// Throws unless part `name` was rendered from the same scene with the same settings as the
// first part.
void check_same_identity(const std::string& name, const PartIdentity& id, const std::string& first_name,
                         const PartIdentity& first) {
  if (id.scene != first.scene)
    throw InputError(name, "",
                     "is from another scene than " + first_name + ": " + kSceneHashAttribute + " '" +
                         id.scene + "', " + first_name + " has '" + first.scene + "'; " + kForceHint);
  if (id.settings.entries != first.settings.entries)
    throw InputError(name, "",
                     "was rendered with other settings than " + first_name + ":\n" +
                         describe_differences(first.settings, id.settings, first_name, name) + "\n" +
                         kForceHint);
}

// Throws unless the part has the display window and the EXR parts and channels of the first.
void check_layout(const std::string& name, const std::vector<OIIO::ImageSpec>& specs,
                  const std::string& first_name, const std::vector<OIIO::ImageSpec>& full) {
  const OIIO::ImageSpec& s0 = specs[0];
  if (s0.full_width != full[0].full_width || s0.full_height != full[0].full_height)
    throw InputError(name, "",
                     "display window " + std::to_string(s0.full_width) + "x" +
                         std::to_string(s0.full_height) + " differs from " + first_name + "'s " +
                         std::to_string(full[0].full_width) + "x" + std::to_string(full[0].full_height));
  bool same = specs.size() == full.size();
  for (size_t sub = 0; same && sub < specs.size(); ++sub) {
    same = specs[sub].nchannels == full[sub].nchannels;
    for (int c = 0; same && c < specs[sub].nchannels; ++c)
      same = specs[sub].channelnames[size_t(c)] == full[sub].channelnames[size_t(c)] &&
             specs[sub].channelformat(c) == full[sub].channelformat(c);
  }
  if (!same) throw InputError(name, "", "its parts or channels differ from " + first_name + "'s");
}

// Records part `k` as the owner of the pixels of its data window; throws if one is taken.
void claim_pixels(const std::vector<std::filesystem::path>& parts, size_t k, const OIIO::ImageSpec& s0,
                  std::vector<int>& owner) {
  for (int y = 0; y < s0.height; ++y)
    for (int x = 0; x < s0.width; ++x) {
      const size_t f = size_t(s0.y + y) * size_t(s0.full_width) + size_t(s0.x + x);
      if (owner[f] >= 0)
        throw InputError(parts[k].string(), "",
                         "overlaps " + parts[size_t(owner[f])].string() + " at pixel " +
                             std::to_string(s0.x + x) + "," + std::to_string(s0.y + y));
      owner[f] = int(k);
    }
}

// Decodes every EXR part of `in` in its native channel types into its place in `pixels`.
void copy_pixels(OIIO::ImageInput& in, const std::string& name, const std::vector<OIIO::ImageSpec>& specs,
                 std::vector<std::vector<unsigned char>>& pixels) {
  for (size_t sub = 0; sub < specs.size(); ++sub) {
    const OIIO::ImageSpec& sp = specs[sub];
    const size_t pb = sp.pixel_bytes(true);
    std::vector<unsigned char> data(size_t(sp.width) * size_t(sp.height) * pb);
    if (!in.read_image(int(sub), 0, 0, sp.nchannels, OIIO::TypeDesc::UNKNOWN, data.data()))
      throw InputError(name, "", "cannot decode: " + in.geterror());
    for (int y = 0; y < sp.height; ++y)
      std::memcpy(&pixels[sub][(size_t(sp.y + y) * size_t(sp.full_width) + size_t(sp.x)) * pb],
                  &data[size_t(y) * size_t(sp.width) * pb], size_t(sp.width) * pb);
  }
}

// Sums of the statistics that add up over a frame's parts; each is written only when every part
// has it, and removed otherwise.
struct PartStatistics {
  bool has_samples = true, has_passes = true, has_seconds = true;
  uint64_t samples = 0;
  long long passes = 0;
  double seconds = 0;

  void add(const OIIO::ImageSpec& spec) {
    const OIIO::ParamValue* s = string_attribute(spec, kSamplesAttribute);
    const OIIO::ParamValue* p = string_attribute(spec, kPassesAttribute);
    const OIIO::ParamValue* t = spec.find_attribute(kRenderSecondsAttribute, OIIO::TypeDesc::FLOAT);
    has_samples = has_samples && s && add_count(s->get_string(), samples);
    uint64_t part_passes = 0;
    has_passes = has_passes && p && add_count(p->get_string(), part_passes);
    passes = std::max(passes, static_cast<long long>(part_passes));
    has_seconds = has_seconds && t;
    if (t) seconds += double(t->get_float());
  }
  // Writes the frame's statistics into the header of an EXR part, where it has them (every part
  // of a multi-part file repeats the metadata).
  void apply(OIIO::ImageSpec& spec) const {
    const uint64_t pixels = uint64_t(spec.full_width) * uint64_t(spec.full_height);
    const auto replace = [&](bool keep, const char* name, auto value) {
      if (!spec.find_attribute(name)) return;
      if (keep)
        spec.attribute(name, value);
      else  // the first part's figure would describe that part alone
        spec.erase_attribute(name);
    };
    replace(has_samples, kSamplesAttribute, std::to_string(samples));
    replace(has_samples, kMeanSppAttribute, format_mean_spp(samples, pixels));
    replace(has_passes, kPassesAttribute, std::to_string(passes));
    replace(has_seconds, kRenderSecondsAttribute, float(seconds));
  }

 private:
  // Adds the decimal count `text` to `sum`; false if it is not one or the sum overflows.
  static bool add_count(const std::string& text, uint64_t& sum) {
    if (text.empty() || text.size() > 19 || text.find_first_not_of("0123456789") != std::string::npos)
      return false;
    return !__builtin_add_overflow(sum, std::stoull(text), &sum);
  }
};

}  // namespace

void exr_parts::write_frame(const std::filesystem::path& out, std::vector<OIIO::ImageSpec> specs,
                            const std::vector<std::vector<unsigned char>>& pixels, bool whole_frame,
                            std::string* sha256) {
  for (auto& sp : specs) {
    if (whole_frame) {
      sp.x = sp.y = 0;
      sp.width = sp.full_width;
      sp.height = sp.full_height;
    }
    sp.tile_width = sp.tile_height = 0;
    sp.erase_attribute("openexr:chunkCount");  // a part's count; the writer counts the frame's
  }
  write_atomically(
      out,
      [&](const std::filesystem::path& temp) {
        auto o = OIIO::ImageOutput::create(out.string());
        if (!o) throw std::runtime_error(out.string() + ": no image writer (" + OIIO::geterror() + ")");
        const bool multi = specs.size() > 1;
        write_through_checked_file(o, temp, out, [&] {
          if (!(multi ? o->open(temp.string(), int(specs.size()), specs.data())
                      : o->open(temp.string(), specs[0])))
            throw std::runtime_error(out.string() + ": cannot open for writing: " + o->geterror());
          for (size_t sub = 0; sub < specs.size(); ++sub) {
            if (sub > 0 && !o->open(temp.string(), specs[sub], OIIO::ImageOutput::AppendSubimage))
              throw std::runtime_error(out.string() + ": cannot start part " + std::to_string(sub) + ": " +
                                       o->geterror());
            if (!o->write_image(OIIO::TypeDesc::UNKNOWN, pixels[sub].data()))
              throw std::runtime_error(out.string() + ": write failed: " + o->geterror());
          }
          if (!o->close()) throw std::runtime_error(out.string() + ": close failed: " + o->geterror());
        });
      },
      sha256);
}

/// Cryptomatte manifests kept in sidecar files (cryptomatte/<key>/manif_file, relative to the
/// EXR) follow the frame: each is copied from beside the first part to beside `out`
/// ("OUT.{name}.json") and the attribute renamed in every part's header.
void exr_parts::move_crypto_sidecars(const std::filesystem::path& first, const std::filesystem::path& out,
                                     std::vector<OIIO::ImageSpec>& specs) {
  constexpr uint64_t kMaxManifestBytes = uint64_t(1) << 30;
  for (const OIIO::ParamValue& p : OIIO::ParamValueList(specs[0].extra_attribs)) {
    const std::string attr = p.name().string();
    if (attr.rfind("cryptomatte/", 0) != 0 || attr.size() < 11 ||
        attr.compare(attr.size() - 11, 11, "/manif_file") != 0 || p.type() != OIIO::TypeDesc::STRING)
      continue;
    const std::string prefix = attr.substr(0, attr.size() - 10);  // "cryptomatte/<key>/"
    const std::string layer = specs[0].get_string_attribute(prefix + "name", "manifest");
    const std::filesystem::path source = first.parent_path() / p.get_string();
    check_input_file(source, attr, kMaxManifestBytes);
    std::ifstream in(source, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) throw InputError(source.string(), attr, "cannot be read");
    const std::filesystem::path dest = std::filesystem::path(out).replace_extension("." + layer + ".json");
    write_atomically(dest, [&](const std::filesystem::path& temp) {
      write_file_checked(temp, text.data(), text.size(), dest);
    });
    for (auto& sp : specs)
      if (sp.find_attribute(attr)) sp.attribute(attr, dest.filename().string());
  }
}

namespace {

// The deep parts' samples, each part's pixels copied into its place in one whole-frame deep image.
void write_merged_deep(const std::filesystem::path& out, OIIO::ImageSpec spec,
                       const std::vector<OIIO::ImageSpec>& specs, const std::vector<OIIO::DeepData>& data) {
  spec.x = spec.y = 0;
  spec.width = spec.full_width;
  spec.height = spec.full_height;
  spec.tile_width = spec.tile_height = 0;
  spec.erase_attribute("openexr:chunkCount");
  const auto frame_pixel = [&](const OIIO::ImageSpec& sp, int x, int y) {
    return int64_t(sp.y + y) * int64_t(spec.full_width) + int64_t(sp.x + x);
  };
  std::vector<unsigned int> counts(size_t(spec.full_width) * size_t(spec.full_height), 0);
  for (size_t k = 0; k < specs.size(); ++k)
    for (int y = 0; y < specs[k].height; ++y)
      for (int x = 0; x < specs[k].width; ++x)
        counts[size_t(frame_pixel(specs[k], x, y))] =
            unsigned(data[k].samples(int64_t(y) * specs[k].width + x));
  OIIO::DeepData frame;
  frame.init(spec);
  frame.set_all_samples(counts);
  for (size_t k = 0; k < specs.size(); ++k)
    for (int y = 0; y < specs[k].height; ++y)
      for (int x = 0; x < specs[k].width; ++x)
        frame.copy_deep_pixel(frame_pixel(specs[k], x, y), data[k], int64_t(y) * specs[k].width + x);
  write_deep_frame(out, spec, frame);
}

}  // namespace

void merge_exr_parts(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& out,
                     const MergeOptions& options) {
  if (parts.empty()) throw InputError(out.string(), "", "no parts to merge");
  std::vector<uint64_t> sizes;
  for (const auto& part : parts) sizes.push_back(check_input_file(part, "", kMaxMergePartBytes));
  const std::string first_name = parts[0].string();
  std::vector<OIIO::ImageSpec> full;               // per EXR part (subimage), from the first file
  std::vector<std::vector<unsigned char>> pixels;  // per subimage, the whole frame
  std::vector<int> owner;                          // file that wrote each pixel, -1 = none
  PartIdentity first_id;                           // without options.force
  PartStatistics statistics;
  double frame_bytes = 0;
  // Deep parts: each one's window and samples, and the bytes they hold.
  const bool deep = is_deep_exr(parts[0]);
  std::vector<OIIO::ImageSpec> deep_specs;
  std::vector<OIIO::DeepData> deep_data;
  double deep_bytes = 0;
  for (size_t k = 0; k < parts.size(); ++k) {
    const std::string name = parts[k].string();
    const ExrHeaderInfo header = check_exr_header(parts[k], sizes[k], deep);
    auto in = open_part(name);
    const std::vector<OIIO::ImageSpec> specs = read_specs(*in, name);
    if (!options.force) {
      PartIdentity id = part_identity(name, specs[0]);
      const auto complete = id.settings.entries.find("complete");
      if (complete != id.settings.entries.end() && complete->second != "1")
        throw InputError(name, "",
                         "is incomplete: its render was interrupted or stopped by --time-limit before the "
                         "requested samples; " +
                             std::string(kForceHint));
      if (k == 0) {
        first_id = std::move(id);
      } else {
        check_same_identity(name, id, first_name, first_id);
      }
    }
    if (k == 0) full = specs;
    double part_bytes = 0;
    for (const auto& sp : specs) part_bytes = std::max(part_bytes, image_bytes(sp, false));
    if (k == 0) {
      for (const auto& sp : specs) frame_bytes += image_bytes(sp, true);
      frame_bytes += 4.0 * double(specs[0].full_width) * double(specs[0].full_height);  // pixel owners
      if (frame_bytes + part_bytes > double(options.max_memory_bytes))
        throw InputError(name, "",
                         "the full frame and one decoded part would need " +
                             format_bytes(uint64_t(frame_bytes + part_bytes)) + ", over the " +
                             format_bytes(options.max_memory_bytes) + " limit");
      if (!deep)  // deep samples are kept per part (deep_data)
        for (const auto& sp : specs) pixels.emplace_back(size_t(image_bytes(sp, true)), 0);
      owner.assign(size_t(specs[0].full_width) * size_t(specs[0].full_height), -1);
    } else {
      check_layout(name, specs, first_name, full);
      if (frame_bytes + part_bytes > double(options.max_memory_bytes))
        throw InputError(name, "",
                         "decoding it beside the full frame would exceed the " +
                             format_bytes(options.max_memory_bytes) + " limit");
    }
    claim_pixels(parts, k, specs[0], owner);
    if (deep) {
      // What the part's chunks declare, checked before OpenEXR allocates it.
      const double declared = double(check_deep_chunks(parts[k], sizes[k], header,
                                                       uint64_t(specs[0].width) * uint64_t(specs[0].height),
                                                       options.max_memory_bytes));
      if (2 * (deep_bytes + declared) > double(options.max_memory_bytes))
        throw InputError(name, "",
                         "the deep parts' samples and the frame's would need more than the " +
                             format_bytes(options.max_memory_bytes) + " limit");
      OIIO::DeepData d;
      if (!in->read_native_deep_image(0, 0, d))
        throw InputError(name, "", "cannot decode: " + in->geterror());
      deep_bytes += double(d.all_data().size()) + 4.0 * double(d.pixels());
      // The parts' samples and the frame's copy of them.
      if (2 * deep_bytes > double(options.max_memory_bytes))
        throw InputError(name, "",
                         "the deep parts' samples and the frame's would need " +
                             format_bytes(uint64_t(2 * deep_bytes)) + ", over the " +
                             format_bytes(options.max_memory_bytes) + " limit");
      deep_specs.push_back(specs[0]);
      deep_data.push_back(std::move(d));
    } else {
      copy_pixels(*in, name, specs, pixels);
    }
    statistics.add(specs[0]);
  }
  for (size_t f = 0; f < owner.size(); ++f)
    if (owner[f] < 0)
      throw InputError(out.string(), "",
                       "the parts do not cover the frame: pixel " +
                           std::to_string(f % size_t(full[0].full_width)) + "," +
                           std::to_string(f / size_t(full[0].full_width)) + " is missing");
  // The first part's capture date; OpenImageIO reads an empty one as none and would stamp the
  // time of the merge.
  for (auto& spec : full) {
    statistics.apply(spec);
    if (!spec.find_attribute("DateTime")) spec.attribute("DateTime", "");
  }
  move_crypto_sidecars(parts[0], out, full);
  if (deep) {
    write_merged_deep(out, full[0], deep_specs, deep_data);
    return;
  }
  const auto [denoise, noisy_main] = requested_denoise(full[0]);
  if (!denoise) {
    write_frame(out, full, pixels);
    return;
  }
  ExrDenoiseOptions d;
  d.noisy_main = noisy_main;
  d.config.threads = options.threads;
  d.max_memory_bytes = options.max_memory_bytes;
  d.progress = options.denoise_progress;
  denoise_through_file(
      out,
      [&](const std::filesystem::path& noisy) {
        write_frame(noisy, full, pixels);
        std::vector<std::vector<unsigned char>>().swap(pixels);  // the denoiser reads the file
      },
      d);
}

std::string format_mean_spp(uint64_t samples, uint64_t pixels) {
  char text[64];
  std::snprintf(text, sizeof text, "%.3f", pixels ? double(samples) / double(pixels) : 0.0);
  return text;
}

}  // namespace penumbra
