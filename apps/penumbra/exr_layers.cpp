// EXR metadata and AOV layers of a render.
#include "apps/penumbra/exr_layers.h"

#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/render_job.h"
#include "io/files/error.h"
#include "io/gltf/id_manifest.h"
#include "io/image/exr_merge.h"
#include "render/exr_layers.h"
#include "renderer/integrators/light_groups.h"
#include "renderer/integrators/raster.h"

namespace penumbra::cli {

namespace fs = std::filesystem;

namespace {

/// Cryptomatte channels ({layer}00.R = rank 0 id, .G its coverage, .B rank 1 id, .A its coverage,
/// then {layer}01, ...: always 32-bit float) and the cryptomatte/<key>/ attributes.
void add_crypto_channels(ExrOptions& exr, const RenderJob& job, LayerBuffers& buffers) {
  const CryptoImage& img = buffers.layers.crypto;
  for (size_t l = 0; l < job.request.crypto.size(); ++l) {
    const std::string& layer = job.request.crypto[l];
    for (int group = 0; group < img.channels / 4; ++group)
      for (int c = 0; c < 4; ++c)
        exr.extra.push_back({format("%s%02d.", layer.c_str(), group) + "RGBA"[c], &img.layers[l],
                             ChannelType::Float, img.channels, group * 4 + c});
    const std::string key = "cryptomatte/" + crypto_key(layer) + "/";
    exr.metadata.push_back({key + "name", layer});
    exr.metadata.push_back({key + "hash", "MurmurHash3_32"});
    exr.metadata.push_back({key + "conversion", "uint32_to_float32"});
    const std::string& manifest = buffers.layers.crypto_manifests[l];
    if (manifest.size() <= kInlineManifestBytes || job.request.out_streams) {
      exr.metadata.push_back({key + "manifest", manifest});
    } else {
      const fs::path sidecar = crypto_sidecar_path(job.request.out, layer);
      exr.metadata.push_back({key + "manif_file", sidecar.filename().string()});
      buffers.sidecars.push_back({sidecar, manifest});
    }
  }
}

/// OpenEXR's standard camera attributes (row vectors, p' = p M; camera space looks down -Z):
/// worldToCamera, and worldToNDC mapping the image to x, y in [-1, 1] (y up) after the
/// homogeneous divide, as Nuke reads them; plus the field of view and clip distances.
void add_camera_metadata(ExrOptions& exr, const Camera& cam, int width, int height) {
  const Vec3f u = cam.u, v = cam.v, w = cam.w, e = cam.eye;
  const std::array<float, 16> w2c = {u.x, v.x, w.x, 0, u.y,        v.y,        w.y,        0,
                                     u.z, v.z, w.z, 0, -dot(e, u), -dot(e, v), -dot(e, w), 1};
  const float aspect = float(width) / float(height);
  std::array<float, 16> proj{};  // camera space -> clip space (row vectors)
  if (cam.projection == Projection::Perspective) {
    const float ty = std::tan(0.5f * cam.yfov), tx = ty * aspect;
    proj = {1 / tx, 0, 0, 0, 0, 1 / ty, 0, 0, 0, 0, -1, -1, 0, 0, 0, 0};
  } else {
    proj = {1 / (cam.ymag * aspect), 0, 0, 0, 0, 1 / cam.ymag, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1};
  }
  std::array<float, 16> w2ndc{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k)
        w2ndc[size_t(r * 4 + c)] += w2c[size_t(r * 4 + k)] * proj[size_t(k * 4 + c)];
  exr.matrix_metadata.push_back({"worldToCamera", w2c});
  exr.matrix_metadata.push_back({"worldToNDC", w2ndc});
  if (cam.projection == Projection::Perspective) {
    exr.float_metadata.push_back({"penumbra:yfov_degrees", cam.yfov * 180 / kPi});
    exr.float_metadata.push_back(
        {"penumbra:xfov_degrees", 2 * std::atan(std::tan(0.5f * cam.yfov) * aspect) * 180 / kPi});
  }
  exr.float_metadata.push_back({"penumbra:near", cam.znear});
  exr.float_metadata.push_back(
      {"penumbra:far", std::isfinite(cam.zfar) ? cam.zfar : std::numeric_limits<float>::max()});
}

/// Crops and tiles carry their render's identity: merge accepts only parts of one render.
void add_part_identity(ExrOptions& exr, const RenderJob& job) {
  RenderSettings part = job.prepared.identity;
  part.entries["spp"] = std::to_string(job.prepared.config.spp);
  part.entries["complete"] = job.frame_complete ? "1" : "0";  // all requested samples taken
  std::string layers;
  for (const auto& name : job.request.aovs) layers += (layers.empty() ? "" : ",") + name;
  part.entries["aovs"] = layers;
  if (!job.request.crypto.empty()) part.entries["crypto_depth"] = std::to_string(job.request.crypto_depth);
  exr.metadata.push_back({kSceneHashAttribute, job.scene_sha256});
  exr.metadata.push_back({kSettingsAttribute, canonical_text(part)});
}

/// The data AOVs and the path tracer's layers (render/exr_layers.h), then the cost layers.
void add_render_channels(ExrOptions& exr, const RenderJob& job, LayerBuffers& buffers) {
  const RenderImage& image = job.image;
  if (job.request.aovs.count("samples")) buffers.samples.assign(image.samples.begin(), image.samples.end());
  add_layer_channels(
      exr, job.request.aovs,
      {&buffers.layers.data, &buffers.layers.id_manifest, &buffers.samples, &image.variance, &image.groups,
       &buffers.layers.vector, &buffers.layers.velocity, &image.halves, &buffers.layers.wireframe},
      job.args.use_float ? ChannelType::Float : ChannelType::Half);
  if (job.request.cost_aov) {
    if (buffers.layers.cost.counted) {
      exr.extra.push_back({"cost_nodes.X", &buffers.layers.cost.nodes});
      exr.extra.push_back({"cost_triangles.X", &buffers.layers.cost.triangles});
      exr.extra.push_back({"cost_shapes.X", &buffers.layers.cost.shapes});
    }
    exr.extra.push_back({"cost_ns.X", &buffers.layers.cost.nanoseconds});
  }
}

}  // namespace

fs::path crypto_sidecar_path(const fs::path& exr, const std::string& layer) {
  return fs::path(exr).replace_extension("." + layer + ".json");
}

ExrOptions make_exr_options(const RenderJob& job, LayerBuffers& buffers) {
  const RenderArgs& a = job.args;
  const RenderConfig& cfg = job.prepared.config;
  ExrOptions exr;
  exr.half = !a.use_float;
  exr.compression = a.compression;
  exr.multipart = a.multipart;
  exr.metadata = {{"penumbra:scene", a.scene_file},
                  {"penumbra:camera", job.prepared.camera.name},
                  {"penumbra:spp", std::to_string(cfg.spp)},
                  {"penumbra:integrator", a.spec.integrator},
                  {"penumbra:filter",
                   std::string(filter_name(cfg.filter.type)) + " " + std::to_string(cfg.filter.width)}};
  if (job.request.path) {
    exr.metadata.push_back(
        {kMeanSppAttribute, format_mean_spp(job.image.stats.samples, uint64_t(job.image.film.width) *
                                                                         uint64_t(job.image.film.height))});
    exr.metadata.push_back({kSamplesAttribute, std::to_string(job.image.stats.samples)});
    exr.metadata.push_back({kPassesAttribute, std::to_string(job.image.stats.image_passes)});
  }
  add_part_identity(exr, job);
  if (!a.reproducible) exr.metadata.push_back({"penumbra:command_line", a.command_line});
  // OpenImageIO stamps the time of writing into capDate unless DateTime is given; reproducible
  // files carry it empty.
  if (a.reproducible) exr.metadata.push_back({"DateTime", ""});
  exr.metadata.push_back({"penumbra:version", PENUMBRA_VERSION});
  add_camera_metadata(exr, job.prepared.camera, cfg.width, cfg.height);
  if (!a.reproducible)
    exr.float_metadata.push_back({kRenderSecondsAttribute, float(job.image.stats.seconds)});
  add_render_channels(exr, job, buffers);
  add_crypto_channels(exr, job, buffers);
  // The display transform its display image is (or, for --no-png and farm stripes, would be)
  // made with, so that a frame's EXR is the same however it was rendered. Without a display
  // image an unusable config is no error: the attributes are left out.
  try {
    for (auto& kv : display_metadata(describe_display(job.request.display))) exr.metadata.push_back(kv);
  } catch (const InputError&) {
    if (job.request.png) throw;
  }
  return exr;
}

}  // namespace penumbra::cli
