// Bounding proxies fitted to point sets: the hit-boxes of collision detection. Each encloses
// every input point (to rounding: fitting ends by growing the proxy to its farthest point) and
// trades tightness against the cost of testing and of following a transformation:
//  - sphere: the exact minimal ball (Welzl, "Smallest enclosing disks (balls and ellipsoids)",
//    LNCS 555, 1991, with Gaertner's move-to-front order, "Fast and robust smallest enclosing
//    balls", ESA 1999), and Ritter's fast approximation ("An efficient bounding sphere",
//    Graphics Gems, 1990) for comparison;
//  - aabb: the axis-aligned box;
//  - obb: the oriented box of least volume among candidate frames: the world axes, the principal
//    axes of the hull's surface (Gottschalk, Lin & Manocha, "OBBTree", SIGGRAPH 1996), and for
//    each of the largest hull faces the face normal with the minimum-area rectangle of the
//    projection, which has a side on the projected hull (Freeman & Shapira, CACM 18(7), 1975);
//    the hull faces' silhouette edges give those sides without a 2-d hull. O'Rourke's exact
//    algorithm ("Finding minimal enclosing boxes", IJCIS 14(3), 1985) also tries edge pairs;
//  - capsule: along the principal axis, radius the minimal enclosing circle of the points
//    projected across the axis, the segment as short as that radius allows;
//  - hull: the convex hull (Qhull);
//  - kdop: the k-DOP, k in {6, 14, 18, 26} (axes, then corners, then edges of the cube);
//  - composite: one convex hull per connected component of the triangles.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "renderer/collision/hull.h"

namespace penumbra {

enum class ProxyKind : uint8_t { Sphere, Ritter, Aabb, Obb, Capsule, Hull, Kdop, Composite };

/// Number of ProxyKind values.
inline constexpr int kProxyKindCount = 8;

/// "sphere", "ritter", "aabb", "obb", "capsule", "hull", "kdop", "composite".
const char* proxy_kind_name(ProxyKind kind);

/// The kind a name gives; false for an unknown name.
bool parse_proxy_kind(std::string_view name, ProxyKind& kind);

struct BoundingSphere {
  DVec3 center{};
  double radius = 0;
};

/// A box centre + sum_i s_i axis[i], |s_i| <= half[i]; axes orthonormal and right-handed.
struct OrientedBox {
  DVec3 center{};
  DVec3 axis[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  DVec3 half{};
};

/// The points within `radius` of the segment ab.
struct CapsuleProxy {
  DVec3 a{}, b{};
  double radius = 0;
};

/// One fitted proxy: the member its kind names is set.
struct Proxy {
  ProxyKind kind = ProxyKind::Aabb;
  BoundingSphere sphere;                ///< Sphere, Ritter
  OrientedBox box;                      ///< Aabb (world axes), Obb
  CapsuleProxy capsule;                 ///< Capsule
  std::vector<ConvexPolyhedron> parts;  ///< Hull and Kdop: one; Composite: one per component
};

/// How proxies are fitted.
struct ProxyConfig {
  int kdop = 26;                  ///< k of the k-DOP: 6, 14, 18 or 26
  int obb_face_candidates = 256;  ///< largest hull faces whose normals the OBB search tries
  ConvexHullConfig hull;          ///< flat parts' thickening
};

/// Fits a proxy of `kind` to `points` (finite, at least one). `triangles` (3 indices into points
/// per triangle) gives the connectivity `composite` splits by, vertices at equal positions
/// joined; without triangles, composite is one hull. Throws std::invalid_argument for an empty
/// or non-finite input, a k not in {6, 14, 18, 26} or an index out of range.
Proxy fit_proxy(ProxyKind kind, std::span<const DVec3> points, std::span<const uint32_t> triangles = {},
                const ProxyConfig& config = {});

/// The minimal enclosing ball of `points` (Welzl with move-to-front), grown to its farthest point.
BoundingSphere minimal_sphere(std::span<const DVec3> points);

/// Ritter's bounding sphere: from the farthest pair found by two sweeps, grown by each point
/// outside.
BoundingSphere ritter_sphere(std::span<const DVec3> points);

/// The eigenvectors of the covariance of `points` (or, when `hull` is given, of its surface as
/// a continuous area density), columns of decreasing eigenvalue, right-handed.
void principal_axes(std::span<const DVec3> points, const ConvexPolyhedron* hull, DVec3 axes[3]);

/// The unit directions of the k-DOP's k / 2 slabs.
std::vector<DVec3> kdop_directions(int k);

/// The proxy's volume (a composite's parts summed: they may overlap).
double proxy_volume(const Proxy& proxy);

/// True if p lies in the proxy, allowing `tolerance` (world units).
bool proxy_contains(const Proxy& proxy, DVec3 p, double tolerance);

/// `count` points on the proxy's surface, uniformly by area, from a fixed `seed` (the same
/// points every run), appended to `out`.
void sample_proxy_surface(const Proxy& proxy, size_t count, uint64_t seed, std::vector<DVec3>& out);

}  // namespace penumbra
