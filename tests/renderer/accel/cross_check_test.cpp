// The accelerator cross-check: every back end against the brute-force oracle and
// against Embree, per ray, on synthetic edge cases, the project's default scene and every valid
// corpus model; watertightness from inside a closed sphere; and the default scene rendered with
// every back end. The [.slow] variants run many more rays outside CI:
//   renderer_tests "[slow]"
#include "support/cross_check.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstring>
#include <filesystem>
#include <map>

#include "io/gltf/loader.h"
#include "renderer/integrators/render.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/scene/curve_size.h"
#include "renderer/scene/scene.h"
#include "renderer/shapes/shape.h"
#include "support/sdf_trees.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

std::vector<Vec3f> light_positions(const Scene& s) {
  std::vector<Vec3f> out;
  for (const auto& l : s.lights)
    if (l.type != LightType::Directional) out.push_back(l.position);
  return out;
}

}  // namespace

// ---- Synthetic scenes ---------------------------------------------------------------------------

TEST_CASE("cross-check: empty scene", "[accel][crosscheck]") {
  Soup s;
  s.add({}, {});  // one empty mesh, and no meshes at all
  check_scene("empty mesh", s.views(), {});
  check_scene("no meshes", {}, {});
}

TEST_CASE("cross-check: one triangle, hit in the middle, on edges and on vertices", "[accel][crosscheck]") {
  Soup s;
  s.add({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  std::vector<Ray> extra;
  for (Vec3f target : {Vec3f{0.25f, 0.25f, 0}, Vec3f{0.5f, 0, 0}, Vec3f{0, 0.5f, 0}, Vec3f{0.5f, 0.5f, 0},
                       Vec3f{0, 0, 0}, Vec3f{1, 0, 0}, Vec3f{0, 1, 0}})
    for (Vec3f from : {Vec3f{0, 0, 1}, Vec3f{0, 0, -1}, Vec3f{0.3f, -0.2f, 1}})
      extra.push_back({target + from, 0, normalize(-from), kInfinity});
  check_scene("one triangle", s.views(), {}, 1, extra);
  // Known answers: t = 1 straight down onto the interior, u, v the barycentrics of b, c.
  for (const auto& a : build_all(s.views())) {
    Hit h;
    REQUIRE(a.accel->intersect({{0.25f, 0.5f, 1}, 0, {0, 0, -1}, kInfinity}, h));
    CHECK(h.t == Approx(1).epsilon(1e-6));
    CHECK(h.u == Approx(0.25f).epsilon(1e-5));
    CHECK(h.v == Approx(0.5f).epsilon(1e-5));
    CHECK_FALSE(a.accel->intersect({{0.25f, 0.5f, 1}, 0, {0, 0, -1}, 0.999f}, h));    // segment stops short
    CHECK_FALSE(a.accel->intersect({{0.25f, 0.5f, 1}, 0, {0, 0, 1}, kInfinity}, h));  // facing away
  }
}

TEST_CASE("cross-check: degenerate and zero-area triangles", "[accel][crosscheck]") {
  Soup s;
  s.add({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 2, 2}, {3, 3, 3}, {0.5f, 0.5f, 0.5f}, {0, 0, 1}, {1, 0, 1}},
        {3, 3, 3,    // a point
         3, 4, 4,    // two equal vertices
         0, 3, 4,    // collinear (0,0,0)-(2,2,2)-(3,3,3)
         0, 1, 2,    // a real triangle
         5, 5, 3,    // another point-segment
         6, 7, 6,    // a segment in z = 1
         0, 1, 2});  // the real one again (a tie)
  check_scene("degenerate", s.views(), {});
}

TEST_CASE("cross-check: coplanar, overlapping and interpenetrating triangles", "[accel][crosscheck]") {
  Soup s;
  for (int i = 0; i < 4; ++i) s.add_plane(2, 0.0f, 0.0f, 1.0f, 3);  // identical stacked planes
  s.add_plane(2, 0.0f, 0.5f, 1.5f, 4);                              // overlapping, offset
  s.add({{0.2f, 0.2f, -0.5f}, {0.8f, 0.8f, 0.5f}, {0.2f, 0.8f, 0.5f}}, {0, 1, 2});  // through the plane
  s.add({{0.2f, 0.2f, 0.5f}, {0.8f, 0.8f, -0.5f}, {0.8f, 0.2f, -0.5f}}, {0, 1, 2});
  check_scene("coplanar", s.views(), {}, 1, lattice_rays(-0.5f, 1.5f, 0.25f));
}

TEST_CASE("cross-check: axis-aligned walls on split planes, axis-parallel rays through edges and vertices",
          "[accel][crosscheck]") {
  Soup s;
  for (int axis = 0; axis < 3; ++axis)
    for (int i = 0; i <= 4; ++i) s.add_plane(axis, float(i), 0.0f, 4.0f, 4);  // a 4^3 lattice of cubes
  std::vector<Ray> extra = lattice_rays(0.0f, 4.0f, 0.5f);
  // Diagonals through lattice vertices.
  for (Vec3f o : {Vec3f{-1, -1, -1}, Vec3f{5, -1, -1}, Vec3f{0.5f, -1, 0.5f}})
    extra.push_back({o, 0, normalize(Vec3f{2, 2, 2} - o), kInfinity});
  // Rays from inside cells towards walls, ending exactly on them.
  extra.push_back({{0.5f, 0.5f, 0.5f}, 0, {1, 0, 0}, 0.5f});
  extra.push_back({{0.5f, 0.5f, 0.5f}, 0, {0, -1, 0}, 0.5f});
  check_scene("walls", s.views(), {}, 1, extra);
}

TEST_CASE("cross-check: a tessellated plane, rays through vertices, along edges and starting on it",
          "[accel][crosscheck]") {
  Soup s;
  s.add_plane(1, 0.0f, -4.0f, 4.0f, 8);
  std::vector<Ray> extra;
  for (float x = -4; x <= 4; x += 0.5f)
    for (float z = -4; z <= 4; z += 0.5f) {
      extra.push_back({{x, 1, z}, 0, {0, -1, 0}, kInfinity});                        // vertices, edges
      extra.push_back({{x, 0, z}, 0, {0, 1, 0}, kInfinity});                         // starts on the plane
      extra.push_back({{x, 0, z}, 0, normalize(Vec3f{0.3f, -1, 0.2f}), kInfinity});  // into it
      extra.push_back(
          {{x - 0.5f, 1, z - 0.5f}, 0, normalize(Vec3f{0.5f, -1, 0.5f}), kInfinity});  // diagonals
    }
  for (float z = -4; z <= 4; z += 1) extra.push_back({{-5, 0, z}, 0, {1, 0, 0}, kInfinity});  // in the plane
  check_scene("plane", s.views(), {}, 1, extra);
}

TEST_CASE("cross-check: huge and tiny coordinates", "[accel][crosscheck][heavy]") {
  struct Variant {
    float scale;
    Vec3f offset;
  };
  for (const Variant& v :
       {Variant{1e-6f, {0, 0, 0}}, Variant{1e-6f, {1e-6f, 2e-6f, 0}}, Variant{1, {1e-6f, 0, 0}},
        Variant{1, {1e3f, -1e3f, 1e3f}}, Variant{1, {1e6f, 0, 1e6f}}, Variant{1e6f, {0, 0, 0}},
        Variant{1e6f, {1e6f, 1e6f, 1e6f}}}) {
    const Soup s = icosphere(2, v.scale, v.offset);
    char name[96];
    std::snprintf(name, sizeof name, "sphere scale %g offset (%g, %g, %g)", v.scale, v.offset.x, v.offset.y,
                  v.offset.z);
    check_scene(name, s.views(), {});
  }
}

TEST_CASE("cross-check: rays from inside a closed sphere always hit (watertightness)",
          "[accel][crosscheck][heavy]") {
  const Soup s = icosphere(4, 1.0f, {0.1f, -0.2f, 0.3f});  // 5120 triangles
  const auto views = s.views();
  const auto all = build_all(views);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.9f, 0.9f);
  std::vector<Ray> rays;
  for (int i = 0; i < 100000; ++i) {
    // Half from the centre, half from random points well inside (|p - c| < 0.9; the
    // tessellation's inner radius is above 0.98).
    Vec3f o{0.1f, -0.2f, 0.3f};
    if (i % 2 == 0) {
      Vec3f d;
      do d = {u(rng), u(rng), u(rng)};
      while (dot(d, d) >= 0.81f);
      o = o + d;
    }
    rays.push_back({o, 0, random_direction(rng), kInfinity});
  }
  for (const auto& a : all) {
    const size_t n = a.name == "brute" ? 20000 : rays.size();
    size_t misses = 0, occl_misses = 0;
    for (size_t i = 0; i < n; ++i) {
      Hit h;
      misses += !a.accel->intersect(rays[i], h);
      occl_misses += !a.accel->occluded(rays[i]);
    }
    INFO(a.name << ": " << misses << " misses, " << occl_misses << " occlusion misses in " << n << " rays");
    CHECK(double(misses) <= 2e-5 * double(n));
    CHECK(double(occl_misses) <= 2e-5 * double(n));
  }
}

