// Brute-force back end: a linear scan over every triangle and shape with the shared tests
// (the watertight triangle test, the per-kind shape test).
// The oracle for accelerator tests; O(N) per ray, never use it for real renders.
#pragma once

#include <memory>
#include <span>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// The views' data (mesh arrays and shapes) is referenced, not copied: it must outlive the
/// accelerator.
std::unique_ptr<Accelerator> make_brute_accelerator(std::span<const GeometryView> meshes);

}  // namespace penumbra
