// Point sets from files; see point_cloud.h.
#include "io/mesh/point_cloud.h"

#include <algorithm>
#include <cctype>

#include "io/files/points_file.h"
#include "io/mesh/ply_loader.h"

namespace penumbra {

namespace {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

}  // namespace

bool is_point_cloud_file(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".ply" || ext == ".npy" || ext == ".txt" || ext == ".xyz" || ext == ".pts" || ext == ".csv";
}

Scene load_point_cloud(const std::filesystem::path& path, size_t max_points) {
  const std::string ext = lower_extension(path);
  if (ext == ".ply") return load_ply_or_points(path, max_points);
  Scene scene;
  add_world_mesh(scene, make_point_set(ext == ".npy" ? read_npy_points(path.string(), max_points)
                                                     : read_points_file(path.string(), max_points),
                                       path.stem().string()));
  return scene;
}

}  // namespace penumbra
