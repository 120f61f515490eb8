// Deep EXR writing and reading through OpenImageIO's DeepData.
#include "io/image/deep_exr.h"

#include <OpenImageIO/deepdata.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "io/files/atomic_file.h"
#include "io/files/checked_file.h"
#include "io/files/error.h"
#include "io/files/file_checks.h"
#include "io/image/exr_parts.h"

namespace penumbra {

void exr_parts::write_deep_frame(const std::filesystem::path& out, const OIIO::ImageSpec& spec,
                                 const OIIO::DeepData& data, std::string* sha256) {
  write_atomically(
      out,
      [&](const std::filesystem::path& temp) {
        auto o = OIIO::ImageOutput::create(out.string());
        if (!o || !o->supports("deepdata"))
          throw std::runtime_error(out.string() + ": no deep image writer for this extension");
        write_through_checked_file(o, temp, out, [&] {
          if (!o->open(temp.string(), spec))
            throw std::runtime_error(out.string() + ": cannot open for writing: " + o->geterror());
          if (!o->write_deep_image(data))
            throw std::runtime_error(out.string() + ": write failed: " + o->geterror());
          if (!o->close()) throw std::runtime_error(out.string() + ": close failed: " + o->geterror());
        });
      },
      sha256);
}

uint64_t exr_parts::check_deep_chunks(const std::filesystem::path& path, uint64_t size,
                                      const ExrHeaderInfo& info, uint64_t pixels, uint64_t max_bytes) {
  const std::string name = path.string();
  if (info.multipart) throw InputError(name, "", "multi-part deep files are not read (one deep part only)");
  const uint64_t table_end = info.end + 8 * uint64_t(std::max<int64_t>(info.chunk_count, 0));
  if (info.chunk_count < 1 || info.chunk_count > 65536 || table_end > size)
    throw InputError(name, "chunkCount", "the chunk table does not fit the file");
  std::ifstream in(path, std::ios::binary);
  in.seekg(std::streamoff(info.end));
  std::vector<uint64_t> offsets(size_t(info.chunk_count));
  in.read(reinterpret_cast<char*>(offsets.data()), std::streamsize(offsets.size() * 8));
  uint64_t total = pixels * 16;  // the counts, OpenImageIO's and OpenEXR's
  for (size_t c = 0; c < offsets.size() && in; ++c) {
    // y (int32), packed count table size, packed sample data size, unpacked sample data size.
    constexpr uint64_t kChunkHeader = 4 + 3 * 8;
    uint64_t sizes[3] = {0, 0, 0};
    if (offsets[c] < table_end || offsets[c] > size - kChunkHeader ||
        !in.seekg(std::streamoff(offsets[c] + 4)).read(reinterpret_cast<char*>(sizes), sizeof sizes))
      throw InputError(name, "", "chunk " + std::to_string(c) + " lies outside the file");
    const uint64_t left = size - offsets[c] - kChunkHeader;
    if (sizes[0] > left || sizes[1] > left - sizes[0])
      throw InputError(name, "", "chunk " + std::to_string(c) + " claims more bytes than the file holds");
    if (sizes[2] > max_bytes || total > max_bytes - sizes[2])
      throw InputError(name, "",
                       "its samples would need more than the " + format_bytes(max_bytes) + " limit (chunk " +
                           std::to_string(c) + " alone unpacks to " + format_bytes(sizes[2]) + ")");
    total += sizes[2];
  }
  if (!in) throw InputError(name, "", "its chunk table is cut off");
  return total;
}

bool exr_parts::is_deep_exr(const std::filesystem::path& path) {
  // OpenEXR's magic number, then the version field's "non-image" (deep) flag, bit 11.
  std::ifstream in(path, std::ios::binary);
  unsigned char start[8] = {};
  return in.read(reinterpret_cast<char*>(start), sizeof start) && start[0] == 0x76 && start[1] == 0x2f &&
         start[2] == 0x31 && start[3] == 0x01 && (start[5] & 0x08) != 0;
}

void write_deep_exr(const DeepImage& image, const std::filesystem::path& path, const ExrOptions& options,
                    std::string* sha256) {
  OIIO::ImageSpec spec(image.width, image.height, kDeepChannels, OIIO::TypeDesc::FLOAT);
  spec.channelnames.assign(std::begin(kDeepChannelNames), std::end(kDeepChannelNames));
  spec.alpha_channel = 3;
  spec.z_channel = 4;
  spec.deep = true;
  spec.x = image.origin_x;
  spec.y = image.origin_y;
  spec.full_x = spec.full_y = 0;
  spec.full_width = image.full_width > 0 ? image.full_width : image.width;
  spec.full_height = image.full_height > 0 ? image.full_height : image.height;
  spec.attribute("compression", options.compression == "none" ? "none" : "zips");
  exr_parts::set_attributes(spec, options);
  const size_t npix = size_t(image.width) * size_t(image.height);
  if (image.counts.size() != npix)
    throw std::invalid_argument(path.string() + ": the deep image's sample counts do not match its size");
  OIIO::DeepData data;
  data.init(spec);
  data.set_all_samples(OIIO::cspan<unsigned int>(image.counts.data(), image.counts.size()));
  size_t at = 0;
  for (size_t p = 0; p < npix; ++p) {
    const uint32_t n = image.counts[p];
    if (n == 0) continue;
    if (at + n > image.samples.size())
      throw std::invalid_argument(path.string() + ": the deep image holds fewer samples than its counts");
    std::memcpy(data.data_ptr(int64_t(p), 0, 0), &image.samples[at], size_t(n) * sizeof(DeepSample));
    at += n;
  }
  exr_parts::write_deep_frame(path, spec, data, sha256);
}

DeepImage read_deep_exr(const std::filesystem::path& path, uint64_t max_bytes) {
  const std::string name = path.string();
  const uint64_t size = check_input_file(path, "", max_bytes);
  if (!exr_parts::is_deep_exr(path)) throw InputError(name, "", "is not a deep OpenEXR image");
  const exr_parts::ExrHeaderInfo header = exr_parts::check_exr_header(path, size, true);
  auto in = exr_parts::open_part(name);
  const OIIO::ImageSpec spec = in->spec();
  if (!spec.deep) throw InputError(name, "", "is not a deep image");
  exr_parts::check_deep_chunks(path, size, header, uint64_t(spec.width) * uint64_t(spec.height), max_bytes);
  int channel[kDeepChannels];
  for (int c = 0; c < kDeepChannels; ++c) {
    channel[c] = spec.channelindex(kDeepChannelNames[c]);
    if (channel[c] < 0) throw InputError(name, kDeepChannelNames[c], "the deep channel is missing");
  }
  OIIO::DeepData data;
  if (!in->read_native_deep_image(0, 0, data)) throw InputError(name, "", "cannot decode: " + in->geterror());
  DeepImage img;
  img.width = spec.width;
  img.height = spec.height;
  img.origin_x = spec.x;
  img.origin_y = spec.y;
  img.full_width = spec.full_width;
  img.full_height = spec.full_height;
  const int64_t npix = data.pixels();
  uint64_t total = 0;
  for (int64_t p = 0; p < npix; ++p) total += uint64_t(data.samples(p));
  if (deep_image_bytes(uint64_t(npix), total) > max_bytes)
    throw InputError(name, "",
                     "its " + std::to_string(total) + " deep samples need " +
                         format_bytes(deep_image_bytes(uint64_t(npix), total)) + ", over the " +
                         format_bytes(max_bytes) + " limit");
  img.counts.resize(size_t(npix));
  img.samples.reserve(size_t(total));
  for (int64_t p = 0; p < npix; ++p) {
    img.counts[size_t(p)] = uint32_t(data.samples(p));
    const auto bad = [&](const char* channel_name, const std::string& what) {
      return InputError(name, channel_name,
                        what + " at pixel " + std::to_string(spec.x + int(p % spec.width)) + "," +
                            std::to_string(spec.y + int(p / spec.width)));
    };
    for (int s = 0; s < data.samples(p); ++s) {
      float v[kDeepChannels];
      for (int c = 0; c < kDeepChannels; ++c) v[c] = data.deep_value(p, channel[c], s);
      DeepSample ds;
      std::memcpy(&ds, v, sizeof ds);
      if (!(ds.a >= 0 && ds.a <= 1)) throw bad("A", "alpha outside [0, 1]");
      if (!(ds.z >= 0 && ds.zback >= ds.z))
        throw bad("Z", "a depth that is negative, NaN or behind its ZBack");
      if (s > 0 && ds.z < img.samples.back().z) throw bad("Z", "samples not sorted front to back");
      img.samples.push_back(ds);
    }
  }
  return img;
}

}  // namespace penumbra
