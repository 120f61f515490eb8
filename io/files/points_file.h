// Point files: plain text (one point per line, three numbers separated by spaces, tabs or
// commas; blank lines and lines starting with '#' skipped) and NumPy .npy arrays of shape
// (N, 3), as query points or as a point set to query (io/mesh/point_cloud.h).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "renderer/core/math.h"

namespace penumbra {

/// The points of `path`. Throws InputError naming the file and the line ("line N") for a line
/// that is not three finite numbers, a file that cannot be read, one with no point, or one
/// with more than `max_points` points.
std::vector<Vec3f> read_points_file(const std::string& path, size_t max_points);

/// The points of a NumPy .npy file: a little-endian float32 or float64 array of shape (N, 3)
/// (or (3,): one point) in C order, format 1.0, 2.0 or 3.0. Throws InputError naming the file
/// and "header" or "row i" for another layout, a truncated file, a non-finite or out-of-float-
/// range value, or more than `max_points` rows.
std::vector<Vec3f> read_npy_points(const std::string& path, size_t max_points);

/// Query points from `path`: .npy files by read_npy_points (recognised by their magic bytes),
/// others by read_points_file.
std::vector<Vec3f> read_query_points(const std::string& path, size_t max_points);

}  // namespace penumbra
