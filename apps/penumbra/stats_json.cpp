// The statistics JSON of a render.
#include "apps/penumbra/stats_json.h"

#include <nlohmann/json.hpp>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/render_job.h"
#include "io/files/atomic_file.h"

namespace penumbra::cli {

std::string stats_json_text(const RenderJob& job) {
  const RenderArgs& a = job.args;
  const RenderRequest& q = job.request;
  const RenderStats& stats = job.image.stats;
  const Scene& scene = job.loaded.scene;
  nlohmann::ordered_json j;
  j["version"] = PENUMBRA_VERSION;
  j["scene"] = a.scene_file;
  j["output"] = q.out.string();
  j["outputs"]["exr"] = {{"path", q.out.string()}, {"sha256", job.hashes.exr}};
  if (q.png) j["outputs"]["png"] = {{"path", q.png->string()}, {"sha256", job.hashes.png}};
  if (q.cost_png)
    j["outputs"]["cost_png"] = {{"path", q.cost_png->string()}, {"sha256", job.hashes.cost_png}};
  j["integrator"] = a.spec.integrator;
  j["width"] = job.prepared.config.width;
  j["height"] = job.prepared.config.height;
  const Film& f = job.image.film;
  j["window"] = {f.origin_x, f.origin_y, f.origin_x + f.width, f.origin_y + f.height};
  j["spp"] = job.prepared.config.spp;
  j["mean_spp"] = job.mean_spp;
  j["passes"] = stats.passes;
  j["time_limited"] = stats.time_limited;
  j["interrupted"] = job.interrupted != 0;
  j["threads"] = stats.threads;
  j["accelerator"] = a.spec.accel;
  j["accelerator_update"] = job.structure.update;
  j["seconds"] = {
      {"load", job.load_s}, {"build", job.build_s}, {"render", stats.seconds}, {"write", job.write_s}};
  j["rays"] = {{"camera", stats.rays.camera},
               {"shadow", stats.rays.shadow},
               {q.path ? "bounce" : "reflection", stats.rays.reflection},
               {"total", stats.rays.total()}};
  j["mrays_per_second"] = stats.seconds > 0 ? double(stats.rays.total()) / stats.seconds / 1e6 : 0.0;
  j["peak_memory_mib"] = peak_memory_mib();
  j["triangles"] = count_triangles(scene);
  j["shapes"] = count_shape_instances(scene);
  j["instances"] = scene.instances.size();
  j["lights"] = scene.lights.size();
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

void write_stats_json(const RenderJob& job) {
  const std::string text = stats_json_text(job);
  const std::string& path = job.args.stats_json;
  write_atomically(path, [&](const std::filesystem::path& temp) {
    write_file_checked(temp, text.data(), text.size(), path);
  });
}

}  // namespace penumbra::cli
