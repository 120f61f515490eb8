// Tests for renderer/shapes/shape: each analytic ray test against hand-computed hits (through the
// middle, tangent, from inside, behind, tnear/tfar, non-unit directions), surface normals and
// UVs, CSG bounds, and implicit shapes against their analytic twins, thin plates and grazing
// rays included (no leaks).
#include "renderer/shapes/shape.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

// The hit distance, or -1 on a miss.
float hit_t(const Shape& s, Vec3f o, Vec3f d, float tnear = 0, float tfar = kInfinity) {
  ShapeHit h;
  return intersect_shape(s, Ray{o, tnear, d, tfar}, h) ? h.t : -1.0f;
}

SdfTree tree_of(std::vector<SdfNode> nodes, int root) {
  SdfTree t;
  t.nodes = std::move(nodes);
  t.root = root;
  return t;
}

}  // namespace

TEST_CASE("sphere: the quadratic's roots", "[shapes][quick]") {
  const Shape s = analytic_shape(ShapeKind::Sphere, 1);
  CHECK(hit_t(s, {0, 0, -5}, {0, 0, 1}) == Approx(4));
  CHECK(hit_t(s, {0, 0, -5}, {0, 0, 2}) == Approx(2));           // t in units of the direction
  CHECK(hit_t(s, {1, 0, -5}, {0, 0, 1}) == Approx(5));           // tangent: the double root
  CHECK(hit_t(s, {1.001f, 0, -5}, {0, 0, 1}) == -1);             // just past the silhouette
  CHECK(hit_t(s, {0, 0, 0}, {0, 1, 0}) == Approx(1));            // from inside: the far side
  CHECK(hit_t(s, {0, 0, 5}, {0, 0, 1}) == -1);                   // behind the origin
  CHECK(hit_t(s, {0, 0, -5}, {0, 0, 1}, 4.5f) == Approx(6));     // tnear past the entry: the exit
  CHECK(hit_t(s, {0, 0, -5}, {0, 0, 1}, 0, 3.9f) == -1);         // tfar before the entry
  CHECK(hit_t(s, {0, 0, -5}, {0, 0, 1}, 0, 4.0f) == Approx(4));  // tfar exactly at it
  CHECK(hit_t(s, {0, 0, -5}, {0, 0, 1}, 6.5f) == -1);            // both roots before tnear
  // A far-away sphere: the stable quadratic keeps its digits.
  const Shape big = analytic_shape(ShapeKind::Sphere, 1e-3f);
  CHECK(hit_t(big, {0, 0, -1e4f}, {0, 0, 1}) == Approx(1e4f - 1e-3f).epsilon(1e-7));
}

TEST_CASE("plane and disk: the crossing of y = 0, inside the outline, from either side", "[shapes][quick]") {
  const Shape plane = analytic_shape(ShapeKind::Plane, 1, {1, 0, 2});
  CHECK(hit_t(plane, {0.5f, 3, -1.5f}, {0, -1, 0}) == Approx(3));
  CHECK(hit_t(plane, {0.5f, -3, -1.5f}, {0, 1, 0}) == Approx(3));  // from below: two-sided
  CHECK(hit_t(plane, {1.5f, 3, 0}, {0, -1, 0}) == -1);             // outside |x| <= 1
  CHECK(hit_t(plane, {0, 3, 2.5f}, {0, -1, 0}) == -1);             // outside |z| <= 2
  CHECK(hit_t(plane, {0, 1, 0}, {1, 0, 0}) == -1);                 // parallel
  CHECK(hit_t(plane, {0, 3, 0}, {0, 1, 0}) == -1);                 // away
  CHECK(hit_t(plane, {-1, 1, 0}, normalize(Vec3f{1, -1, 0})) == Approx(std::sqrt(2.0f)));
  const Shape disk = analytic_shape(ShapeKind::Disk, 1);
  CHECK(hit_t(disk, {0.6f, 2, 0.7f}, {0, -1, 0}) == Approx(2));  // 0.36 + 0.49 <= 1
  CHECK(hit_t(disk, {0.8f, 2, 0.7f}, {0, -1, 0}) == -1);         // 0.64 + 0.49 > 1
  CHECK(hit_t(disk, {1, 2, 0}, {0, -1, 0}) == Approx(2));        // on the rim
}

