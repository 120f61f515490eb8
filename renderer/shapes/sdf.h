// Implicit surfaces as signed distance functions (f < 0 inside, f = 0 on the surface): SDF
// primitives in canonical local frames, CSG trees over them (union, intersection, subtraction,
// complement and their smooth variants, displacement by fractal noise), each node with its own
// transform, a Lipschitz bound per tree, and sphere tracing (Hart, "Sphere tracing: a geometric method for
// the antialiased ray tracing of implicit surfaces", The Visual Computer 12(10), 1996). Plain data and free
// functions; evaluation never allocates, throws or logs.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer/core/geometry.h"
#include "renderer/core/math.h"
#include "renderer/procedural/noise.h"
#include "renderer/shapes/solid_bsp.h"

namespace penumbra {

/// What an SdfNode is. Primitives are centred at the local origin, axis of symmetry +Y.
enum class SdfKind : uint8_t {
  Sphere,              ///< radius = size.x
  Box,                 ///< half extents = size
  RoundBox,            ///< half extents = size (outer), edge radius = radius (<= min half extent)
  Capsule,             ///< segment from -size.y to +size.y on Y, radius = radius
  Cylinder,            ///< radius = radius, half height = size.y, capped
  Cone,                ///< base radius = radius at y = -size.y, apex at y = +size.y
  Torus,               ///< major radius = size.x in the XZ plane, minor radius = radius
  HalfSpace,           ///< dot(normal, p) - offset <= 0 inside; normal is unit
  ConvexPolyhedron,    ///< intersection of half-spaces planes[first_plane, first_plane + plane_count)
  Polyhedron,          ///< the closed mesh SdfTree::polyhedra[polyhedron], concave or not: the exact
                       ///< distance to its triangles, negated inside its solid BSP
  Union,               ///< min(a, b)
  Intersection,        ///< max(a, b)
  Subtraction,         ///< a minus b: max(a, -b)
  Complement,          ///< -a
  SmoothUnion,         ///< polynomial smooth minimum of a and b with blend radius `radius`
  SmoothIntersection,  ///< smooth maximum of a and b
  SmoothSubtraction,   ///< smooth maximum of a and -b
  Displace,            ///< a + amplitude x fractal_noise(frequency x p), with the noise of
                       ///< SdfTree::displacements[displacement]
};

/// True for the operators (nodes with children).
bool is_operator(SdfKind kind);

/// True for the operators with one child (a): Complement and Displace.
bool is_unary(SdfKind kind);

/// The noise a Displace node adds to its child: amplitude x fractal_noise(table, frequency x p,
/// params) at the node's local point p. |fractal_noise| <= 1, so the displaced surface lies
/// within |amplitude| of the child's (in the child's value).
struct SdfDisplacement {
  PerlinTable table;     ///< make_perlin_table(seed)
  FractalParams params;  ///< the fractal sum (kind, octaves, distortion)
  float amplitude = 0;   ///< any finite value; 0 gives the child exactly, < 0 inverts the relief
  float frequency = 1;   ///< > 0: the noise's lattice cells are 1 / frequency wide
};

struct SdfNode {
  SdfKind kind = SdfKind::Sphere;
  Vec3f size{1, 1, 1};                   ///< per-kind extents (see SdfKind)
  float radius = 0;                      ///< per-kind radius; the blend radius (> 0) of smooth operators
  Vec3f normal{0, 1, 0};                 ///< HalfSpace
  float offset = 0;                      ///< HalfSpace
  int first_plane = 0, plane_count = 0;  ///< ConvexPolyhedron: range in SdfTree::planes
  int a = -1, b = -1;                    ///< operator children (unary operators use a only)
  int displacement = -1;                 ///< Displace: index into SdfTree::displacements
  int polyhedron = -1;                   ///< Polyhedron: index into SdfTree::polyhedra
  /// Maps the parent's frame (the tree's frame at the root) into this node's local frame.
  Affine3f to_local;
};

/// A CSG tree: nodes addressed by index, children before or after their parents.
struct SdfTree {
  std::vector<SdfNode> nodes;
  std::vector<Vec4f> planes;                   ///< (unit normal, offset) of ConvexPolyhedron faces
  std::vector<SdfDisplacement> displacements;  ///< the noise of Displace nodes
  std::vector<SolidMesh> polyhedra;            ///< the meshes of Polyhedron nodes (build_solid_mesh)
  int root = -1;
};

/// Most planes a ConvexPolyhedron node holds (a convex hull proxy's faces).
inline constexpr size_t kMaxConvexPlanes = 4096;

/// Trees deeper than this are rejected by the loader; evaluation recurses at most this deep.
inline constexpr int kMaxSdfDepth = 64;

/// The signed value of the tree at `p` (in the tree's frame). For primitives under rigid
/// transforms it is the Euclidean distance; in general a bound whose Lipschitz constant is
/// sdf_lipschitz(tree).
float sdf_eval(const SdfTree& tree, Vec3f p);
float sdf_eval(const SdfTree& tree, int node, Vec3f p);

/// An upper bound L on |f(x) - f(y)| / |x - y| over the whole tree: 1 for every primitive,
/// the larger child bound for every operator (smooth ones included: their gradient is a convex
/// combination of the children's), the child's bound plus |amplitude| x frequency x
/// fractal_gradient_bound(params) for Displace (the noise's gradient bound, chained through the
/// frequency), times the largest singular value of each node's to_local. Displacement thus
/// shortens every sphere-tracing step.
float sdf_lipschitz(const SdfTree& tree);

/// Unit outward normal at `p` from the analytic gradient: each primitive's closed-form gradient
/// (the cone's by central differences; a polyhedron's from its closest point, see
/// solid_mesh_gradient), chained through the node transforms (L^T g), the active
/// operand of min / max operators, the blend weights of smooth ones and, for Displace, the
/// child's gradient plus amplitude x frequency x the noise's analytic gradient. Zero where the gradient
/// vanishes or is not finite (a sphere's centre).
Vec3f sdf_gradient_normal(const SdfTree& tree, Vec3f p);

/// Unit outward normal at `p` from central differences of step `h`.
Vec3f sdf_normal(const SdfTree& tree, Vec3f p, float h);

/// Largest singular value of the linear part of `a` (Jacobi on its 3x3 Gram matrix).
float max_singular_value(const Affine3f& a);

struct SphereTraceConfig {
  int max_steps = 512;             ///< a ray still marching after this many steps is a miss
  float relative_epsilon = 1e-5f;  ///< hit when |f| / L < max(absolute, relative * t)
  float absolute_epsilon = 1e-6f;
};

/// Marches `ray` (any non-zero direction) from ray.tnear to ray.tfar with steps |f| / (L |dir|),
/// starting inside or outside. It stops when a step crosses the surface (f changes sign) or
/// when |f| / L falls below the tolerance (then it looks for the crossing two tolerances ahead,
/// or twice as far as the last step's secant puts it, up to 1024 tolerances, which a hit at the
/// ray's first evaluation must find: a ray starting on the surface and not crossing it marches
/// on);
/// a found crossing is refined by bisection to float precision (t is then just past the
/// surface). A tree whose root is a Displace node of non-zero amplitude is first
/// marched with its child's bound f_child - |amplitude| and the child's Lipschitz bound (no
/// noise, longer steps) until the ray nears the shell the noise can move the surface in. Sets t and returns
/// true on a hit; a ray still marching after config.max_steps evaluations is a miss. `steps` receives the
/// number of evaluations, bisection included.
bool sphere_trace(const SdfTree& tree, float lipschitz, const Ray& ray, const SphereTraceConfig& config,
                  float& t, int& steps);

}  // namespace penumbra
