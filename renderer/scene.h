// The scene as plain data: world-space triangle meshes, materials, punctual lights and cameras,
// addressed by int handles. Built by io/ from glTF (or by tests directly); consumed by the
// integrators. No behaviour here beyond small free functions.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "renderer/accel/accelerator.h"
#include "renderer/math.h"

namespace penumbra {

/// glTF metallic-roughness parameters (factors only; textures come later).
struct Material {
  std::string name;
  Vec3f base_color{1, 1, 1};  ///< linear RGB
  float alpha = 1;
  float metallic = 1;   ///< glTF default
  float roughness = 1;  ///< glTF default
  Vec3f emissive{0, 0, 0};  ///< emissiveFactor x KHR_materials_emissive_strength
  bool unlit = false;       ///< KHR_materials_unlit: radiance = base_color, no lighting
};

/// A world-space triangle mesh (one glTF primitive instantiated by one node).
struct Mesh {
  std::string name;                ///< "meshName[prim]" for messages
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;      ///< unit, one per position (computed if the file has none)
  std::vector<Vec2f> uvs;          ///< TEXCOORD_0, empty if absent
  std::vector<uint32_t> indices;   ///< 3 per triangle, counter-clockwise = front
  int material = -1;               ///< index into Scene::materials, -1 = default material
  int node = -1;                   ///< glTF node index, -1 if not from glTF
};

enum class LightType { Point, Spot, Directional };

/// KHR_lights_punctual light in world space. Units as in the glTF spec: point and spot
/// intensity in candela (treated as W/sr in scene-linear units), directional in lux.
struct Light {
  std::string name;
  LightType type = LightType::Point;
  Vec3f color{1, 1, 1};
  float intensity = 1;
  Vec3f position;           ///< point / spot
  Vec3f direction{0, 0, -1};  ///< spot / directional: unit direction the light travels
  float range = kInfinity;  ///< point / spot cut-off distance (spec's smooth window)
  float inner_cone = 0;     ///< spot, radians
  float outer_cone = kPi / 4;  ///< spot, radians
};

enum class Projection { Perspective, Orthographic };

/// A camera in world space: eye and a right-handed orthonormal frame (u right, v up, w back;
/// the camera looks along -w), as glTF places cameras looking down their local -Z.
struct Camera {
  std::string name;
  Projection projection = Projection::Perspective;
  Vec3f eye;
  Vec3f u{1, 0, 0}, v{0, 1, 0}, w{0, 0, 1};
  float yfov = 0.6911f;   ///< perspective: vertical field of view, radians (0.6911 ~ 39.6 deg)
  float aspect = 0;       ///< the file's aspect-ratio hint (width/height); 0 = none
  float xmag = 1, ymag = 1;  ///< orthographic half-extents
  float znear = 0;        ///< clip distances along -w
  float zfar = kInfinity;
};

struct Scene {
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Light> lights;
  std::vector<Camera> cameras;
};

/// World-space bounds of all mesh positions (empty box for an empty scene).
Bounds3f compute_bounds(const Scene& scene);
uint64_t count_triangles(const Scene& scene);
/// Views of every mesh for make_accelerator(); geom_id == mesh index.
std::vector<TriangleMeshView> mesh_views(const Scene& scene);
/// Area-weighted smooth vertex normals of an indexed triangle list (unit; a vertex used by no
/// non-degenerate triangle gets +Z).
std::vector<Vec3f> compute_smooth_normals(std::span<const Vec3f> positions,
                                          std::span<const uint32_t> indices);

}  // namespace penumbra