TEST_CASE("box: slabs, from inside, along a face", "[shapes][quick]") {
  const Shape box = analytic_shape(ShapeKind::Box, 1, {1, 2, 3});
  CHECK(hit_t(box, {-5, 0, 0}, {1, 0, 0}) == Approx(4));
  CHECK(hit_t(box, {0, 0, 10}, {0, 0, -1}) == Approx(7));
  CHECK(hit_t(box, {0, 0, 0}, {0, 1, 0}) == Approx(2));   // inside: the exit face
  CHECK(hit_t(box, {-5, 2, 0}, {1, 0, 0}) == Approx(4));  // grazing the face y = 2: touches
  CHECK(hit_t(box, {-5, 2.01f, 0}, {1, 0, 0}) == -1);
  CHECK(hit_t(box, {5, 0, 0}, {1, 0, 0}) == -1);                // behind
  CHECK(hit_t(box, {-5, 0, 0}, {1, 0, 0}, 4.5f) == Approx(6));  // tnear past the entry
  CHECK(hit_t(box, {-5, 0, 0}, {1, 0, 0}, 0, 3) == -1);
  // A diagonal through a corner region: entry where the last slab is entered.
  CHECK(hit_t(box, {-2, -3, 0}, normalize(Vec3f{1, 1, 0})) == Approx(std::sqrt(2.0f) * 1));
}

TEST_CASE("capsule: the side, the caps and the seam between them", "[shapes][quick]") {
  const Shape c = analytic_shape(ShapeKind::Capsule, 0.5f, {1, 1, 1}, 0.5f);
  CHECK(hit_t(c, {-5, 0, 0}, {1, 0, 0}) == Approx(4.5f));  // the cylinder
  CHECK(hit_t(c, {0, 5, 0}, {0, -1, 0}) == Approx(4));     // top cap at y = 1
  CHECK(hit_t(c, {0, -5, 0}, {0, 1, 0}) == Approx(4));     // bottom cap at y = -1
  // Above the segment's end: the cap sphere at y = 0.5, x = -sqrt(0.25 - 0.25^2).
  CHECK(hit_t(c, {-5, 0.75f, 0}, {1, 0, 0}) == Approx(5 - std::sqrt(0.25f - 0.0625f)));
  CHECK(hit_t(c, {-5, 0.5f, 0}, {1, 0, 0}) == Approx(4.5f));  // exactly at the seam
  CHECK(hit_t(c, {0, 0, 0}, {0, 1, 0}) == Approx(1));         // inside
  CHECK(hit_t(c, {0, 0, 0}, {1, 0, 0}) == Approx(0.5f));
  CHECK(hit_t(c, {-5, 1.01f, 0}, {1, 0, 0}) == -1);
  CHECK(hit_t(c, {0.6f, 5, 0}, {0, -1, 0}) == -1);  // outside the radius, parallel to the axis
}

