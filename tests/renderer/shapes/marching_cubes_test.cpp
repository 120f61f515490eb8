// Tests for renderer/shapes/marching_cubes: closed, manifold, outward meshes for primitives, CSG
// and smooth blends; Euler characteristics from each shape's genus; area and volume against
// closed forms; vertices on the surface; the same bytes for any thread count; ambiguous faces.
#include "renderer/shapes/marching_cubes.h"

#include <tbb/task_arena.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>

#include "support/mesh_checks.h"
#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

Bounds3f cube(float h) {
  return {{-h, -h, -h}, {h, h, h}};
}

MeshTopology topology(const IsosurfaceMesh& m) {
  return mesh_topology(m.positions.size(), m.indices);
}

// The largest |f(v)| / L over the vertices, in cells.
double max_vertex_error_cells(const SdfTree& tree, const IsosurfaceMesh& m, const Bounds3f& box, int res) {
  const float cell = marching_cubes_grid(box, res, {}).cell, l = sdf_lipschitz(tree);
  double worst = 0;
  for (const Vec3f& p : m.positions) worst = std::max(worst, double(std::abs(sdf_eval(tree, p)) / l / cell));
  return worst;
}

bool same_bytes(const IsosurfaceMesh& a, const IsosurfaceMesh& b) {
  return a.positions.size() == b.positions.size() && a.indices.size() == b.indices.size() &&
         std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3f)) == 0 &&
         std::memcmp(a.normals.data(), b.normals.data(), a.normals.size() * sizeof(Vec3f)) == 0 &&
         std::memcmp(a.indices.data(), b.indices.data(), a.indices.size() * sizeof(uint32_t)) == 0;
}

struct ClosedForm {
  const char* name;
  SdfTree tree;
  Bounds3f box;
  double area, volume;
};

std::vector<ClosedForm> closed_forms() {
  const double pi = 3.14159265358979323846;
  std::vector<ClosedForm> shapes;
  shapes.push_back(
      {"sphere", single_shape(sdf_primitive(SdfKind::Sphere, {1, 0, 0})), cube(1), 4 * pi, 4 * pi / 3});
  {
    const double major = 1, minor = 0.35;
    shapes.push_back({"torus",
                      single_shape(sdf_primitive(SdfKind::Torus, {1, 0, 0}, 0.35f)),
                      {{-1.35f, -0.35f, -1.35f}, {1.35f, 0.35f, 1.35f}},
                      4 * pi * pi * major * minor,
                      2 * pi * pi * major * minor * minor});
  }
  {
    // Faces at 0.8, 0.7 and 0.6 fall on grid planes: f is zero (up to rounding) at grid points.
    // Marching cubes chamfers the 12 edges over about a cell, which costs ~0.7% of the area.
    const Vec3f h{0.8f, 0.7f, 0.6f};
    shapes.push_back({"box",
                      single_shape(sdf_primitive(SdfKind::Box, h)),
                      {-h, h},
                      8 * (h.x * h.y + h.y * h.z + h.x * h.z),
                      8.0 * h.x * h.y * h.z});
  }
  {
    // Steiner: the inner box b grown by r: faces, quarter cylinders along the edges, a sphere.
    const double r = 0.1, bx = 0.7, by = 0.4, bz = 0.2;
    const Vec3f h{0.8f, 0.5f, 0.3f};
    shapes.push_back({"rounded box",
                      single_shape(sdf_primitive(SdfKind::RoundBox, h, 0.1f)),
                      {-h, h},
                      8 * (bx * by + by * bz + bx * bz) + 4 * pi * r * (bx + by + bz) + 4 * pi * r * r,
                      8 * bx * by * bz + 8 * r * (bx * by + by * bz + bx * bz) +
                          2 * pi * r * r * (bx + by + bz) + 4 * pi * r * r * r / 3});
  }
  {
    const double r = 0.3, half = 0.6;
    shapes.push_back({"capsule",
                      single_shape(sdf_primitive(SdfKind::Capsule, {0, 0.6f, 0}, 0.3f)),
                      {{-0.3f, -0.9f, -0.3f}, {0.3f, 0.9f, 0.3f}},
                      4 * pi * r * r + 2 * pi * r * 2 * half,
                      4 * pi * r * r * r / 3 + pi * r * r * 2 * half});
  }
  return shapes;
}

}  // namespace

