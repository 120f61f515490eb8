// Scene sessions, render settings, renders and their EXR for the Python module.
#include "python/render_session.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "io/files/error.h"
#include "io/gltf/id_manifest.h"
#include "io/image/deep_exr.h"
#include "io/image/environment_io.h"
#include "io/image/exr_denoise.h"
#include "render/exr_layers.h"
#include "renderer/accel/factory.h"
#include "renderer/integrators/light_groups.h"
#include "renderer/integrators/raster.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/lights/environment.h"
#include "renderer/scene/camera.h"

namespace penumbra::python {

uint64_t default_memory_budget() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 8ull << 30;
  return uint64_t(pages) * uint64_t(page) / 2;
}

std::shared_ptr<SceneSession> load_session(const std::string& file, const GltfLoadOptions& options) {
  auto session = std::make_shared<SceneSession>();
  session->file = file;
  session->loaded = load_gltf(file, options);
  session->loaded_at_time = options.time.has_value();
  session->time = options.time.value_or(0);
  session->load_at = [file, options](double time) {
    GltfLoadOptions at = options;
    at.time = time;
    at.keep_animation = false;
    return load_gltf(file, at);
  };
  return session;
}

bool pose_session(SceneSession& session, double time) {
  if (!session.loaded.animation) return false;
  uint64_t moved = 0;
  if (!pose_gltf_scene(*session.loaded.animation, time, session.loaded.scene, &moved)) return false;
  session.time = time;
  session.area_lights.reset();  // punctual lights among them may have moved
  if (moved == 0) return true;
  Structure& s = session.structure;
  try {
    if (s.accel && !s.accel->update_instances(instance_views(session.loaded.scene))) s = Structure{};
  } catch (...) {
    s = Structure{};
    throw;
  }
  return true;
}

const std::vector<std::string>& python_aov_names() {
  static const std::vector<std::string> names = {
      "albedo", "N", "P", "Z", "UV", "id", "samples", "variance", "light", "halves", "vector", "velocity"};
  return names;
}

RenderOutput render_session(SceneSession& session, const RenderSettings& settings,
                            const std::vector<std::string>& aov_names) {
  RenderSpec spec = settings;
  spec.aovs = check_aovs(aov_names, spec.integrator, python_aov_names());
  validate(spec);
  RenderResult r = render_scene(session, spec, default_memory_budget());
  RenderOutput out;
  out.scene_file = session.file;
  out.settings = settings;
  out.aovs = spec.aovs;
  if (spec.denoise) out.aovs.insert("halves");
  out.config = r.prepared.config;
  out.camera = r.prepared.camera;
  out.camera_index = r.prepared.camera_index;
  out.default_light = r.prepared.default_light;
  out.warnings = r.prepared.warnings;
  out.film = std::move(r.image.film);
  if (spec.denoise) {
    out.second = std::move(r.image.denoised);
    if (spec.denoise_main == "denoised") std::swap(out.film, out.second);
  }
  out.halves = std::move(r.image.halves);
  out.stats = r.image.stats;
  if (out.aovs.count("samples")) {
    out.samples = std::move(r.image.samples);
    out.samples_f.assign(out.samples.begin(), out.samples.end());
  }
  if (out.aovs.count("variance")) out.variance = std::move(r.image.variance);
  if (out.aovs.count("light")) out.groups = std::move(r.image.groups);
  out.data = std::move(r.layers.data);
  out.id_manifest = std::move(r.layers.id_manifest);
  out.vector = std::move(r.layers.vector);
  out.velocity = std::move(r.layers.velocity);
  out.wireframe = std::move(r.layers.wireframe);
  out.deep = std::move(r.deep.image);
  return out;
}

namespace {

/// The attributes of a render's EXRs.
ExrOptions render_exr_options(const RenderOutput& out, const ExrWriteOptions& options) {
  const RenderConfig& cfg = out.config;
  ExrOptions exr;
  exr.half = options.half;
  exr.compression = options.compression;
  exr.multipart = options.multipart;
  exr.metadata = {
      {"penumbra:scene", out.scene_file},
      {"penumbra:camera", out.camera.name},
      {"penumbra:spp", std::to_string(cfg.spp)},
      {"penumbra:integrator", out.settings.integrator},
      {"penumbra:filter", std::string(filter_name(cfg.filter.type)) + " " + std::to_string(cfg.filter.width)},
      {"penumbra:version", PENUMBRA_VERSION}};
  exr.metadata.insert(exr.metadata.end(), options.metadata.begin(), options.metadata.end());
  return exr;
}

}  // namespace

void write_render_deep_exr(const RenderOutput& out, const std::filesystem::path& path,
                           const ExrWriteOptions& options) {
  write_deep_exr(out.deep, path, render_exr_options(out, options));
}

void write_render_exr(const RenderOutput& out, const std::filesystem::path& path,
                      const ExrWriteOptions& options) {
  ExrOptions exr = render_exr_options(out, options);
  add_layer_channels(exr, out.aovs,
                     {&out.data, &out.id_manifest, &out.samples_f, &out.variance, &out.groups, &out.vector,
                      &out.velocity, &out.halves, &out.wireframe},
                     options.half ? ChannelType::Half : ChannelType::Float);
  if (out.settings.denoise) {  // the second beauty and the attributes `penumbra denoise` writes
    const bool noisy_main = out.settings.denoise_main == "noisy";
    for (int c = 0; c < 4; ++c)
      exr.extra.push_back({std::string(noisy_main ? "denoised." : "noisy.") + "RGBA"[c], &out.second.rgba,
                           options.half ? ChannelType::Half : ChannelType::Float, 4, c});
    exr.metadata.push_back({kDenoiserAttribute, "nfor"});
    exr.metadata.push_back({kDenoiseMainAttribute, out.settings.denoise_main});
  }
  write_exr(out.film, path, exr);
}

}  // namespace penumbra::python
