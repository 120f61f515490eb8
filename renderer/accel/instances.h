// Two-level instancing for the back ends that have none of their own (bvh, kdtree, grid,
// brute): object-space structures per mesh under a top-level BVH over the instances.
#pragma once

// One structure per instanced mesh in object space, one over everything placed by the
// identity in world space, and a top-level BVH over the instances' world bounds whose leaves
// carry the ray into object space (pbrt-v4's TransformedPrimitive; Wald et al., "Distributed
// Interactive Ray Tracing of Dynamic Scenes", IEEE PVG 2003, for the two-level scheme).

#include <functional>
#include <memory>
#include <span>

#include "renderer/accel/accelerator.h"
#include "renderer/accel/deforming.h"

namespace penumbra {

/// Builds one back end's structure over some meshes (geom_id = index in the span).
using AcceleratorBuilder = std::function<std::unique_ptr<Accelerator>(std::span<const GeometryView>)>;

/// Two-level structure over `instances` of `meshes` (views of meshes or shapes); a Hit's geom_id
/// is the instance index and its t is measured along the world ray (object-space rays keep the
/// parameterisation: the direction is mapped, not normalised). `build` makes every bottom level:
/// one per mesh used by a non-identity instance, and one over the identity instances' views
/// (built even when empty). A shape placed by a non-identity instance has no bottom level: the
/// top level's leaf maps the ray and calls the shape test itself. A deforming mesh
/// (GeometryView::deforms()) gets the structure of accel/deforming.h with `deforming`'s
/// parameters instead of `build`'s, placed under the top level even by the identity, its box
/// that of the whole shutter; deforming meshes must all have the same motion_steps. With moving
/// instances (InstanceView::motion) the top level keeps its boxes per time segment (eight over
/// the shutter; up to 32 MiB of them, else the shutter's) and a ray walks its time's. Instances
/// with a singular or non-finite map are left out. Throws std::invalid_argument if an instance
/// names a mesh outside `meshes` or deforming meshes differ in motion_steps, and whatever `build`
/// throws. update_instances() keeps every bottom level and builds the top level again over the
/// instances' new world boxes; refit_instances() declines (returns false) when a level deforms.
std::unique_ptr<Accelerator> make_two_level_accelerator(const AcceleratorBuilder& build,
                                                        std::span<const GeometryView> meshes,
                                                        std::span<const InstanceView> instances,
                                                        const DeformingConfig& deforming = {});

/// Throws std::invalid_argument naming the instance if it refers to a mesh outside `mesh_count`.
void validate_instances(std::span<const InstanceView> instances, size_t mesh_count);

}  // namespace penumbra