// ---- Shapes among triangles -----------------------------------------------------------------------

namespace {

Affine3f translated(Affine3f a, Vec3f t) {
  a.m[0][3] += t.x, a.m[1][3] += t.y, a.m[2][3] += t.z;
  return a;
}

/// The classic CSG part: a sphere intersected with a cube, minus three orthogonal cylinders,
/// centred at `centre` (to_local holds the inverse placement).
Shape csg_part(Vec3f centre) {
  SdfTree t;
  t.nodes = {sdf_primitive(SdfKind::Sphere, {0.65f, 0, 0}), sdf_primitive(SdfKind::Box, {0.5f, 0.5f, 0.5f}),
             sdf_operator(SdfKind::Intersection, 0, 1)};
  Affine3f rot_x, rot_z;  // the Y-axis cylinder turned onto X and Z
  rot_x.m[0][0] = 0, rot_x.m[0][1] = 1, rot_x.m[1][0] = -1, rot_x.m[1][1] = 0;
  rot_z.m[1][1] = 0, rot_z.m[1][2] = 1, rot_z.m[2][1] = -1, rot_z.m[2][2] = 0;
  int body = 2;
  for (const Affine3f& r : {Affine3f{}, rot_x, rot_z}) {
    SdfNode cyl = sdf_primitive(SdfKind::Cylinder, {0, 0.7f, 0}, 0.3f);
    cyl.to_local = r;
    t.nodes.push_back(cyl);
    t.nodes.push_back(sdf_operator(SdfKind::Subtraction, body, int(t.nodes.size()) - 1));
    body = int(t.nodes.size()) - 1;
  }
  t.nodes[size_t(body)].to_local = moved_by(centre);
  t.root = body;
  return make_implicit_shape(std::move(t));
}

/// A torus and a sphere blended by a smooth union, centred at `centre`.
Shape blob(Vec3f centre) {
  SdfTree t;
  t.nodes = {sdf_primitive(SdfKind::Torus, {0.6f, 0, 0}, 0.15f),
             sdf_primitive(SdfKind::Sphere, {0.35f, 0, 0}), sdf_operator(SdfKind::SmoothUnion, 0, 1, 0.3f)};
  t.nodes[1].to_local = moved_by({0, 0.3f, 0});
  t.nodes[2].to_local = moved_by(centre);
  t.root = 2;
  return make_implicit_shape(std::move(t));
}

/// Every back end over `instances` of `views` (meshes and shapes) against brute force over the
/// same instances: Penumbra's own back ends exactly (the same object-space rays meet the same
/// tests), Embree (which maps rays into object space itself) within a relative 1e-4 in t.
void check_shape_instances(const std::string& scene, std::span<const GeometryView> views,
                           std::span<const InstanceView> instances) {
  const auto brute = make_accelerator("brute", views, instances);
  const Bounds3f b = brute->bounds();
  REQUIRE_FALSE(b.empty());
  std::mt19937 rng(17);
  std::vector<Ray> rays = camera_rays(b, 48);
  const std::vector<Ray> rnd = random_rays(b, 6000, rng);
  rays.insert(rays.end(), rnd.begin(), rnd.end());
  const std::vector<Ray> bad = bad_rays(b);
  rays.insert(rays.end(), bad.begin(), bad.end());
  std::vector<Hit> ref(rays.size());
  size_t hits = 0;
  for (size_t i = 0; i < rays.size(); ++i) hits += brute->intersect(rays[i], ref[i]);
  CHECK(hits >= rays.size() / 20);  // not a scene of misses
  const float scale = length(b.extent());
  for (const auto& name : accelerator_names()) {
    const auto a = make_accelerator(name, views, instances);
    const bool exact = name != "embree";
    size_t mismatches = 0;
    std::string first;
    for (size_t i = 0; i < rays.size(); ++i) {
      Hit h;
      const bool hit = a->intersect(rays[i], h);
      bool same = hit == ref[i].valid() && a->occluded(rays[i]) == hit;
      if (same && hit)
        same = h.geom_id == ref[i].geom_id && h.prim_id == ref[i].prim_id &&
               (exact ? h.t == ref[i].t && h.u == ref[i].u && h.v == ref[i].v
                      : std::fabs(h.t - ref[i].t) <= 1e-4f * std::max({h.t, ref[i].t, 0.1f * scale}));
      if (same) continue;
      ++mismatches;
      if (first.empty()) first = describe(rays[i]) + " -> " + describe(h) + " vs brute " + describe(ref[i]);
    }
    INFO(scene << ": " << name << " vs brute over " << rays.size() << " rays, " << mismatches
               << " mismatches\n  first: " << first);
    CHECK(mismatches == 0);
    CHECK(a->stats().shapes == brute->stats().shapes);
  }
}

}  // namespace

