// The one ray-query interface of Penumbra. Every back end (Embree, brute force, and the
// reference structures to come) builds from triangle geometry only and answers closest-hit and
// occlusion queries with the same Hit record. Accelerators know nothing of materials or film.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/geometry.h"

namespace penumbra {

/// A read-only view of one triangle mesh in world space. geom_id in a Hit is the index of the
/// mesh in the span given to the builder; prim_id is the triangle index within it.
struct TriangleMeshView {
  std::span<const Vec3f> positions;
  std::span<const uint32_t> indices;  ///< 3 per triangle, each < positions.size()
};

/// Build and size statistics of an accelerator (fields not meaningful for a back end are 0).
struct AccelStats {
  std::string name;
  uint64_t triangles = 0;
  uint64_t nodes = 0;
  uint64_t leaves = 0;
  uint64_t max_depth = 0;
  uint64_t bytes = 0;
  double build_seconds = 0;
};

class Accelerator {
 public:
  virtual ~Accelerator() = default;
  /// Closest hit with t in [ray.tnear, ray.tfar]. Returns hit.valid(). NaN/Inf rays miss.
  /// Thread-safe; never allocates, throws or logs.
  virtual bool intersect(const Ray& ray, Hit& hit) const = 0;
  /// True iff some triangle is hit with t in [ray.tnear, ray.tfar]. Thread-safe.
  virtual bool occluded(const Ray& ray) const = 0;
  virtual Bounds3f bounds() const = 0;
  virtual AccelStats stats() const = 0;
};

/// Names accepted by make_accelerator, default first.
std::vector<std::string> accelerator_names();

/// Builds the named back end over `meshes` (which must outlive the accelerator only for
/// "brute"; Embree copies the data). Throws std::invalid_argument for an unknown name and
/// std::runtime_error if the back end reports an error (message names the back end).
std::unique_ptr<Accelerator> make_accelerator(std::string_view name,
                                              std::span<const TriangleMeshView> meshes);

}  // namespace penumbra
