// Tests for renderer/raster/edge.h: edge functions and barycentrics against hand-computed
// values, and the top-left rule on grids of triangle pairs sharing edges (every sample covered
// exactly once).
#include "renderer/raster/edge.h"

#include <catch2/catch.hpp>
#include <random>
#include <vector>

using namespace penumbra;

namespace {
FixedPoint px(double x, double y) {
  return to_fixed(x, y);
}

// Sets up (a, b, c) in either winding, as the rasteriser does.
EdgeTriangle setup(FixedPoint a, FixedPoint b, FixedPoint c) {
  if (edge_function(a, b, c) < 0) std::swap(b, c);
  return make_edge_triangle(a, b, c);
}
}  // namespace

TEST_CASE("edge functions and barycentrics match hand-computed values", "[raster][quick]") {
  // Raster space, y down: (0,0), (4,0), (0,4) turn clockwise on screen; twice the area is
  // 16 pixels^2 = 16 * 4096^2 units.
  const FixedPoint a = px(0, 0), b = px(4, 0), c = px(0, 4);
  CHECK(edge_function(a, b, c) == 16 * 4096 * 4096);
  CHECK(edge_function(a, c, b) == -16 * 4096 * 4096);
  const EdgeTriangle t = make_edge_triangle(a, b, c);
  CHECK(t.area2 == 16 * 4096 * 4096);
  // At (1, 2): the barycentric of a is the area of (b, c, p) over the whole: (4 - 1 - 2) / 4.
  int64_t e[3];
  REQUIRE(edge_inside(t, px(1, 2), e));
  double l[3];
  edge_barycentrics(t, e, l);
  CHECK(l[0] == Approx(0.25));
  CHECK(l[1] == Approx(0.25));  // x / 4
  CHECK(l[2] == Approx(0.5));   // y / 4
  CHECK(e[0] + e[1] + e[2] == t.area2);
  // Outside beyond the hypotenuse, and a vertex is inside with weight 1.
  CHECK_FALSE(edge_inside(t, px(3, 3), e));
  REQUIRE(edge_inside(t, a, e));
  edge_barycentrics(t, e, l);
  CHECK(l[0] == 1);
  CHECK(l[1] == 0);
  CHECK(l[2] == 0);
  // Snapping: 1/4096 pixel.
  CHECK(px(0.5, -0.25).x == 2048);
  CHECK(px(0.5, -0.25).y == -1024);
}

TEST_CASE("top-left rule: samples on edges belong to the top or left edge's triangle", "[raster][quick]") {
  // Square (0,0)-(2,2) split along its diagonal; samples on the diagonal, on the top edge and on
  // the left edge are inside; on the right and bottom edges outside.
  const EdgeTriangle upper = setup(px(0, 0), px(2, 0), px(2, 2));  // above the diagonal
  const EdgeTriangle lower = setup(px(0, 0), px(2, 2), px(0, 2));
  int64_t e[3];
  const FixedPoint diagonal = px(1, 1), top = px(1, 0), left = px(0, 1), right = px(2, 1), bottom = px(1, 2);
  CHECK(edge_inside(upper, diagonal, e) != edge_inside(lower, diagonal, e));
  CHECK(edge_inside(upper, top, e));
  CHECK(edge_inside(lower, left, e));
  CHECK_FALSE(edge_inside(upper, right, e));
  CHECK_FALSE(edge_inside(lower, bottom, e));
  // Horizontal edge shared by a triangle above and one below: only the one below (whose top
  // edge it is) covers samples on it.
  const EdgeTriangle above = setup(px(0, 0), px(4, 2), px(-2, 2));
  const EdgeTriangle below = setup(px(-2, 2), px(4, 2), px(1, 5));
  CHECK_FALSE(edge_inside(above, px(1, 2), e));
  CHECK(edge_inside(below, px(1, 2), e));
}

TEST_CASE("top-left rule: a grid of triangle pairs covers every sample exactly once", "[raster][quick]") {
  // A 16 x 16 pixel area cut into a jittered grid of quads, each split in two triangles along a
  // random diagonal, in random windings; vertices on sample centres and sub-pixel positions.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  constexpr int n = 8;  // cells of 2 x 2 pixels
  std::vector<FixedPoint> grid((n + 1) * (n + 1));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = 2.0 * i, y = 2.0 * j;
      const bool border = i == 0 || j == 0 || i == n || j == n;
      if (!border && (i + j) % 3 == 0) {
        x += 0.5;  // on a column of pixel centres: samples fall on edges and vertices
      } else if (!border) {
        x += jitter(rng);
        y += jitter(rng);
      }
      grid[size_t(j * (n + 1) + i)] = px(x, y);
    }
  std::vector<EdgeTriangle> tris;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const FixedPoint a = grid[size_t(j * (n + 1) + i)], b = grid[size_t(j * (n + 1) + i + 1)];
      const FixedPoint c = grid[size_t((j + 1) * (n + 1) + i + 1)], d = grid[size_t((j + 1) * (n + 1) + i)];
      if (rng() & 1) {
        tris.push_back(setup(a, b, c));
        tris.push_back(setup(c, d, a));
      } else {
        tris.push_back(setup(b, c, d));
        tris.push_back(setup(d, a, b));
      }
    }
  // Samples: pixel centres, pixel corners and sub-pixel positions, over the inside of the
  // area (the outer border belongs to whoever lies beyond it).
  int covered_once = 0, wrong = 0;
  for (int y = 1; y < 16 * 4; ++y)
    for (int x = 1; x < 16 * 4; ++x) {
      const FixedPoint p = px(x * 0.25, y * 0.25);
      int hits = 0;
      int64_t e[3];
      for (const EdgeTriangle& t : tris) hits += edge_inside(t, p, e);
      if (hits == 1)
        ++covered_once;
      else
        ++wrong;
    }
  CHECK(wrong == 0);
  CHECK(covered_once == 63 * 63);
}
