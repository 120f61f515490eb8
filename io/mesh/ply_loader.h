// PLY (Stanford polygon file format) loading: ASCII and binary little/big-endian files with a
// "vertex" element (float or double x, y, z) and a "face" element (a vertex_indices or
// vertex_index list). Polygons are triangulated as fans. Other elements and properties are
// skipped. Used to bring the Stanford models into the benchmark, and as point sets for spatial
// queries; writes nothing.
#pragma once

#include <cstdint>
#include <filesystem>

#include "renderer/scene/scene.h"

namespace penumbra {

/// Largest PLY file read (the Stanford dragon in binary is 20 MiB; a billion triangles fits).
inline constexpr uint64_t kMaxPlyBytes = uint64_t(32) << 30;

/// Loads `file` as one mesh (no materials, lights or cameras). Throws InputError naming the
/// file and the element ("face[812]: index 9312 >= vertex count 4000", "header line 3: ...")
/// for anything malformed: unknown format, truncated data, non-finite coordinates, out-of-range
/// indices, counts over 2^31.
Scene load_ply(const std::filesystem::path& file);

/// load_ply, except that a file without faces (no face element, or one with no polygons) gives
/// a point set of its vertices (make_point_set) instead of an error; refused past `max_points`
/// vertices.
Scene load_ply_or_points(const std::filesystem::path& file, size_t max_points);

}  // namespace penumbra