TEST_CASE("segment: a capsule about any axis, a sphere for a point", "[shapes][quick]") {
  // The axis (1, 1, 1)-(3, 1, 1), radius 0.25: a ray down -y through x = 2 meets it at y = 1.25.
  const Shape s = make_segment_shape({1, 1, 1}, {3, 1, 1}, 0.25f, 7);
  CHECK(s.element == 7);
  CHECK(hit_t(s, {2, 5, 1}, {0, -1, 0}) == Approx(3.75f));
  CHECK(hit_t(s, {0, 1, 1}, {1, 0, 0}) == Approx(0.75f));  // into the cap at x = 0.75
  CHECK(hit_t(s, {2, 1, 1}, {0, 0, 1}) == Approx(0.25f));  // from inside: the far side
  CHECK(hit_t(s, {3.3f, 5, 1}, {0, -1, 0}) == -1);         // past the cap
  // A tilted axis: (0, 0, 0)-(1, 1, 1); the ray through the midpoint across it.
  const Shape t = make_segment_shape({0, 0, 0}, {1, 1, 1}, 0.1f, 0);
  const Vec3f across = normalize(Vec3f{1, -1, 0});
  CHECK(hit_t(t, Vec3f{0.5f, 0.5f, 0.5f} + across * 4, -across) == Approx(3.9f));
  const ShapeSurface surf = shape_surface(t, Vec3f{0.5f, 0.5f, 0.5f} + across * 0.1f, 1e-4f);
  CHECK(dot(surf.n, across) == Approx(1).epsilon(1e-5));
  CHECK(surf.uv.x == Approx(0.5f));
  // A point: the sphere of the radius about p0, its bounds and area.
  const Shape p = make_segment_shape({0, 2, 0}, {0, 2, 0}, 0.5f, 0);
  CHECK(hit_t(p, {0, 2, -3}, {0, 0, 1}) == Approx(2.5f));
  CHECK(hit_t(p, {0.49f, 2, -3}, {0, 0, 1}) == Approx(3 - std::sqrt(0.25f - 0.49f * 0.49f)).epsilon(1e-4));
  CHECK(hit_t(p, {0.51f, 2, -3}, {0, 0, 1}) == -1);
  const Bounds3f b = shape_bounds(p);
  CHECK((b.lo.x == -0.5f && b.hi.y == 2.5f));
  CHECK(snap_to_shape(s, {2, 1.5f, 1}).y == Approx(1.25f));
}

TEST_CASE("shape surfaces: normals and UVs", "[shapes][quick]") {
  const Shape sphere = analytic_shape(ShapeKind::Sphere, 2);
  const ShapeSurface top = shape_surface(sphere, {0, 2, 0}, 1e-4f);
  CHECK(top.n.y == Approx(1));
  CHECK(top.uv.y == Approx(0).margin(1e-6));
  const ShapeSurface px = shape_surface(sphere, {2, 0, 0}, 1e-4f);
  CHECK(px.uv.x == Approx(0).margin(1e-6));
  CHECK(px.uv.y == Approx(0.5f));
  CHECK(shape_surface(sphere, {0, 0, -2}, 1e-4f).uv.x == Approx(0.25f));  // phi = 90 deg towards -Z
  const Shape box = analytic_shape(ShapeKind::Box, 1, {1, 2, 3});
  CHECK(shape_surface(box, {0.2f, -2, 1}, 1e-4f).n.y == -1);
  CHECK(shape_surface(box, {1, 0.3f, 1}, 1e-4f).n.x == 1);
  const Shape cap = analytic_shape(ShapeKind::Capsule, 0.5f, {1, 1, 1}, 0.5f);
  const Vec3f n = shape_surface(cap, {0, 0.5f + 0.5f * std::sqrt(0.5f), 0.5f * std::sqrt(0.5f)}, 1e-4f).n;
  CHECK(n.y == Approx(std::sqrt(0.5f)));
  CHECK(n.z == Approx(std::sqrt(0.5f)));
  CHECK(snap_to_shape(sphere, {0, 0, 2.1f}).z == Approx(2));
}