TEST_CASE("cross-check: triangles, analytic primitives and implicit shapes in one scene",
          "[accel][crosscheck][shapes]") {
  // Overlapping analytic shapes at the origin (closest hit among interpenetrating surfaces), CSG
  // and smooth-union shapes beside them, an icosphere and a floor of triangles.
  Soup s = icosphere(2, 0.8f, {0, 0, 3});
  s.add_plane(1, -1.5f, -5.0f, 5.0f, 6);
  const std::vector<Shape> shapes{analytic_shape(ShapeKind::Sphere, 0.5f),
                                  analytic_shape(ShapeKind::Box, 1, {1, 0.3f, 0.7f}),
                                  analytic_shape(ShapeKind::Capsule, 0.25f, {}, 1.2f),
                                  analytic_shape(ShapeKind::Disk, 1.5f),
                                  analytic_shape(ShapeKind::Plane, 1, {2.5f, 0, 0.4f}),
                                  csg_part({3, 0, 0}),
                                  blob({-3, 0, 0})};
  std::vector<GeometryView> views = s.views();
  for (const Shape& sh : shapes) views.push_back({{}, {}, &sh});
  std::vector<Ray> extra;
  // Straight at each shape's centre line and along the flat shapes' planes.
  for (float x : {-3.0f, -0.6f, 0.0f, 0.6f, 3.0f})
    for (float y : {-0.3f, 0.0f, 0.3f}) {
      extra.push_back({{x, y, -6}, 0, {0, 0, 1}, kInfinity});
      extra.push_back({{x, 6, y}, 0, {0, -1, 0}, kInfinity});
    }
  extra.push_back({{-6, 0, 0}, 0, {1, 0, 0}, kInfinity});  // in the disk's and plane's plane
  check_scene("mixed", views, {}, 1, extra);
}

