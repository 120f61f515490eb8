// Query points from a plain text file: one point per line, three numbers separated by spaces,
// tabs or commas; blank lines and lines starting with '#' are skipped.
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

}  // namespace penumbra
