// Embree 3 back end of the Accelerator interface: one RTCDevice per process, one triangle
// geometry per mesh (geometry id == mesh index) or per identity instance, Embree instances for
// the other placements; by default the robust scene flag and medium
// build quality (EmbreeConfig).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// Embree scene settings.
struct EmbreeConfig {
  bool robust = true;  ///< RTC_SCENE_FLAG_ROBUST: no cracks on shared edges (slower traversal)
  int quality = 1;     ///< build quality: 0 low, 1 medium (Embree's default), 2 high
  /// A build over instances where some are the identity and some not: true puts the identity
  /// placements in a scene of their own under one identity instance, so that
  /// update_instances() rebuilds a top level of instances only (queries of the identity
  /// placements pass one more level); false keeps them in the top scene, whose triangles an
  /// update then rebuilds too. Chosen by the program (penumbra render sets it for animated
  /// scenes), not an --accel-param.
  bool world_apart = false;
};

/// Throws std::invalid_argument naming the field if a value is out of range.
void validate(const EmbreeConfig& config);

/// Builds an Embree scene over the meshes (data is copied into Embree-owned buffers).
/// Throws std::runtime_error with Embree's message if the device or build fails.
std::unique_ptr<Accelerator> make_embree_accelerator(std::span<const GeometryView> meshes,
                                                     const EmbreeConfig& config = {});

/// Builds an Embree scene over placements of the meshes (geom_id in a Hit = instance index):
/// identity placements as triangle geometries of the top scene (or of a world scene, see
/// EmbreeConfig::world_apart), the others as Embree instances (RTC_GEOMETRY_TYPE_INSTANCE) of
/// one scene per mesh. Instance mesh indices must be valid
/// (the factory checks them). update_instances() sets the Embree instances' transforms and
/// commits the top scene again; the per-mesh scenes are kept.
std::unique_ptr<Accelerator> make_embree_accelerator(std::span<const GeometryView> meshes,
                                                     std::span<const InstanceView> instances,
                                                     const EmbreeConfig& config = {});

/// Embree's collision broad phase: rtcCollide over two scenes of user geometries with one box
/// per primitive (`boxes_a`, `boxes_b`), every pair (index into boxes_a, index into boxes_b)
/// whose boxes Embree reports as overlapping, sorted and without repeats. Throws
/// std::runtime_error if Embree fails.
std::vector<std::pair<uint32_t, uint32_t>> embree_collide(std::span<const Bounds3f> boxes_a,
                                                          std::span<const Bounds3f> boxes_b);

/// The process-wide Embree device's version string (e.g. "3.13.5").
std::string embree_version();

}  // namespace penumbra
