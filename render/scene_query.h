// Spatial queries on a loaded scene (renderer/accel/query.h over the scene's geometry), with
// what the scene knows of each answer: the glTF node, the mesh or shape and the material; the
// structure a session keeps for them; and picking, what a camera sees through a pixel. What
// `penumbra query` and the Python module both call.
#pragma once

#include <string>
#include <vector>

#include "render/session.h"
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

/// The glTF node `spec` names: an index below info.node_count, or a unique node name. Returns -1
/// with `error` set ("<file> has 4 nodes (0 to 3)", "several nodes of <file> have this name
/// (nodes 1 and 5); give its index", "<file> has no node of that name") otherwise.
int find_node(const GltfInfo& info, const std::string& spec, const std::string& file, std::string& error);

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

/// The session's structure for spec.accel and spec.accel_params over its scene, as render_scene
/// builds it (the kept one when the name and parameters match, else built and kept in its place).
/// Call with session.mutex held. Throws std::invalid_argument for bad parameters.
const Accelerator& query_structure(Session& session, const RenderSpec& spec);

/// What a camera sees through the centre of one pixel.
struct Pick {
  bool hit = false;
  Ray ray;                  ///< the pinhole camera ray through (x + 0.5, y + 0.5)
  PrimitiveMatch match;     ///< distance along the ray (ray.dir is unit), world point, u, v and ids
  MatchOwner owner;         ///< all -1 on a miss
  float depth = kInfinity;  ///< the hit's depth along the view axis (the Z AOV's measure)
  Vec3f normal;             ///< unit geometric normal facing the camera
};

/// The first visible surface on the camera ray through the centre of pixel (x, y) of a width x
/// height image: alpha-masked texels and the back faces of single-sided materials are skipped as
/// the renderer's camera rays skip them (intersect_visible), Blend surfaces count. The ray is the
/// pinhole one (the surface in focus under a thin lens) at the shutter's middle. Requires
/// 0 <= x < width, 0 <= y < height and a camera validate_camera accepts for that size.
Pick pick(const Scene& scene, const Accelerator& accel, const Camera& camera, int width, int height, int x,
          int y);

}  // namespace penumbra