TEST_CASE("cross-check: instances of analytic and implicit shapes", "[accel][crosscheck][shapes]") {
  const Soup s = icosphere(2, 0.5f, {0, 0, 0});
  const std::vector<Shape> shapes{analytic_shape(ShapeKind::Sphere, 0.5f),
                                  analytic_shape(ShapeKind::Box, 1, {0.4f, 0.3f, 0.2f}),
                                  analytic_shape(ShapeKind::Capsule, 0.2f, {}, 0.3f),
                                  analytic_shape(ShapeKind::Disk, 0.6f),
                                  csg_part({0, 0, 0}),
                                  blob({0, 0, 0})};
  std::vector<GeometryView> views = s.views();
  for (const Shape& sh : shapes) views.push_back({{}, {}, &sh});
  // Each geometry placed twice: translated, and rotated, scaled non-uniformly or mirrored.
  std::vector<InstanceView> instances;
  for (uint32_t g = 0; g < views.size(); ++g) {
    const float x = -3.5f + 1.2f * float(g);
    instances.push_back({g, translated(Affine3f{}, {x, 0, 0})});
    Affine3f m;
    const float c = std::cos(0.7f + 0.3f * float(g)), sn = std::sin(0.7f + 0.3f * float(g));
    m.m[0][0] = 1.3f * c, m.m[0][2] = sn;
    m.m[1][1] = g % 2 ? 0.6f : -0.8f;  // odd: squashed; even: mirrored
    m.m[2][0] = -1.3f * sn, m.m[2][2] = c;
    instances.push_back({g, translated(m, {x, 1.5f, 0.5f})});
  }
  instances.push_back({uint32_t(views.size() - 1), Affine3f{}});  // one identity placement too
  check_shape_instances("shape instances", views, instances);
}

