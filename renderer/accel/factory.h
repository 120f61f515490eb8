// Choosing an acceleration structure by name: the one place that maps "embree", "bvh",
// "kdtree", "grid", "octree", "bsp" and "brute" to their builders, with each builder's configuration.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/accel/accelerator.h"
#include "renderer/accel/bsp.h"
#include "renderer/accel/bvh.h"
#include "renderer/accel/embree.h"
#include "renderer/accel/grid.h"
#include "renderer/accel/kdtree.h"
#include "renderer/accel/octree.h"

namespace penumbra {

/// Build parameters of every back end; only the chosen one's are used.
struct AccelConfig {
  EmbreeConfig embree;
  BvhConfig bvh;
  KdTreeConfig kdtree;
  GridConfig grid;
  OctreeConfig octree;
  BspConfig bsp;
};

/// Names accepted by make_accelerator, default ("embree") first.
std::vector<std::string> accelerator_names();

/// Builds the named back end over `meshes`. Deforming meshes (GeometryView::deforms()) go to
/// Embree's multi-step geometry, or for the other back ends to the time-aware structure of
/// accel/deforming.h under a top level, where they must all have the same motion_steps.
/// Every back end except "brute" copies what it needs; for "brute" the meshes must outlive the
/// accelerator. Throws std::invalid_argument for an unknown name, an invalid configuration or
/// (back ends other than Embree) deforming meshes that differ in motion_steps, std::runtime_error if the
/// build fails (the message names the back end).
std::unique_ptr<Accelerator> make_accelerator(std::string_view name, std::span<const GeometryView> meshes,
                                              const AccelConfig& config = {});

/// Builds the named back end over placements of `meshes`; a Hit's geom_id is the instance index.
/// Embree uses its own instances; the other back ends go through the two-level wrapper of
/// accel/instances.h with one structure of that back end per level. When every instance is the
/// identity (a flattened scene) this is exactly the single-level build over the instances'
/// meshes. Throws as above, and std::invalid_argument if an instance names a mesh outside
/// `meshes`.
std::unique_ptr<Accelerator> make_accelerator(std::string_view name, std::span<const GeometryView> meshes,
                                              std::span<const InstanceView> instances,
                                              const AccelConfig& config = {});

/// What refit_or_rebuild() did to a structure.
struct RefitReport {
  bool refitted = false;  ///< false: built anew
  double growth = 0;      ///< the refitted SAH cost over the last build's (0: not refitted)
  std::string reason;     ///< why it was built anew (empty when refitted)
};

/// The rebuild policy of animation. `accel` was made by make_accelerator(name, ...) over an
/// earlier pose of the same meshes and instances (same counts, meshes, kinds and triangle
/// counts), and `built_sah` is its SAH cost when it was last built (stats().sah_cost). Refits it
/// to the new pose when the back end can (the BVH, alone or under instances) and
/// config.bvh.refit_max_growth is not 0, and keeps it while its SAH cost is at most that factor
/// of `built_sah`; otherwise, and always when a mesh deforms, builds it anew (updating
/// `built_sah`). The answers are those of a
/// fresh build either way. Throws as make_accelerator does.
RefitReport refit_or_rebuild(std::unique_ptr<Accelerator>& accel, double& built_sah, std::string_view name,
                             std::span<const GeometryView> meshes, std::span<const InstanceView> instances,
                             const AccelConfig& config = {});

}  // namespace penumbra
