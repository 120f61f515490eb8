// Point and line sizes: parsed, converted from pixels at each vertex's depth, and the file's own
// sizes kept.
#include "renderer/scene/curve_size.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>

using namespace penumbra;

TEST_CASE("curve sizes: pixels or scene units, anything else refused", "[curves][quick]") {
  const CurveSize px = parse_curve_size("2.5px", "point_size");
  CHECK((px.pixels && px.value == 2.5f));
  const CurveSize units = parse_curve_size("0.01", "line_width");
  CHECK((!units.pixels && units.value == 0.01f));
  for (const char* bad : {"", "px", "0", "-2px", "2 px", "2pix", "nan", "inf", "1e30px", "x1"}) {
    INFO(bad);
    CHECK_THROWS_WITH(parse_curve_size(bad, "line_width"), Catch::Contains("line_width"));
  }
}

TEST_CASE("curve sizes: pixel footprints and the radii set from them", "[curves][quick]") {
  Camera cam = look_at({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 0.5f);
  // Perspective: 2 d tan(fov / 2) / height at depth d along the view axis.
  CHECK(pixel_footprint(cam, 100, {3, 1, 2}) == Approx(2 * 8 * std::tan(0.25f) / 100));
  Scene s;
  Mesh pts = make_point_set({{0, 0, 0}, {0, 0, -10}}, "pts");
  s.meshes.push_back(pts);
  s.instances.push_back(make_instance(0, Affine3f{}));
  Mesh lines = pts;
  lines.points = false;
  lines.lines = true;
  lines.indices = {0, 1, 1};
  lines.radii = {0.5f, 0.5f};
  lines.file_radii = true;  // the file's radii stay
  s.meshes.push_back(lines);
  s.instances.push_back(make_instance(1, Affine3f{}));
  Affine3f doubled;
  doubled.m[0][0] = doubled.m[1][1] = doubled.m[2][2] = 2;
  s.meshes.push_back(pts);  // placed at twice the size: object-space radii halve
  s.instances.push_back(make_instance(2, doubled));
  set_curve_radii(s, cam, 100, {4, true}, {1, true});
  REQUIRE(s.meshes[0].radii.size() == 2);
  CHECK(s.meshes[0].radii[0] == Approx(2 * pixel_footprint(cam, 100, {0, 0, 0})));
  CHECK(s.meshes[0].radii[1] == Approx(2 * pixel_footprint(cam, 100, {0, 0, -10})));
  CHECK(s.meshes[0].radii[1] == Approx(2 * s.meshes[0].radii[0]));  // twice as deep, twice as wide
  CHECK(s.meshes[1].radii == std::vector<float>{0.5f, 0.5f});
  CHECK(s.meshes[2].radii[1] == Approx(0.5f * 2 * pixel_footprint(cam, 100, {0, 0, -20})));
  // Scene units, and orthographic footprints.
  set_curve_radii(s, cam, 100, {0.2f, false}, {1, true});
  CHECK(s.meshes[0].radii == std::vector<float>{0.1f, 0.1f});
  CHECK(s.meshes[2].radii[0] == Approx(0.05f));
  cam.projection = Projection::Orthographic;
  cam.ymag = 5;
  CHECK(pixel_footprint(cam, 100, {0, 0, -50}) == Approx(0.1f));
}