TEST_CASE("CSG bounds: overlap, merge, the first operand, smooth widening, unbounded trees",
          "[shapes][quick]") {
  // Sphere r = 1.3 intersected with a cube of half size 1: the cube's box.
  const SdfTree part =
      tree_of({sdf_primitive(SdfKind::Sphere, {1.3f, 0, 0}), sdf_primitive(SdfKind::Box, {1, 1, 1}),
               sdf_operator(SdfKind::Intersection, 0, 1)},
              2);
  Bounds3f b = sdf_tree_bounds(part);
  CHECK(b.lo.x == Approx(-1));
  CHECK(b.hi.z == Approx(1));
  // Union of two translated spheres.
  std::vector<SdfNode> nodes{sdf_primitive(SdfKind::Sphere, {1, 0, 0}),
                             sdf_primitive(SdfKind::Sphere, {1, 0, 0}), sdf_operator(SdfKind::Union, 0, 1)};
  nodes[0].to_local = moved_by({-2, 0, 0});
  nodes[1].to_local = moved_by({3, 0, 0});
  b = sdf_tree_bounds(tree_of(nodes, 2));
  CHECK(b.lo.x == Approx(-3));
  CHECK(b.hi.x == Approx(4));
  // Smooth union widens by a quarter of the blend radius: smin >= min - k / 4.
  nodes[2] = sdf_operator(SdfKind::SmoothUnion, 0, 1, 0.8f);
  const SdfTree blob = tree_of(nodes, 2);
  b = sdf_tree_bounds(blob);
  CHECK(b.lo.x == Approx(-3.2f));
  CHECK(b.hi.y == Approx(1.2f));
  // The bound holds: sample points outside it are outside the shape.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-6, 6);
  for (int i = 0; i < 20000; ++i) {
    const Vec3f p{u(rng), u(rng), u(rng)};
    const bool outside_box =
        p.x < b.lo.x || p.y < b.lo.y || p.z < b.lo.z || p.x > b.hi.x || p.y > b.hi.y || p.z > b.hi.z;
    if (outside_box) REQUIRE(sdf_eval(blob, p) > 0);
  }
  // Subtraction keeps the first operand's box; a half-space or complement alone is unbounded.
  b = sdf_tree_bounds(
      tree_of({sdf_primitive(SdfKind::Box, {1, 2, 3}), sdf_primitive(SdfKind::Sphere, {5, 0, 0}),
               sdf_operator(SdfKind::Subtraction, 0, 1)},
              2));
  CHECK(b.hi.z == Approx(3));
  SdfNode half;
  half.kind = SdfKind::HalfSpace;
  CHECK(sdf_tree_bounds(tree_of({half}, 0)).empty());
  CHECK(sdf_tree_bounds(
            tree_of({sdf_primitive(SdfKind::Sphere, {1, 0, 0}), sdf_operator(SdfKind::Complement, 0, -1)}, 1))
            .empty());
  CHECK_FALSE(sdf_tree_bounds(tree_of({half, sdf_primitive(SdfKind::Sphere, {1, 0, 0}),
                                       sdf_operator(SdfKind::Intersection, 0, 1)},
                                      2))
                  .empty());
  // Convex polyhedra: a cube from six planes is bounded, three planes are not.
  SdfTree cube;
  for (int k = 0; k < 3; ++k)
    for (float s : {1.0f, -1.0f}) {
      const Vec4f pl{k == 0 ? s : 0, k == 1 ? s : 0, k == 2 ? s : 0, 0.5f};
      cube.planes.push_back(pl);
    }
  SdfNode poly;
  poly.kind = SdfKind::ConvexPolyhedron;
  poly.plane_count = 6;
  cube.nodes.push_back(poly);
  cube.root = 0;
  b = sdf_tree_bounds(cube);
  CHECK(b.lo.y == Approx(-0.5f));
  CHECK(b.hi.x == Approx(0.5f));
  cube.nodes[0].plane_count = 3;
  CHECK(sdf_tree_bounds(cube).empty());
}

TEST_CASE("CSG bounds: displacement widens its child's box by |amplitude| through the transforms",
          "[shapes][noise][quick]") {
  for (const float amplitude : {0.3f, -0.3f}) {
    SdfTree t;
    const int box = add_node(t, sdf_primitive(SdfKind::Box, {1, 0.5f, 0.25f}));
    FractalParams params;
    params.kind = FractalKind::Ridged;  // range [0, 1]: the relief only grows for amplitude < 0
    const int displaced = add_displace(t, box, amplitude, 4, params, 2);
    SdfNode scaled = sdf_operator(SdfKind::Union, displaced, displaced);
    scaled.to_local.m[0][0] = 0.5f;  // the parent's x is twice the local x
    scaled.to_local.m[1][3] = -1;    // moved up by 1
    t.root = add_node(t, scaled);
    const Bounds3f b = sdf_tree_bounds(t);
    CHECK(b.lo.x == Approx(-2 * 1.3f));
    CHECK(b.hi.x == Approx(2 * 1.3f));
    CHECK(b.lo.y == Approx(1 - 0.8f));
    CHECK(b.hi.z == Approx(0.55f));
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-4, 4);
    int inside = 0;
    for (int i = 0; i < 50000; ++i) {
      const Vec3f p{u(rng), u(rng) * 0.5f + 1, u(rng) * 0.25f};
      const bool outside_box =
          p.x < b.lo.x || p.y < b.lo.y || p.z < b.lo.z || p.x > b.hi.x || p.y > b.hi.y || p.z > b.hi.z;
      const float f = sdf_eval(t, p);
      if (outside_box) REQUIRE(f > 0);
      inside += f <= 0;
    }
    CHECK(inside > 0);
  }
}

