// The statistics JSON of a render.
#include "apps/penumbra/stats_json.h"

#include <nlohmann/json.hpp>

#include "apps/penumbra/cli_support.h"
#include "io/files/atomic_file.h"

namespace penumbra::cli {

std::string stats_json_text(const RenderReport& r, const std::vector<WrittenImage>& written) {
  const RenderStats& stats = r.image.stats;
  const Scene& scene = r.scene;
  nlohmann::ordered_json j;
  j["version"] = PENUMBRA_VERSION;
  j["scene"] = r.scene_file;
  j["output"] = written.front().path;
  for (const WrittenImage& w : written) j["outputs"][w.key] = {{"path", w.path}, {"sha256", w.sha256}};
  j["integrator"] = r.prepared.spec.integrator;
  j["width"] = r.prepared.config.width;
  j["height"] = r.prepared.config.height;
  const Film& f = r.image.film;
  j["window"] = {f.origin_x, f.origin_y, f.origin_x + f.width, f.origin_y + f.height};
  j["spp"] = r.prepared.config.spp;
  j["mean_spp"] = r.mean_spp;
  j["passes"] = stats.passes;
  j["time_limited"] = stats.time_limited;
  j["interrupted"] = r.interrupted;
  j["threads"] = stats.threads;
  j["accelerator"] = r.prepared.spec.accel;
  j["accelerator_update"] = r.structure_update;
  j["seconds"] = {{"load", r.load_s}, {"build", r.build_s}, {"render", stats.seconds}, {"write", r.write_s}};
  if (r.deep) {
    j["seconds"]["deep"] = r.deep_s;
    j["seconds"]["deep_write"] = r.deep_write_s;
    j["deep_samples"] = r.deep_samples;
  }
  j["rays"] = {{"camera", stats.rays.camera},
               {"shadow", stats.rays.shadow},
               {r.prepared.spec.integrator == "path" ? "bounce" : "reflection", stats.rays.reflection},
               {"total", stats.rays.total()}};
  j["mrays_per_second"] = stats.seconds > 0 ? double(stats.rays.total()) / stats.seconds / 1e6 : 0.0;
  j["peak_memory_mib"] = peak_memory_mib();
  j["triangles"] = count_triangles(scene);
  j["shapes"] = count_shape_instances(scene);
  j["instances"] = scene.instances.size();
  j["lights"] = scene.lights.size();
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

void write_stats_json(const RenderReport& report, const std::vector<WrittenImage>& written,
                      const std::string& path) {
  const std::string text = stats_json_text(report, written);
  write_atomically(path, [&](const std::filesystem::path& temp) {
    write_file_checked(temp, text.data(), text.size(), path);
  });
}

}  // namespace penumbra::cli