/// A polyline of `n` segments (n + 1 vertices, stored as (a, b, b) triangles) spiralling about
/// `centre`, with radii varying along it, and a grid of points with radii of their own (all
/// radii times `thickness`).
struct CurveSoup {
  std::vector<Vec3f> line_positions, point_positions;
  std::vector<uint32_t> line_indices, point_indices;
  std::vector<float> line_radii, point_radii;
  CurveSoup(Vec3f centre, int n, float thickness = 1) {
    for (int i = 0; i <= n; ++i) {
      const float a = 0.7f * float(i);
      line_positions.push_back(centre + Vec3f{std::cos(a), 0.15f * float(i) - 1, std::sin(a)});
      line_radii.push_back(thickness * (0.04f + 0.01f * float(i % 5)));
      if (i > 0) line_indices.insert(line_indices.end(), {uint32_t(i - 1), uint32_t(i), uint32_t(i)});
    }
    for (int x = 0; x < 6; ++x)
      for (int z = 0; z < 6; ++z) {
        const uint32_t i = uint32_t(point_positions.size());
        point_positions.push_back(centre + Vec3f{0.4f * float(x) - 1, 1.5f, 0.4f * float(z) - 1});
        point_radii.push_back(thickness * (0.06f + 0.02f * float((x + z) % 3)));
        point_indices.insert(point_indices.end(), {i, i, i});
      }
  }
  GeometryView lines() const {
    GeometryView v{line_positions, line_indices};
    v.curves = CurveKind::Segments;
    v.radii = line_radii;
    return v;
  }
  GeometryView points() const {
    GeometryView v{point_positions, point_indices};
    v.curves = CurveKind::Points;
    v.radii = point_radii;
    return v;
  }
};