TEST_CASE("marching cubes: closed forms give closed meshes with their area and volume", "[shapes][mc]") {
  for (const ClosedForm& s : closed_forms()) {
    INFO(s.name);
    const IsosurfaceMesh m = extract_isosurface(s.tree, s.box, 128);
    REQUIRE(!m.indices.empty());
    REQUIRE(m.normals.size() == m.positions.size());
    const MeshTopology t = topology(m);
    CHECK(t.closed_manifold());
    CHECK(t.unused_vertices == 0);
    CHECK(t.euler == (std::string(s.name) == "torus" ? 0 : 2));
    CHECK(mesh_area(m.positions, m.indices) == Approx(s.area).epsilon(0.01));
    CHECK(mesh_volume(m.positions, m.indices) == Approx(s.volume).epsilon(0.01));
    CHECK(max_vertex_error_cells(s.tree, m, s.box, 128) <= 1.0);
    for (const Vec3f& n : m.normals) CHECK(std::abs(length(n) - 1) < 1e-4f);
  }
}

TEST_CASE("marching cubes: a sphere's normals and faces point outwards", "[shapes][mc][quick]") {
  const SdfTree sphere = single_shape(sdf_primitive(SdfKind::Sphere, {1, 0, 0}));
  for (int res : {4, 17, 40}) {
    INFO("resolution " << res);
    const IsosurfaceMesh m = extract_isosurface(sphere, cube(1), res);
    CHECK(topology(m).closed_manifold());
    CHECK(topology(m).euler == 2);
    size_t inward_normals = 0, inward_faces = 0;
    for (size_t v = 0; v < m.positions.size(); ++v) inward_normals += dot(m.normals[v], m.positions[v]) <= 0;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
      const Vec3f a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]],
                  c = m.positions[m.indices[t + 2]];
      inward_faces += dot(cross(b - a, c - a), a + b + c) < 0;
    }
    CHECK(inward_normals == 0);
    CHECK(inward_faces == 0);
    CHECK(mesh_volume(m.positions, m.indices) > 0);
    CHECK(max_vertex_error_cells(sphere, m, cube(1), res) <= 1.0);
  }
}

TEST_CASE("marching cubes: the CSG part and a smooth blend have their genus", "[shapes][mc][quick]") {
  const SdfTree part = csg_part();
  for (int res : {48, 96}) {
    INFO("CSG part at " << res);
    const IsosurfaceMesh m = extract_isosurface(part, cube(1), res);
    const MeshTopology t = topology(m);
    CHECK(t.closed_manifold());
    CHECK(t.euler == -8);  // genus 5, see csg_part()
    CHECK(mesh_volume(m.positions, m.indices) > 0);
    CHECK(max_vertex_error_cells(part, m, cube(1), res) <= 1.0);
  }
  // Two spheres of radius 0.5 whose centres are 0.9 apart, smoothly joined: one blob.
  const SdfTree blob = sphere_pair(0.5f, 0.45f, 0.3f);
  const Bounds3f box{{-0.95f, -0.5f, -0.5f}, {0.95f, 0.5f, 0.5f}};
  const IsosurfaceMesh m = extract_isosurface(blob, box, 64);
  CHECK(topology(m).closed_manifold());
  CHECK(topology(m).euler == 2);
  CHECK(max_vertex_error_cells(blob, m, box, 64) <= 1.0);
}

TEST_CASE("marching cubes: a displaced sphere meshes to its relief, not to the sphere",
          "[shapes][mc][noise][quick]") {
  // Radius 1, amplitude 0.15, fBm at frequency 2: every point of the surface lies within 0.15
  // of the unit sphere, and the relief spans much of that.
  const SdfTree rough = displaced_sphere(1, 0.15f, 2, FractalKind::Fbm, 3);
  const Bounds3f box = sdf_tree_bounds(rough);
  CHECK(box.hi.x == Approx(1.15f));
  const int res = 96;
  const IsosurfaceMesh m = extract_isosurface(rough, box, res);
  REQUIRE(!m.positions.empty());
  CHECK(topology(m).closed_manifold());
  CHECK(max_vertex_error_cells(rough, m, box, res) <= 1.0);
  const float cell = marching_cubes_grid(box, res, {}).cell;
  float nearest = kInfinity, farthest = 0;
  for (const Vec3f& p : m.positions) {
    nearest = std::min(nearest, length(p)), farthest = std::max(farthest, length(p));
    REQUIRE(std::abs(length(p) - 1) <= 0.15f + cell);
  }
  INFO("vertex radii in [" << nearest << ", " << farthest << "]");
  CHECK(farthest - nearest > 0.1f);  // a plain sphere's would be within a cell
}

