// Proxies of a scene's nodes: the world-space geometry each glTF node (or node subtree) places,
// the tightness of a proxy fitted to it, and the proxy as renderable shapes (analytic shapes for
// spheres, boxes and capsules; implicit convex polyhedra for hulls and k-DOPs; triangle meshes
// for hulls with more faces than a convex polyhedron holds).
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "renderer/collision/proxy.h"
#include "renderer/collision/shape_triangles.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// What one glTF node (alone or with its descendants) places, in world space.
struct NodeGeometry {
  int node = -1;                    ///< the glTF node (a subtree's root)
  std::vector<DVec3> points;        ///< every placed vertex (point sets' points included)
  std::vector<uint32_t> triangles;  ///< 3 per triangle into points (point sets' (i, i, i) left out)
  std::vector<Vec3f> positions;     ///< points in single precision, for a query structure
  std::vector<uint32_t> measured;   ///< triangles and point sets' (i, i, i): what distances are measured to
  /// The enclosed volume of the placed meshes (each closed mesh's MeshVolume x |det| of its
  /// placement, summed); NaN when some placed mesh is not closed or is a point set.
  double enclosed_volume = NAN;
  uint64_t instances = 0;  ///< mesh and shape instances gathered
  uint64_t shapes = 0;     ///< of those, shapes (as shape_triangles)
  /// The shapes' tessellations lie within this distance of their true surfaces (each one's
  /// ShapeTriangles::error times its placement's largest stretch, bounded by the Frobenius norm).
  double shape_error = 0;
  /// Per gathered mesh instance, where its triangles start in `triangles` (3 indices each); a
  /// last entry holds the end.
  std::vector<size_t> instance_triangles{0};
  std::vector<Affine3f> instance_to_world;  ///< per gathered instance, its placement
};

/// True if `node` is `ancestor` or lies below it (`parents`: each glTF node's parent, -1 for a
/// root; parent links are followed at most once per node, so a cycle ends).
bool node_in_subtree(int node, int ancestor, std::span<const int> parents);

/// How a file's glTF nodes are joined: by the hierarchy and by skins.
struct NodeLinks {
  std::span<const int> parents;                   ///< each node's parent, -1 for a root
  std::span<const std::vector<int>> skin_joints;  ///< per node, the joints of its skin (empty: none)
};

/// True if the file joins nodes a and b: one lies below the other, or a skin joins them (a
/// skinned node and a node at or below one of its skin's joints, or two skinned nodes whose
/// skins share a joint). Their contact is by design (a character's hand and the sword its hand
/// bone carries, a body and the clothes skinned to its skeleton).
bool nodes_joined(int a, int b, const NodeLinks& links);

/// The geometry of each node that places a mesh or a shape (`root` < 0; instances not from glTF
/// are left out), or of the subtree under node `root` as one entry (empty if it places
/// neither). Shapes are taken as their shape_triangles(shape, `shapes`). `node_parents` holds
/// each glTF node's parent (-1 for a root). Throws std::invalid_argument naming the node and
/// the shape if a shape cannot be tessellated (an unbounded implicit shape).
std::vector<NodeGeometry> node_geometry(const Scene& scene, std::span<const int> node_parents, int root,
                                        const ShapeTrianglesConfig& shapes = {});

/// What node_geometry gathers over the whole scene (meshes' vertices and triangles, shapes'
/// shape_triangles_count), for memory budgets.
ShapeTrianglesCount placed_geometry_count(const Scene& scene, const ShapeTrianglesConfig& shapes = {});

/// How tight a proxy is around its node's geometry.
struct ProxyTightness {
  double proxy_volume = 0;
  double mesh_volume = NAN;   ///< NodeGeometry::enclosed_volume
  double volume_ratio = NAN;  ///< proxy_volume / mesh_volume; NaN when the mesh is open
  double hull_ratio = NAN;    ///< proxy_volume / the convex hull's volume (defined for open meshes)
  /// The one-sided Hausdorff distance from the proxy's surface to the geometry: the largest
  /// distance from a sample of the proxy's surface to the nearest triangle or point (a lower
  /// bound on the true value, which the samples approach). The other side is 0: the proxy
  /// holds the geometry.
  double hausdorff = 0;
  uint64_t samples = 0;  ///< surface samples measured
};

/// Measures `proxy` against `geometry` with `samples` surface samples (fixed seed) on `threads`
/// workers (0: all cores); the same result for any thread count. `hull_volume` (the geometry's
/// convex hull volume, or NaN) gives hull_ratio.
ProxyTightness proxy_tightness(const Proxy& proxy, const NodeGeometry& geometry, size_t samples, int threads,
                               double hull_volume);

/// What fit_scene_proxies fits.
struct SceneProxyConfig {
  ProxyKind kind = ProxyKind::Obb;
  int root = -1;           ///< a glTF node: one proxy for its subtree; -1: one per node placing a mesh
  ProxyConfig fit;         ///< the fitting's parameters
  size_t samples = 20000;  ///< surface samples of the Hausdorff distance (0: not measured)
  int threads = 0;         ///< workers of the distance queries (0: all cores)
};

/// One node's proxy and its tightness.
struct NodeProxy {
  int node = -1;
  uint64_t vertices = 0, triangles = 0;  ///< of the geometry it was fitted to
  Proxy proxy;
  ProxyTightness tightness;
};

/// Fits config.kind to each node's geometry (node_geometry) and measures it. Throws
/// std::invalid_argument naming the node ("node 3: ...") if its geometry cannot be fitted
/// (a non-finite vertex).
std::vector<NodeProxy> fit_scene_proxies(const Scene& scene, std::span<const int> node_parents,
                                         const SceneProxyConfig& config);

/// Faces of the largest convex part written as a convexPolyhedron shape: sphere tracing
/// evaluates every plane at every step, so larger hulls render far faster as triangles.
inline constexpr size_t kMaxProxyPlanes = 256;

/// Appends `proxy` to `scene` as shapes placed in world space with `material`, named `name`:
/// sphere -> a Sphere, box -> a Box rotated into the box's axes, capsule -> a Capsule whose +Y
/// follows its segment, each convex part -> an implicit convexPolyhedron (or a triangle mesh
/// when it has more than kMaxProxyPlanes faces). Throws std::invalid_argument if a proxy is
/// degenerate (zero radius or a zero box side: widened to 1e-6 of its size first).
void append_proxy_shapes(Scene& scene, const Proxy& proxy, int material, const std::string& name, int node);

}  // namespace penumbra