TEST_CASE("cross-check: line segments and points among triangles", "[accel][crosscheck][shapes]") {
  Soup s = icosphere(2, 0.8f, {0, 0, 3});
  s.add_plane(1, -1.5f, -5.0f, 5.0f, 6);
  const CurveSoup curves({0, 0, 0}, 16);
  std::vector<GeometryView> views = s.views();
  views.push_back(curves.lines());
  views.push_back(curves.points());
  std::vector<Ray> extra;
  // Down onto each point's centre and across each segment's middle.
  for (const Vec3f p : curves.point_positions)
    extra.push_back({p + Vec3f{0, 3, 0}, 0, {0, -1, 0}, kInfinity});
  for (size_t i = 0; i + 1 < curves.line_positions.size(); ++i) {
    const Vec3f m = (curves.line_positions[i] + curves.line_positions[i + 1]) * 0.5f;
    extra.push_back({m + Vec3f{0, 0, -6}, 0, {0, 0, 1}, kInfinity});
  }
  check_scene("curves", views, {}, 1, extra);
  // Each element reports its own index; u, v are 0 as for shapes.
  for (const auto& a : build_all(views)) {
    INFO(a.name);
    for (size_t i = 0; i < curves.point_positions.size(); ++i) {
      Hit h;
      REQUIRE(a.accel->intersect({curves.point_positions[i] + Vec3f{0, 3, 0}, 0, {0, -1, 0}, kInfinity}, h));
      CHECK(h.geom_id == views.size() - 1);
      CHECK(h.prim_id == i);
      CHECK(h.t == Approx(3 - curves.point_radii[i]).epsilon(1e-5));
    }
    CHECK(a.accel->stats().shapes == 16 + 36);
  }
}

TEST_CASE("cross-check: instances of line and point sets", "[accel][crosscheck][shapes]") {
  const CurveSoup curves({0, 0, 0}, 12, 3);
  const std::vector<GeometryView> views{curves.lines(), curves.points()};
  std::vector<InstanceView> instances;
  for (uint32_t g = 0; g < views.size(); ++g) {
    instances.push_back({g, translated(Affine3f{}, {3.0f * float(g), 0, 0})});
    Affine3f m;
    m.m[0][0] = 1.5f, m.m[1][1] = g ? -0.7f : 0.8f, m.m[2][2] = 1.1f;  // stretched; mirrored for points
    instances.push_back({g, translated(m, {3.0f * float(g), 0, 4})});
  }
  check_shape_instances("curve instances", views, instances);
}

// ---- Real scenes ----------------------------------------------------------------------------------

TEST_CASE("cross-check: the default scene", "[accel][crosscheck]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto meshes = mesh_views(l.scene);
  const auto instances = instance_views(l.scene);
  // Flattened (one level), and as loaded: the "wall" mesh is instanced by three nodes.
  check_scene("default.gltf", flatten(meshes, instances).views, light_positions(l.scene));
  REQUIRE(l.scene.instances.size() > l.scene.meshes.size());
  check_instanced("default.gltf", meshes, instances, light_positions(l.scene));
}

TEST_CASE("cross-check: the points and lines scene", "[accel][crosscheck][shapes]") {
  LoadedScene l = load_gltf(source_dir() / "scenes/curves.gltf");
  REQUIRE_FALSE(l.scene.cameras.empty());
  // Sizes as a 480 x 270 render gives them: 2-pixel points, 1-pixel lines (the tetrahedron's
  // 4 cm from the file).
  set_curve_radii(l.scene, l.scene.cameras[0], 270, {2, true}, {1, true});
  const auto views = mesh_views(l.scene);
  REQUIRE(std::count_if(views.begin(), views.end(),
                        [](const GeometryView& v) { return v.curves != CurveKind::None; }) == 4);
  REQUIRE(std::all_of(l.scene.instances.begin(), l.scene.instances.end(),
                      [](const Instance& i) { return i.identity; }));
  check_scene("curves.gltf", views, light_positions(l.scene));
}

TEST_CASE("cross-check: Embree without the robust flag and at low and high build quality",
          "[accel][crosscheck][heavy]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  for (const auto& [robust, quality] : {std::pair{false, 1}, std::pair{true, 0}, std::pair{true, 2}}) {
    AccelConfig config;
    config.embree.robust = robust;
    config.embree.quality = quality;
    const auto embree = make_accelerator("embree", views, config);
    CHECK(embree->stats().config.find(robust ? "robust 1" : "robust 0") != std::string::npos);
    std::mt19937 rng(7);
    const Bounds3f b = bounds_of(views);
    std::vector<Ray> rays = camera_rays(b, 32);
    const auto rnd = random_rays(b, 2000, rng);
    rays.insert(rays.end(), rnd.begin(), rnd.end());
    const auto brute = make_accelerator("brute", views);
    const auto res = cross_check(*embree, reference(*brute, rays), views, length(b.extent()), false, 1e-4f);
    INFO(summary("embree " + embree->stats().config + " vs brute", res));
    CHECK(res.failures() == 0);
  }
}