TEST_CASE("marching cubes: ambiguous faces still give closed manifolds", "[shapes][mc][quick]") {
  SECTION("two spheres almost touching, at many resolutions") {
    // The gap of 0.002 lies in one cell: the faces there are saddles the decider must settle
    // alike from both sides; the result is two spheres (4) or one joined surface (2).
    const SdfTree pair = sphere_pair(0.5f, 0.501f);
    const Bounds3f box{{-1.001f, -0.5f, -0.5f}, {1.001f, 0.5f, 0.5f}};
    for (int res = 3; res <= 40; ++res) {
      INFO("resolution " << res);
      const IsosurfaceMesh m = extract_isosurface(pair, box, res);
      const MeshTopology t = topology(m);
      CHECK(t.closed_manifold());
      CHECK((t.euler == 2 || t.euler == 4));
    }
  }
  SECTION("a thin torus at low resolution") {
    // Tube thinner than a cell: it breaks into pieces, each closed.
    const SdfTree torus = single_shape(sdf_primitive(SdfKind::Torus, {1, 0, 0}, 0.06f));
    const Bounds3f box{{-1.06f, -0.06f, -1.06f}, {1.06f, 0.06f, 1.06f}};
    for (int res = 5; res <= 24; ++res) {
      INFO("resolution " << res);
      const IsosurfaceMesh m = extract_isosurface(torus, box, res);
      const MeshTopology t = topology(m);
      CHECK(t.closed_manifold());
      CHECK(t.euler % 2 == 0);
    }
  }
  SECTION("random sphere soups at the scale of a cell") {
    // Many small spheres with radii near the cell size make every kind of cell and face case.
    // Some loops there need the extra centre vertex (a vertex off every grid line).
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> pos(-1, 1), rad(0.05f, 0.2f);
    int centre_vertices = 0;
    for (int trial = 0; trial < 40; ++trial) {
      SdfTree t;
      int root = -1;
      for (int s = 0; s < 40; ++s) {
        SdfNode n = sdf_primitive(SdfKind::Sphere, {rad(rng), 0, 0});
        n.to_local = moved_by({pos(rng), pos(rng), pos(rng)});
        const int id = add_node(t, n);
        root = root < 0 ? id
                        : add_node(t, sdf_operator(trial % 2 ? SdfKind::SmoothUnion : SdfKind::Union, root,
                                                   id, 0.1f));
      }
      t.root = root;
      INFO("trial " << trial);
      const int res = 12 + trial % 13;
      const IsosurfaceMesh m = extract_isosurface(t, cube(1.2f), res);
      const MeshTopology top = topology(m);
      CHECK(top.closed_manifold());
      CHECK(top.euler % 2 == 0);
      const MarchingCubesGrid g = marching_cubes_grid(cube(1.2f), res, {});
      for (const Vec3f& p : m.positions) {
        int on_grid_planes = 0;
        for (int a = 0; a < 3; ++a) {
          const float q = (p[a] - g.origin[a]) / g.cell;
          on_grid_planes += std::abs(q - std::round(q)) < 1e-4f;
        }
        centre_vertices += on_grid_planes < 2;
      }
    }
    CHECK(centre_vertices > 0);
  }
  SECTION("the complement of a sphere: the same surface facing inwards") {
    SdfTree t = single_shape(sdf_primitive(SdfKind::Sphere, {1, 0, 0}));
    t.root = add_node(t, sdf_operator(SdfKind::Complement, t.root));
    const IsosurfaceMesh m = extract_isosurface(t, cube(1), 32);
    CHECK(topology(m).closed_manifold());
    CHECK(mesh_volume(m.positions, m.indices) == Approx(-4 * 3.14159265 / 3).epsilon(0.02));
    for (size_t v = 0; v < m.positions.size(); ++v) CHECK(dot(m.normals[v], m.positions[v]) < 0);
  }
}

TEST_CASE("marching cubes: the same bytes for any thread count", "[shapes][mc][quick]") {
  const SdfTree part = csg_part();
  IsosurfaceMesh one;
  tbb::task_arena(1).execute([&] { one = extract_isosurface(part, cube(1), 64); });
  const IsosurfaceMesh all = extract_isosurface(part, cube(1), 64);
  REQUIRE(!one.indices.empty());
  CHECK(same_bytes(one, all));
}

