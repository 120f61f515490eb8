// Embree 3 back end of the Accelerator interface: one RTCDevice per process, one triangle
// geometry per mesh (geometry id == mesh index), robust scene flag, default (medium) build quality.
#pragma once

#include <memory>
#include <span>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// Builds an Embree scene over the meshes (data is copied into Embree-owned buffers).
/// Throws std::runtime_error with Embree's message if the device or build fails.
std::unique_ptr<Accelerator> make_embree_accelerator(std::span<const TriangleMeshView> meshes);

/// The process-wide Embree device's version string (e.g. "3.13.5").
std::string embree_version();

}  // namespace penumbra