TEST_CASE("cross-check: every valid corpus model", "[accel][crosscheck][corpus][heavy]") {
  const auto corpus = corpus_dir();
  if (!corpus) return skip("no corpus (set PENUMBRA_CORPUS)");
  // Embree and brute force on every model; the own back ends in turn, each on every other
  // model (files in path order), so that each still meets at least half the corpus.
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(*corpus / "valid")) {
    const auto ext = e.path().extension();
    if (e.is_regular_file() && (ext == ".gltf" || ext == ".glb")) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  const std::vector<std::string> names = accelerator_names();
  std::map<std::string, size_t> checked;
  for (size_t m = 0; m < files.size(); ++m) {
    const AccelFilter keep = [&](const std::string& n) {
      return (size_t(std::find(names.begin(), names.end(), n) - names.begin()) + m) % 2 == 0;
    };
    for (const std::string& n : names) checked[n] += keep(n);
    const LoadedScene l = load_gltf(files[m]);
    const auto meshes = mesh_views(l.scene);
    const auto instances = instance_views(l.scene);
    const std::string name = files[m].filename().string();
    check_scene(name, flatten(meshes, instances).views, light_positions(l.scene), 1, {}, keep);
    if (std::any_of(l.scene.instances.begin(), l.scene.instances.end(),
                    [](const Instance& i) { return !i.identity; }))
      check_instanced(name, meshes, instances, light_positions(l.scene), 7, keep);
  }
  CHECK(files.size() >= 30);
  for (const std::string& n : names)
    if (n != "embree" && n != "brute") CHECK(checked[n] >= files.size() / 2);
}

TEST_CASE("cross-check, slow: the default scene and spheres with 16x the rays",
          "[.][slow][accel][crosscheck]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  check_scene("default.gltf", flatten(mesh_views(l.scene), instance_views(l.scene)).views,
              light_positions(l.scene), 4);
  const Soup s = icosphere(3, 1.0f, {1e3f, 0, 0});
  check_scene("sphere", s.views(), {}, 4);
}

// ---- Renderer level -------------------------------------------------------------------------------

TEST_CASE("the default scene renders the same image with every accelerator", "[accel][render][heavy]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  RenderConfig cfg;
  cfg.width = 160;
  cfg.height = 90;
  cfg.spp = 1;
  cfg.threads = 2;
  std::vector<NamedAccel> all;
  for (const auto& name : accelerator_names()) all.push_back({name, make_scene_accelerator(name, l.scene)});
  std::vector<Film> films;
  for (const auto& a : all) films.push_back(render_whitted(l.scene, *a.accel, l.scene.cameras.at(0), cfg));
  const Film& embree = films[0];
  const Film& brute = films.back();
  REQUIRE(all[0].name == "embree");
  REQUIRE(all.back().name == "brute");
  for (size_t i = 1; i < all.size(); ++i) {
    // Back ends sharing the watertight test: the same image as brute force, bit for bit.
    CHECK(std::memcmp(films[i].rgba.data(), brute.rgba.data(), brute.rgba.size() * sizeof(float)) == 0);
    // Against Embree: every pixel within 1e-4 (relative above 1), except where Embree's own
    // triangle test resolves a tie on a shared edge differently.
    size_t differing = 0;
    for (size_t p = 0; p < embree.rgba.size(); p += 4) {
      bool same = true;
      for (int c = 0; c < 4; ++c)
        same &= std::fabs(films[i].rgba[p + c] - embree.rgba[p + c]) <=
                1e-4f * std::max(1.0f, std::fabs(embree.rgba[p + c]));
      differing += !same;
    }
    INFO(all[i].name << ": " << differing << " of " << embree.rgba.size() / 4
                     << " pixels differ from embree by > 1e-4");
    CHECK(differing <= embree.rgba.size() / 4 / 1000);
  }
}
