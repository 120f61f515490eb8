// Brute-force back end: a linear scan over every triangle with the shared watertight test.
// The oracle for accelerator tests; O(N) per ray, never use it for real renders.
#pragma once

#include <memory>
#include <span>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// The meshes' data is referenced, not copied: it must outlive the accelerator.
std::unique_ptr<Accelerator> make_brute_accelerator(std::span<const TriangleMeshView> meshes);

}  // namespace penumbra
