// Spatial queries on a loaded scene (renderer/accel/query.h over the scene's geometry), with
// what the scene knows of each answer: the glTF node, the mesh or shape and the material. What
// `penumbra query` and the Python module both call.
#pragma once

#include <vector>

#include "renderer/accel/query.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// The views a scene's structure is built over (mesh_views, instance_views: geom_id = instance
/// index), pointing into the scene, which must outlive them.
struct SceneGeometry {
  std::vector<GeometryView> meshes;
  std::vector<InstanceView> instances;
  QueryScene view() const { return {meshes, instances}; }
};

SceneGeometry scene_geometry(const Scene& scene);

/// The scene element behind an answer's geom_id (an instance index).
struct MatchOwner {
  int instance = -1;
  int node = -1;      ///< glTF node, -1 if none
  int mesh = -1;      ///< index into Scene::meshes, -1 for a shape
  int shape = -1;     ///< index into Scene::shapes, -1 for a mesh
  int material = -1;  ///< index into Scene::materials, -1: the default material
};

/// The owner of instance `geom_id`; all -1 for an id the scene does not have.
MatchOwner match_owner(const Scene& scene, uint32_t geom_id);

}  // namespace penumbra
