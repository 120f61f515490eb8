// Tests for renderer/accel/common: the slab test for rays through a box's faces, edges and
// corners, rays parallel to a slab, signed zeros, and NaN or infinite components (which the
// slab test must never turn into NaN distances; is_valid_query turns such rays away first),
// and the packed triangle array.
#include "renderer/accel/common.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

using namespace penumbra;

namespace {
const Vec3f kLo{0, 0, 0}, kHi{1, 1, 1};

// The slab test over [0, inf) of the unit box, with the narrowed range.
bool slab(const Ray& r, float& t0, float& t1) {
  t0 = 0;
  t1 = kInfinity;
  return intersect_box(kLo, kHi, prepare_box_query(r), t0, t1);
}
bool slab(const Ray& r) {
  float t0, t1;
  return slab(r, t0, t1);
}
}  // namespace

TEST_CASE("slab test: entry and exit distances through faces, edges and corners", "[accel][quick]") {
  float t0, t1;
  REQUIRE(slab({{-1, 0.5f, 0.5f}, 0, {1, 0, 0}, kInfinity}, t0, t1));  // through two faces
  CHECK(t0 == Approx(1));
  CHECK(t1 == Approx(2));
  REQUIRE(slab({{-1, -1, -1}, 0, {1, 1, 1}, kInfinity}, t0, t1));  // corner to corner
  CHECK(t0 == Approx(1));
  CHECK(t1 == Approx(2));
  REQUIRE(slab({{-1, 0, 0}, 0, {1, 0, 0}, kInfinity}, t0, t1));  // along an edge
  CHECK(t0 == Approx(1));
  CHECK(t1 == Approx(2));
  CHECK(slab({{0, -1, 0.5f}, 0, {1, 1, 0}, kInfinity}));               // touching only the edge x = 1, y = 0
  CHECK(slab({{2, 2, 2}, 0, {-1, -1, -1}, kInfinity}));                // into the corner (1, 1, 1)
  CHECK(slab({{0.5f, 0.5f, 0.5f}, 0, {0, 0, 1}, kInfinity}, t0, t1));  // from inside
  CHECK(t0 == 0);
  CHECK(t1 == Approx(0.5f));
}

TEST_CASE("slab test: misses, parallel rays and signed zeros", "[accel][quick]") {
  CHECK_FALSE(slab({{0.1f, -1, 0.5f}, 0, {1, 1, 0}, kInfinity}));   // passes that edge outside
  CHECK_FALSE(slab({{-1, 0.5f, 0.5f}, 0, {-1, 0, 0}, kInfinity}));  // points away
  CHECK_FALSE(slab({{0.5f, 2, 0.5f}, 0, {1, 0, 0}, kInfinity}));    // parallel, outside in y
  CHECK(slab({{-1, 1, 0.5f}, 0, {1, 0, 0}, kInfinity}));            // parallel, on the face y = 1
  CHECK(slab({{-1, 0, 0.5f}, 0, {1, -0.0f, 0}, kInfinity}));        // -0 is parallel too
  const RayBoxQuery q = prepare_box_query({{0, 0, 0}, 0, {1, -0.0f, -2}, kInfinity});
  CHECK(q.dir_neg[0] == 0);
  CHECK(q.dir_neg[1] == 1);
  CHECK(q.dir_neg[2] == 1);
  float t0 = 0, t1 = 0.5f;  // the range ends before the box
  CHECK_FALSE(
      intersect_box(kLo, kHi, prepare_box_query({{-1, 0.5f, 0.5f}, 0, {1, 0, 0}, kInfinity}), t0, t1));
}

TEST_CASE("slab test: NaN and infinite components never give NaN distances", "[accel][quick]") {
  const float nan = std::nanf("");
  for (const Ray& r :
       {Ray{{-1, 0.5f, 0.5f}, 0, {nan, 0, 0}, kInfinity}, Ray{{nan, 0.5f, 0.5f}, 0, {1, 0, 0}, kInfinity},
        Ray{{-1, 0.5f, 0.5f}, 0, {kInfinity, 0, 0}, kInfinity},
        Ray{{-1, 0.5f, 0.5f}, 0, {1, -kInfinity, 0}, kInfinity},
        Ray{{-kInfinity, 0.5f, 0.5f}, 0, {1, 0, 0}, kInfinity}}) {
    float t0, t1;
    if (slab(r, t0, t1)) {
      CHECK_FALSE(std::isnan(t0));
      CHECK_FALSE(std::isnan(t1));
    }
    CHECK_FALSE(is_valid_query(r));  // every back end turns these away before any slab test
  }
}

TEST_CASE("gather_primitives: mesh order, ids, and non-finite triangles dropped", "[accel][quick]") {
  const std::vector<Vec3f> a{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, std::nanf("")}};
  const std::vector<uint32_t> ai{0, 1, 2, 0, 1, 3};
  const std::vector<Vec3f> b{{0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
  const std::vector<uint32_t> bi{0, 1, 2, 2, 1, 0};
  Shape sphere;
  sphere.radius = 2;
  SdfTree half_space;
  half_space.nodes = {SdfNode{SdfKind::HalfSpace}};
  half_space.root = 0;
  const Shape unbounded = make_implicit_shape(half_space);
  const std::vector<GeometryView> views{{a, ai}, {{}, {}, &unbounded}, {b, bi}, {{}, {}, &sphere}};
  std::vector<Shape> shapes;
  const std::vector<PrimitiveRecord> tris = gather_primitives(views, shapes);
  REQUIRE(tris.size() == 4);
  // The sphere is one record holding its bounds and its index in the shape table; the
  // unbounded half-space is dropped.
  REQUIRE(shapes.size() == 1);
  CHECK(shapes[0].radius == 2);
  CHECK(is_shape(tris[3]));
  CHECK(tris[3].geom_id == 3);
  CHECK((tris[3].prim_id & ~kShapeBit) == 0);
  CHECK(primitive_bounds(tris[3]).lo.x == -2);
  CHECK(primitive_bounds(tris[3]).hi.z == 2);
  CHECK_FALSE(is_shape(tris[0]));
  CHECK(count_input_shapes(views) == 2);
  CHECK((tris[0].geom_id == 0 && tris[0].prim_id == 0));
  CHECK((tris[1].geom_id == 2 && tris[1].prim_id == 0));
  CHECK((tris[2].geom_id == 2 && tris[2].prim_id == 1));
  CHECK(tris[2].a.y == 1);
  CHECK(count_input_triangles(views) == 4);
  CHECK(surface_area(Bounds3f{kLo, kHi}) == Approx(6));
  CHECK(surface_area(Bounds3f{}) == 0);
}
