// Environment map loading through OpenImageIO.
#include "io/image/environment_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include "io/files/error.h"
#include "io/files/file_checks.h"

namespace penumbra {

uint64_t environment_bytes(int width, int height, int channels) {
  // Decoded floats, RGB texels, the texel pdf and the conditional CDF (about one float each).
  return uint64_t(width) * uint64_t(height) * (uint64_t(std::max(channels, 1)) * 4 + 12 + 4 + 4);
}

Environment load_environment(const std::filesystem::path& path, float intensity, float rotation_degrees,
                             uint64_t max_bytes) {
  const std::string file = path.string();
  if (!std::isfinite(intensity) || intensity < 0)
    throw InputError(file, "--env-intensity", "must be finite and >= 0");
  if (!std::isfinite(rotation_degrees)) throw InputError(file, "--env-rotation", "must be finite");
  check_input_file(path, "--env", kMaxEnvironmentFileBytes);
  auto in = OIIO::ImageInput::open(file);
  if (!in) throw InputError(file, "", "cannot read environment map: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  const int w = spec.width, h = spec.height, nc = spec.nchannels;
  if (w < 1 || h < 1 || nc < 1) throw InputError(file, "", "environment map has no pixels");
  if (w > kMaxEnvironmentSide || h > kMaxEnvironmentSide)
    throw InputError(file, "",
                     "environment map " + std::to_string(w) + "x" + std::to_string(h) + " exceeds " +
                         std::to_string(kMaxEnvironmentSide) + " per side");
  if (environment_bytes(w, h, nc) > max_bytes)
    throw InputError(file, "",
                     "environment map " + std::to_string(w) + "x" + std::to_string(h) + " needs " +
                         std::to_string(environment_bytes(w, h, nc) >> 20) +
                         " MiB, over the memory budget of " + std::to_string(max_bytes >> 20) +
                         " MiB (--max-memory)");
  std::vector<float> pixels(size_t(w) * size_t(h) * size_t(nc));
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw InputError(file, "", "cannot decode environment map: " + in->geterror());
  in->close();
  std::vector<Vec3f> texels(size_t(w) * size_t(h));
  for (size_t i = 0; i < texels.size(); ++i) {
    const float* p = &pixels[i * size_t(nc)];
    const Vec3f c = nc >= 3 ? Vec3f{p[0], p[1], p[2]} : Vec3f{p[0], p[0], p[0]};
    if (!is_finite(c) || c.x < 0 || c.y < 0 || c.z < 0)
      throw InputError(file, "pixel " + std::to_string(i % size_t(w)) + "," + std::to_string(i / size_t(w)),
                       "environment texels must be finite and >= 0");
    texels[i] = c;
  }
  return make_map_environment(w, h, std::move(texels), intensity, rotation_degrees * kPi / 180.0f);
}

}  // namespace penumbra