TEST_CASE("implicit shapes hit where their analytic twins do", "[shapes]") {
  const Shape exact = analytic_shape(ShapeKind::Sphere, 1);
  const Shape traced = make_implicit_shape(tree_of({sdf_primitive(SdfKind::Sphere, {1, 0, 0})}, 0));
  const Shape exact_box = analytic_shape(ShapeKind::Box, 1, {0.5f, 1, 1.5f});
  const Shape traced_box = make_implicit_shape(tree_of({sdf_primitive(SdfKind::Box, {0.5f, 1, 1.5f})}, 0));
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3f o = Vec3f{u(rng), u(rng), u(rng)} * 4.0f;
    const Vec3f d = normalize(Vec3f{u(rng), u(rng), u(rng)} * 2.0f - o * 0.3f);
    for (const auto& [a, b] : {std::pair{&exact, &traced}, std::pair{&exact_box, &traced_box}}) {
      const float ta = hit_t(*a, o, d), tb = hit_t(*b, o, d);
      INFO("ray " << i << " o (" << o.x << ", " << o.y << ", " << o.z << ") d (" << d.x << ", " << d.y << ", "
                  << d.z << "): exact " << ta << ", traced " << tb);
      // The traced hit lies within the tracer's tolerance of the surface (a ray that only grazes
      // the silhouette may be taken as a hit), never beyond the exact hit (no leak).
      if (tb >= 0) CHECK(std::fabs(sdf_eval(b->sdf, o + d * tb)) <= 2e-5f * (1 + tb));
      if (ta < 0) continue;
      ++hits;
      REQUIRE(tb >= 0);
      CHECK(tb <= ta + 1e-5f * (1 + ta));
    }
  }
  CHECK(hits > 500);
}

TEST_CASE("sphere tracing does not leak through thin plates or at grazing angles", "[shapes]") {
  // A plate 1e-3 thick: rays from above at angles down to 3 degrees all hit it.
  const Shape plate = make_implicit_shape(tree_of({sdf_primitive(SdfKind::Box, {2, 5e-4f, 2})}, 0));
  for (float deg = 90; deg >= 3; deg -= 1) {
    const float a = deg * kPi / 180;
    const Vec3f d{std::cos(a), -std::sin(a), 0.1f * std::cos(a)};
    const Vec3f o = Vec3f{0.2f, 5e-4f, 0} - d * 3.0f;  // aimed at (0.2, top, 0)
    INFO("angle " << deg);
    CHECK(hit_t(plate, o, d) == Approx(3).margin(2e-3f));
  }
  // Rays passing a sphere at impact parameters up to 0.995 r: hit where the quadratic says.
  const Shape exact = analytic_shape(ShapeKind::Sphere, 1);
  const Shape traced = make_implicit_shape(tree_of({sdf_primitive(SdfKind::Sphere, {1, 0, 0})}, 0));
  for (float b = 0; b <= 0.995f; b += 0.005f) {
    const float ta = hit_t(exact, {b, 0, -4}, {0, 0, 1}), tb = hit_t(traced, {b, 0, -4}, {0, 0, 1});
    INFO("impact parameter " << b);
    REQUIRE(ta > 0);
    CHECK(tb == Approx(ta).margin(1e-3f));
  }
  // A thin torus tube seen edge-on.
  std::vector<SdfNode> nodes{sdf_primitive(SdfKind::Torus, {1, 0, 0}, 0.01f)};
  const Shape ring = make_implicit_shape(tree_of(nodes, 0));
  CHECK(hit_t(ring, {1, 4, 0}, {0, -1, 0}) == Approx(3.99f).margin(1e-4f));
  CHECK(hit_t(ring, {-4, 0, 0}, {1, 0, 0}) == Approx(2.99f).margin(1e-4f));
  CHECK(hit_t(ring, {0, 4, 0}, {0, -1, 0}) == -1);  // through the hole
}
