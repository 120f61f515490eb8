// The scene as plain data: triangle meshes, shapes (analytic primitives and implicit surfaces)
// and their instances, materials, image and procedural textures, punctual lights and cameras, addressed by
// int handles. Built by io/ from glTF (or by tests directly); consumed by the integrators. No accelerators
// and no behaviour beyond small free functions (integrators/scene_accel.h builds the accelerator over it).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "renderer/core/math.h"
#include "renderer/core/motion.h"
#include "renderer/procedural/pattern.h"
#include "renderer/scene/splats.h"
#include "renderer/scene/texture.h"
#include "renderer/shapes/shape.h"

namespace penumbra {

/// A material's reference to a texture: which UV set, and KHR_texture_transform's affine map
/// uv' = [m00 m01 m02; m10 m11 m12] (u, v, 1), the identity by default.
struct TextureRef {
  int texture = -1;  ///< index into Scene::textures; -1 = none
  int texcoord = 0;  ///< 0 = TEXCOORD_0, 1 = TEXCOORD_1
  float m[2][3] = {{1, 0, 0}, {0, 1, 0}};
};

enum class AlphaMode : uint8_t { Opaque, Mask, Blend };

/// glTF metallic-roughness material: factors times textures (glTF 2.0 spec 3.9).
/// Colour textures are stored linear (io/ decodes sRGB).
struct Material {
  std::string name;
  Vec3f base_color{1, 1, 1};  ///< linear RGB factor
  float alpha = 1;            ///< baseColorFactor.a
  float metallic = 1;         ///< glTF default
  float roughness = 1;        ///< glTF default
  Vec3f emissive{0, 0, 0};    ///< emissiveFactor x KHR_materials_emissive_strength
  bool unlit = false;         ///< KHR_materials_unlit: radiance = base_color, no lighting
  AlphaMode alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;          ///< Mask: coverage < cutoff is a hole
  bool double_sided = true;           ///< false: back faces are invisible to camera and mirror rays
                                      ///< (glTF's default is false; io/ sets it from the file)
  TextureRef base_color_tex;          ///< RGBA, multiplies base_color and alpha
  TextureRef metallic_roughness_tex;  ///< B = metallic, G = roughness (linear)
  TextureRef normal_tex;              ///< tangent-space normal map (linear)
  float normal_scale = 1;             ///< scales the map's X and Y
  TextureRef occlusion_tex;           ///< R = ambient occlusion (linear)
  float occlusion_strength = 1;       ///< 1 + strength (R - 1)
  TextureRef emissive_tex;            ///< RGB, multiplies emissive
  float ior = 1.5f;                   ///< KHR_materials_ior: dielectric f0 = ((ior-1)/(ior+1))^2
  float specular = 1;                 ///< KHR_materials_specular specularFactor x texture (A)
  Vec3f specular_color{1, 1, 1};      ///< specularColorFactor x texture (RGB, sRGB-decoded)
  TextureRef specular_tex, specular_color_tex;
  float transmission = 0;       ///< KHR_materials_transmission factor
  TextureRef transmission_tex;  ///< R multiplies transmission (linear)
  /// KHR_materials_volume with thicknessFactor > 0: the mesh bounds a volume that transmitted
  /// light refracts into and is absorbed in; false: thin-walled.
  bool volume = false;
  Vec3f attenuation_color{1, 1, 1};        ///< colour white light takes after attenuation_distance
  float attenuation_distance = kInfinity;  ///< world units; infinite: no absorption
  float dispersion = 0;                    ///< KHR_materials_dispersion: 20 / Abbe number
  float clearcoat = 0;                     ///< KHR_materials_clearcoat factor x texture (R)
  float clearcoat_roughness = 0;           ///< x texture (G)
  TextureRef clearcoat_tex, clearcoat_roughness_tex, clearcoat_normal_tex;
  float clearcoat_normal_scale = 1;
  Vec3f sheen_color{0, 0, 0};  ///< KHR_materials_sheen colour factor x texture (RGB)
  float sheen_roughness = 0;   ///< x texture (A)
  TextureRef sheen_color_tex, sheen_roughness_tex;
  float anisotropy = 0;           ///< KHR_materials_anisotropy strength x texture (B)
  float anisotropy_rotation = 0;  ///< radians, counter-clockwise from the tangent
  TextureRef anisotropy_tex;      ///< RG: direction in tangent space, B: strength
  float iridescence = 0;          ///< KHR_materials_iridescence factor x texture (R)
  float iridescence_ior = 1.3f;
  float iridescence_thickness_min = 100, iridescence_thickness_max = 400;  ///< nm, mixed by texture (G)
  TextureRef iridescence_tex, iridescence_thickness_tex;
  float diffuse_transmission = 0;             ///< KHR_materials_diffuse_transmission factor x texture (A)
  Vec3f diffuse_transmission_color{1, 1, 1};  ///< x texture (RGB)
  TextureRef diffuse_transmission_tex, diffuse_transmission_color_tex;
  int procedural = -1;  ///< index into Scene::procedurals (PENUMBRA_procedural), -1 = none
};

/// A triangle mesh (one glTF primitive): in world space when its only instance is the identity
/// (a flattened node), else in the object space its instances place.
struct Mesh {
  std::string name;  ///< "meshName[prim]" for messages
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;     ///< unit, one per position (computed if the file has none)
  std::vector<Vec4f> tangents;    ///< xyz unit tangent along +u, w = +-1 bitangent sign
                                  ///< (bitangent = w cross(n, t)); empty if not needed
  std::vector<Vec2f> uvs;         ///< TEXCOORD_0, empty if absent
  std::vector<Vec2f> uvs1;        ///< TEXCOORD_1, empty if absent
  std::vector<Vec4f> colors;      ///< COLOR_0 as linear RGBA, empty if absent
  std::vector<uint32_t> indices;  ///< 3 per triangle, counter-clockwise = front
  /// A point set (glTF POINTS, a point file): one degenerate triangle (i, i, i) per point, so
  /// that every structure indexes it and the spatial queries measure the points exactly; rays
  /// never hit a degenerate triangle, so it is not rendered.
  bool points = false;
  /// A line set (glTF LINES, LINE_LOOP, LINE_STRIP): one degenerate triangle (a, b, b) per
  /// segment a-b, which triangle code never hits and spatial queries measure exactly.
  bool lines = false;
  /// Points and lines: one radius (>= 0) per position, in the mesh's space. With radii a point
  /// set is rendered as spheres and a line set as capsules about its segments (a segment's
  /// radius is the mean of its ends'); without, they serve spatial queries only.
  std::vector<float> radii;
  /// Points and lines: radii the file gave (PENUMBRA_points), kept; false: the render sets them
  /// from its point size and line width (set_curve_radii).
  bool file_radii = false;
  int material = -1;  ///< index into Scene::materials, -1 = default material
  int node = -1;      ///< glTF node of a flattened mesh, -1 if shared or not from glTF
  /// For a mesh moved into world space from a node: world -> the node's local frame, the object
  /// space of procedural textures (identity otherwise: instances place object-space meshes).
  Affine3f object_from_world;
  /// Deformation motion blur (skins, morph targets): `motion_steps` >= 2 copies of positions
  /// and of normals, step after step, spread evenly over Ray::time 0 to 1 and interpolated
  /// linearly (interpolate_vertex); empty, with motion_steps 0, for a mesh that keeps its shape
  /// over the shutter. positions and normals stay the frame time's pose.
  std::vector<Vec3f> motion_positions, motion_normals;
  uint32_t motion_steps = 0;
};

/// An analytic primitive or an implicit surface in its object space with its material, placed
/// by instances as meshes are.
struct SceneShape {
  std::string name;  ///< for messages: the glTF node's name, or "nodes[i]"
  Shape shape;
  int material = -1;  ///< index into Scene::materials, -1 = default material
  int node = -1;      ///< glTF node that carries it, -1 if not from glTF
};

/// One placement of a mesh or a shape in the world. A Hit's geom_id is an index into
/// Scene::instances. Make them with make_instance() or make_shape_instance() so the inverse and
/// `mirrored` agree with `to_world`.
struct Instance {
  int mesh = 0;           ///< index into Scene::meshes; -1 when the instance places a shape
  int shape = -1;         ///< index into Scene::shapes, or -1 for a mesh instance
  Affine3f to_world;      ///< object to world
  Affine3f to_object;     ///< its inverse
  bool identity = true;   ///< to_world is the identity (the mesh is in world space); false for an
                          ///< instance that animation moves, whatever its map at this time
  bool mirrored = false;  ///< det(to_world) < 0: the front face is clockwise in world space
                          ///< (glTF 3.7.4), i.e. counter-clockwise in object space
  int node = -1;          ///< glTF node, -1 if not from glTF
  int copy = -1;          ///< EXT_mesh_gpu_instancing instance index within the node, else -1
};

enum class LightType { Point, Spot, Directional };

/// KHR_lights_punctual light in world space. Units as in the glTF spec: point and spot
/// intensity in candela (treated as W/sr in scene-linear units), directional in lux.
struct Light {
  std::string name;
  LightType type = LightType::Point;
  Vec3f color{1, 1, 1};
  float intensity = 1;
  Vec3f position;              ///< point / spot
  Vec3f direction{0, 0, -1};   ///< spot / directional: unit direction the light travels
  float range = kInfinity;     ///< point / spot cut-off distance (spec's smooth window)
  float inner_cone = 0;        ///< spot, radians
  float outer_cone = kPi / 4;  ///< spot, radians
};

enum class Projection { Perspective, Orthographic };

/// A thin lens in front of the camera (pbrt-v4's ProjectiveCamera; Kolb et al., "A Realistic
/// Camera Model for Computer Graphics", SIGGRAPH 1995): rays leave a point of the aperture and
/// meet, whatever the point, on the plane at `focus_distance` in front of the camera. A zero
/// radius is a pinhole: no depth of field.
struct ThinLens {
  float radius = 0;          ///< aperture radius in scene units (metres for glTF); 0: pinhole
  float focus_distance = 1;  ///< depth along -w of the plane in focus, > 0
  int blades = 0;            ///< 0: a circular aperture; >= 3: a regular polygon of that many sides
  float rotation = 0;        ///< the polygon's turn about the view axis, radians: its corners lie at
                             ///< rotation + (k + 1/2) 2 pi / blades, as Cycles' blades
  float ratio = 1;           ///< anamorphic squeeze: the aperture's height / width (1: round bokeh)
};

/// A camera in world space: eye and a right-handed orthonormal frame (u right, v up, w back;
/// the camera looks along -w), as glTF places cameras looking down their local -Z.
struct Camera {
  std::string name;
  Projection projection = Projection::Perspective;
  Vec3f eye;
  Vec3f u{1, 0, 0}, v{0, 1, 0}, w{0, 0, 1};
  float yfov = 0.6911f;      ///< perspective: vertical field of view, radians (0.6911 ~ 39.6 deg)
  float aspect = 0;          ///< the file's aspect-ratio hint (width/height); 0 = none
  float xmag = 1, ymag = 1;  ///< orthographic half-extents
  float znear = 0;           ///< clip distances along -w
  float zfar = kInfinity;
  float focal_mm = 0;  ///< the lens' focal length in millimetres when a rig set it; 0: unknown
  ThinLens lens;       ///< depth of field; a pinhole by default
  /// Motion blur: the frame's keys over the shutter (camera_frame maps, spaced evenly over
  /// Ray::time 0 to 1); empty for a camera that stays put. eye, u, v, w are the frame time's.
  std::vector<MotionKey> motion;
};

struct Scene {
  std::vector<Mesh> meshes;
  std::vector<SceneShape> shapes;
  std::vector<Instance> instances;  ///< what is rendered: a mesh without an instance is not
  /// Motion blur: empty (nothing moves), or one entry per instance: its transform's keys spaced
  /// evenly over the shutter (Ray::time 0 to 1), empty for an instance that stays put. A moving
  /// instance's to_world is its map at the frame's time (what the data of a still uses).
  std::vector<std::vector<MotionKey>> instance_motion;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<ProceduralTexture> procedurals;  ///< procedural textures of materials
  std::vector<Light> lights;
  /// Motion blur: empty (no light moves), or up to one entry per light: the light at each motion
  /// step, spaced evenly over the shutter (Ray::time 0 to 1), empty for a light that stays put.
  /// lights[i] is the light at the frame's time.
  std::vector<std::vector<Light>> light_motion;
  std::vector<Camera> cameras;
  /// Gaussian splats (KHR_gaussian_splatting): each primitive's cloud once, placed by instances.
  std::vector<SplatCloud> splat_clouds;
  std::vector<SplatInstance> splat_instances;
};

/// Light `index` at ray time `time`: the scene's own entry when it does not move, else `storage`
/// filled with the two steps around `time` interpolated linearly (position, colour, intensity;
/// the direction normalised after). Never allocates or throws.
const Light& light_at(const Scene& scene, size_t index, float time, Light& storage);

/// Instance `index` where it is at ray time `time`: the scene's own entry when it does not move,
/// else `storage` filled with the interpolated map (interpolate_motion) and its inverse. Never
/// allocates or throws.
const Instance& instance_at(const Scene& scene, uint32_t index, float time, Instance& storage);

/// An instance of `mesh` placed by `to_world`. Throws std::invalid_argument if the map is
/// singular or not finite.
Instance make_instance(int mesh, const Affine3f& to_world, int node = -1);
/// An instance of Scene::shapes[shape] placed by `to_world`; throws as make_instance().
Instance make_shape_instance(int shape, const Affine3f& to_world, int node = -1);
/// The material index (-1 = default) of what the instance places.
inline int instance_material(const Scene& scene, const Instance& inst) {
  return inst.shape >= 0 ? scene.shapes[size_t(inst.shape)].material
                         : scene.meshes[size_t(inst.mesh)].material;
}
/// Appends a world-space mesh with its identity instance; returns the mesh index.
int add_world_mesh(Scene& scene, Mesh mesh);

/// A point or line set that is rendered: Mesh::points or Mesh::lines with a radius per position.
inline bool renders_as_curves(const Mesh& m) {
  return (m.points || m.lines) && !m.radii.empty() && m.radii.size() == m.positions.size();
}

/// A point set mesh (Mesh::points) over `points`: one degenerate triangle (i, i, i) per point,
/// normals +Z, the default material. Requires points.size() < 2^32 / 3.
Mesh make_point_set(std::vector<Vec3f> points, std::string name);

/// World-space bounds of every instance's positions and shapes, and of the placed splats'
/// centres (empty box for an empty scene); exact
/// unless the meshes placed by non-identity instances hold more than `exact_vertex_limit`
/// vertices in all, then each such placement contributes the mapped box of its mesh
/// (conservative, and as cheap for a million placements as for one).
Bounds3f compute_bounds(const Scene& scene, uint64_t exact_vertex_limit = uint64_t(1) << 24);
/// Shapes rendered: each shape counted once per instance.
uint64_t count_shape_instances(const Scene& scene);
/// Triangles rendered: each mesh counted once per instance; point and line sets not.
uint64_t count_triangles(const Scene& scene);
/// Triangles stored: each mesh once, a point set's degenerate triangles (one per point) too, as
/// the acceleration structures store them.
uint64_t count_stored_triangles(const Scene& scene);
/// Points of the placed point sets, each counted once per instance.
uint64_t count_points(const Scene& scene);
/// Segments of the placed line sets, each counted once per instance.
uint64_t count_line_segments(const Scene& scene);

/// Bytes held by the scene's arrays (mesh attributes, shapes, instances, texture pyramids), for
/// memory budgets.
uint64_t scene_memory_bytes(const Scene& scene);
/// Triangle `prim` of mesh instance `inst` in world space: its vertex indices, its world positions
/// and its unit front-facing geometric normal (counter-clockwise side in object space; zero if
/// degenerate).
struct WorldTriangle {
  uint32_t index[3];
  Vec3f p[3];
  Vec3f ng;
};
WorldTriangle world_triangle(const Scene& scene, const Instance& inst, uint32_t prim);
/// The triangle at ray time `time`: a deforming mesh's vertices interpolated at that time (the
/// triangle every structure intersects), else world_triangle(scene, inst, prim).
WorldTriangle world_triangle(const Scene& scene, const Instance& inst, uint32_t prim, float time);
/// Unit vertex normal `i` of `mesh` at ray time `time` (object space): a deforming mesh's
/// normals interpolated at that time and normalised, else normals[i]. The mesh has normals.
Vec3f mesh_normal(const Mesh& mesh, uint32_t i, float time);
/// World-space vertex normal: L^-T n, normalised (n itself for identity instances).
inline Vec3f world_normal(const Instance& inst, Vec3f n) {
  return inst.identity ? n : normalize(apply_normal(inst.to_object, n));
}
/// Area-weighted smooth vertex normals of an indexed triangle list (unit; a vertex used by no
/// non-degenerate triangle gets +Z).
std::vector<Vec3f> compute_smooth_normals(std::span<const Vec3f> positions,
                                          std::span<const uint32_t> indices);
/// Per-vertex tangents for normal mapping from positions, unit normals and the UV set the
/// normal map uses: per-triangle dp/du and dp/dv accumulated (area-weighted) per vertex,
/// Gram-Schmidt orthogonalised against the normal; w = +1 when cross(n, t) points along
/// -dp/dv (glTF's V axis points down the image, so +Y of the map is -v), else -1, which is
/// the MikkTSpace convention for glTF. Vertices without usable UVs get any unit tangent
/// orthogonal to n.
std::vector<Vec4f> compute_tangents(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                                    std::span<const Vec2f> uvs, std::span<const uint32_t> indices);

}  // namespace penumbra
