// Point sets from files, for spatial queries: a PLY's vertices, a NumPy .npy array or a text
// file of points, as a scene of one point set (Mesh::points).
#pragma once

#include <cstddef>
#include <filesystem>

#include "renderer/scene/scene.h"

namespace penumbra {

/// True for the files load_point_cloud reads: .ply, .npy, .txt, .xyz, .pts and .csv.
bool is_point_cloud_file(const std::filesystem::path& path);

/// A scene of one point set (make_point_set) from a point file: a PLY's vertices (a PLY with
/// faces gives its mesh), an .npy array (read_npy_points) or a text file (read_points_file), at
/// most `max_points` points. Throws InputError as the readers do.
Scene load_point_cloud(const std::filesystem::path& path, size_t max_points);

}  // namespace penumbra
