// EXR and display-image writers.
#include "io/image_output.h"

#include <OpenColorIO/OpenColorIO.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "io/atomic_file.h"
#include "io/error.h"

namespace OCIO = OCIO_NAMESPACE;

namespace penumbra {

namespace {

void write_with_oiio(const std::filesystem::path& final_path, const std::filesystem::path& temp,
                     const OIIO::ImageSpec& spec, const void* pixels, OIIO::TypeDesc pixel_type) {
  auto out = OIIO::ImageOutput::create(final_path.string());
  if (!out)
    throw std::runtime_error(final_path.string() + ": no image writer for this extension (" +
                             OIIO::geterror() + ")");
  if (!out->open(temp.string(), spec))
    throw std::runtime_error(final_path.string() + ": cannot open for writing: " + out->geterror());
  if (!out->write_image(pixel_type, pixels))
    throw std::runtime_error(final_path.string() + ": write failed: " + out->geterror());
  if (!out->close()) throw std::runtime_error(final_path.string() + ": close failed: " + out->geterror());
}

}  // namespace

void write_exr(const Film& film, const std::filesystem::path& path, const ExrOptions& options) {
  OIIO::ImageSpec spec(film.width, film.height, 4, options.half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "B", "A"};
  spec.alpha_channel = 3;
  spec.attribute("compression", options.compression);
  spec.attribute("oiio:ColorSpace", "lin_rec709");
  spec.attribute("Software", "Penumbra " PENUMBRA_VERSION);
  for (const auto& [k, v] : options.metadata) spec.attribute(k, v);
  write_atomically(path, [&](const std::filesystem::path& temp) {
    write_with_oiio(path, temp, spec, film.rgba.data(), OIIO::TypeDesc::FLOAT);
  });
}

namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

/// The one place that turns DisplayOptions into a CPU processor (config, display, view).
OCIO::ConstCPUProcessorRcPtr display_processor(const DisplayOptions& options) {
  const char* env = std::getenv("OCIO");
  const std::string source = !options.ocio_config.empty() ? options.ocio_config
                             : (env && *env)              ? std::string(env)
                                                          : std::string("<shipped config>");
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
    throw InputError(source, "--view", "display '" + display + "' has no view '" + view + "' (available: " + views + ")");
  try {
    return config->getProcessor(OCIO::ROLE_SCENE_LINEAR, display.c_str(), view.c_str(), OCIO::TRANSFORM_DIR_FORWARD)
        ->getDefaultCPUProcessor();
  } catch (const OCIO::Exception& e) {
    throw InputError(source, "OpenColorIO", e.what());
  }
}

}  // namespace

void check_display_output(const std::filesystem::path& path, const DisplayOptions& options) {
  const std::string ext = lower_extension(path);
  if (ext != ".png" && ext != ".jpg" && ext != ".jpeg" && ext != ".tif" && ext != ".tiff")
    throw InputError(path.string(), "", "unsupported display image format '" + ext + "' (use .png, .jpg, .jpeg, .tif or .tiff)");
  display_processor(options);
}

void apply_display_transform(std::vector<float>& rgb, int width, int height,
                             const DisplayOptions& options) {
  const auto cpu = display_processor(options);
  OCIO::PackedImageDesc desc(rgb.data(), width, height, 3);
  cpu->apply(desc);
}

void write_display_image(const Film& film, const std::filesystem::path& path,
                         const DisplayOptions& options) {
  const size_t n = size_t(film.width) * size_t(film.height);
  std::vector<float> rgb(n * 3);
  const float gain = std::exp2(options.exposure);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) rgb[i * 3 + size_t(c)] = film.rgba[i * 4 + size_t(c)] * gain;
  apply_display_transform(rgb, film.width, film.height, options);
  const std::string ext = lower_extension(path);
  const bool sixteen = ext == ".tif" || ext == ".tiff";
  OIIO::ImageSpec spec(film.width, film.height, 3, sixteen ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  spec.attribute("Software", "Penumbra " PENUMBRA_VERSION);
  for (float& v : rgb) v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
  write_atomically(path, [&](const std::filesystem::path& temp) {
    write_with_oiio(path, temp, spec, rgb.data(), OIIO::TypeDesc::FLOAT);
  });
}

}  // namespace penumbra
