// Frame ranges, `#` path patterns and the completeness check of a frame's EXR.
#include "io/farm/frame_outputs.h"

#include <OpenImageIO/deepdata.h>
#include <OpenImageIO/imageio.h>

#include <charconv>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "io/farm/render_settings.h"

namespace penumbra {

namespace {

/// Parses one frame number at text[pos...] (an optional '-', then digits); advances pos.
int64_t parse_frame_number(const std::string& text, size_t& pos) {
  const auto bad = [&] {
    return std::invalid_argument("--frames: '" + text +
                                 "' is not a frame range (expected N, A-B or A-B:STEP)");
  };
  if (pos >= text.size() || text[pos] == '+') throw bad();
  int64_t v = 0;
  const char* begin = text.data() + pos;
  const auto r = std::from_chars(begin, text.data() + text.size(), v);
  if (r.ec == std::errc::result_out_of_range ||
      (r.ec == std::errc() && (v > kMaxFrameNumber || v < -kMaxFrameNumber)))
    throw std::invalid_argument("--frames: '" + text + "': frame numbers must lie within +-" +
                                std::to_string(kMaxFrameNumber));
  if (r.ec != std::errc()) throw bad();
  pos = size_t(r.ptr - text.data());
  return v;
}

}  // namespace

FrameRange parse_frame_range(const std::string& text) {
  const std::invalid_argument bad("--frames: '" + text +
                                  "' is not a frame range (expected N, A-B or A-B:STEP)");
  FrameRange r;
  size_t pos = 0;
  r.first = parse_frame_number(text, pos);
  r.last = r.first;
  if (pos < text.size()) {
    if (text[pos] != '-') throw bad;
    ++pos;
    r.last = parse_frame_number(text, pos);
    if (pos < text.size()) {
      if (text[pos] != ':') throw bad;
      ++pos;
      if (pos >= text.size() || text[pos] == '-' || text[pos] == '+')
        throw std::invalid_argument("--frames: '" + text + "': the step must be an integer >= 1");
      r.step = parse_frame_number(text, pos);
      if (pos < text.size()) throw bad;
    }
  }
  if (r.step < 1) throw std::invalid_argument("--frames: '" + text + "': the step must be an integer >= 1");
  if (r.last < r.first)
    throw std::invalid_argument("--frames: '" + text + "' is empty: the last frame comes before the first");
  if (r.count() > kMaxFramesPerRange)
    throw std::invalid_argument("--frames: '" + text + "' holds " + std::to_string(r.count()) +
                                " frames, more than " + std::to_string(kMaxFramesPerRange));
  return r;
}

bool has_frame_pattern(const std::string& path) {
  return path.find('#') != std::string::npos;
}

std::string substitute_frame(const std::string& path, int64_t frame) {
  const std::string digits = std::to_string(frame < 0 ? -frame : frame);
  std::string out;
  for (size_t i = 0; i < path.size();) {
    if (path[i] != '#') {
      out += path[i++];
      continue;
    }
    size_t k = 0;
    while (i + k < path.size() && path[i + k] == '#') ++k;
    i += k;
    const size_t width = frame < 0 ? (k > 0 ? k - 1 : 0) : k;
    if (frame < 0) out += '-';
    if (digits.size() < width) out.append(width - digits.size(), '0');
    out += digits;
  }
  return out;
}

bool is_complete_exr(const std::filesystem::path& path, std::string& problem) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    problem = "does not exist";
    return false;
  }
  if (!std::filesystem::is_regular_file(path, ec)) {
    problem = "is not a regular file";
    return false;
  }
  auto in = OIIO::ImageInput::create("openexr");
  if (!in) {
    problem = "OpenImageIO has no OpenEXR reader";
    return false;
  }
  OIIO::ImageSpec spec;
  if (!in->open(path.string(), spec)) {
    problem = "cannot be read as OpenEXR: " + in->geterror();
    return false;
  }
  // A render stopped by a signal, --time-limit or a checkpoint writes the image so far, marked
  // as such, with its resume state beside it.
  const OIIO::ParamValue* settings = spec.find_attribute(kSettingsAttribute, OIIO::TypeDesc::STRING);
  const std::string text = settings ? settings->get_string() : std::string();
  if (text.rfind("complete=0\n", 0) == 0 || text.find("\ncomplete=0\n") != std::string::npos) {
    problem = "holds an unfinished render (its penumbra:settings say complete=0)";
    return false;
  }
  if (std::filesystem::exists(std::filesystem::path(path).concat(".resume"), ec)) {
    problem = "has a resume state beside it (" + path.filename().string() + ".resume: an unfinished render)";
    return false;
  }
  std::vector<unsigned char> pixels;
  for (int sub = 0; in->seek_subimage(sub, 0); ++sub) {
    const OIIO::ImageSpec& s = in->spec();
    if (s.width < 1 || s.height < 1 || s.nchannels < 1) {
      problem = "holds an empty part";
      return false;
    }
    if (s.deep) {  // a deep image (render --deep): its samples must decode
      OIIO::DeepData samples;
      if (!in->read_native_deep_image(sub, 0, samples) || in->has_error()) {
        problem = "is incomplete: " + in->geterror();
        return false;
      }
      continue;
    }
    pixels.resize(size_t(s.image_bytes(true)));
    if (!in->read_image(sub, 0, 0, s.nchannels, OIIO::TypeDesc::UNKNOWN, pixels.data()) || in->has_error()) {
      problem = "is incomplete: " + in->geterror();
      return false;
    }
  }
  return true;
}

}  // namespace penumbra