TEST_CASE("marching cubes: skipping far blocks gives the same bytes", "[shapes][mc][quick]") {
  // Blocks far from the surface only need their sign; every value a vertex, a decider or a
  // triangulation reads is still evaluated.
  MarchingCubesConfig every_point;
  every_point.skip_far_blocks = false;
  std::vector<std::pair<SdfTree, Bounds3f>> cases = {{csg_part(), cube(1)},
                                                     {sphere_pair(0.5f, 0.45f, 0.3f), cube(1)},
                                                     {sphere_pair(0.5f, 0.501f), cube(1.01f)}};
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> pos(-1, 1), rad(0.05f, 0.3f);
  SdfTree soup;
  for (int s = 0; s < 30; ++s) {
    SdfNode n = sdf_primitive(SdfKind::Sphere, {rad(rng), 0, 0});
    n.to_local = moved_by({pos(rng), pos(rng), pos(rng)});
    const int id = add_node(soup, n);
    soup.root = soup.root < 0 ? id : add_node(soup, sdf_operator(SdfKind::SmoothUnion, soup.root, id, 0.1f));
  }
  cases.push_back({soup, cube(1.3f)});
  for (size_t c = 0; c < cases.size(); ++c)
    for (int res : {7, 16, 61, 100}) {
      INFO("case " << c << " at " << res);
      const IsosurfaceMesh skipped = extract_isosurface(cases[c].first, cases[c].second, res);
      const IsosurfaceMesh full = extract_isosurface(cases[c].first, cases[c].second, res, every_point);
      REQUIRE(!full.indices.empty());
      CHECK(same_bytes(skipped, full));
    }
}

TEST_CASE("marching cubes: the grid and its memory", "[shapes][mc][quick]") {
  const Bounds3f box{{0, 0, 0}, {2, 1, 0.01f}};
  const MarchingCubesGrid g = marching_cubes_grid(box, 10, {});
  CHECK(g.cell == Approx(0.2f));
  CHECK(g.n[0] == 10 + 4);
  CHECK(g.n[1] == 5 + 4);
  CHECK(g.n[2] == 1 + 4);  // at least one cell, plus the padding
  for (int a = 0; a < 3; ++a)
    CHECK(g.origin[a] + 0.5f * g.cell * float(g.n[a]) == Approx(box.center()[a]).margin(1e-6));
  // The grid values alone take 4 bytes per grid point; a convex shape's mesh fits the estimate.
  const SdfTree sphere = single_shape(sdf_primitive(SdfKind::Sphere, {1, 0, 0}));
  const MarchingCubesGrid sg = marching_cubes_grid(cube(1), 64, {});
  const uint64_t points = uint64_t(sg.n[0] + 1) * uint64_t(sg.n[1] + 1) * uint64_t(sg.n[2] + 1);
  const uint64_t bytes = marching_cubes_bytes(cube(1), 64);
  CHECK(bytes > 4 * points);
  const IsosurfaceMesh m = extract_isosurface(sphere, cube(1), 64);
  CHECK(bytes - 4 * points >= mesh_bytes(m.positions.size(), m.indices.size() / 3));
  // A budget below the mesh's size is refused before the mesh is built.
  MarchingCubesConfig tight;
  tight.max_output_bytes = mesh_bytes(m.positions.size(), m.indices.size() / 3) - 1;
  CHECK_THROWS_AS(extract_isosurface(sphere, cube(1), 64, tight), std::length_error);
  tight.max_output_bytes += 1;
  CHECK(extract_isosurface(sphere, cube(1), 64, tight).indices == m.indices);
}

TEST_CASE("marching cubes: bad resolutions, boxes and settings throw", "[shapes][mc][quick]") {
  const SdfTree sphere = single_shape(sdf_primitive(SdfKind::Sphere, {1, 0, 0}));
  for (int res : {0, -1, kMaxMarchingCubesResolution + 1})
    CHECK_THROWS_AS(extract_isosurface(sphere, cube(1), res), std::invalid_argument);
  CHECK_THROWS_AS(marching_cubes_bytes(cube(1), 0), std::invalid_argument);
  CHECK_THROWS_AS(extract_isosurface(sphere, Bounds3f{}, 8), std::invalid_argument);
  CHECK_THROWS_AS(extract_isosurface(sphere, Bounds3f{{0, 0, 0}, {0, 0, 0}}, 8), std::invalid_argument);
  CHECK_THROWS_AS(extract_isosurface(sphere, Bounds3f{{0, 0, 0}, {kInfinity, 1, 1}}, 8),
                  std::invalid_argument);
  MarchingCubesConfig c;
  c.padding = -1;
  CHECK_THROWS_AS(extract_isosurface(sphere, cube(1), 8, c), std::invalid_argument);
  c = {};
  c.normal_step = 0;
  CHECK_THROWS_AS(extract_isosurface(sphere, cube(1), 8, c), std::invalid_argument);
  // A shape outside the box gives an empty mesh; one cut by the grid's edge is open.
  CHECK(extract_isosurface(sphere, Bounds3f{{5, 5, 5}, {6, 6, 6}}, 8).indices.empty());
  MarchingCubesConfig unpadded;
  unpadded.padding = 0;
  const IsosurfaceMesh cut = extract_isosurface(sphere, Bounds3f{{0, -1, -1}, {1, 1, 1}}, 16, unpadded);
  CHECK(topology(cut).edges_without_twin > 0);
}
