// Tests for renderer/accel/bvh: structural invariants of the binned-SAH build, its
// configuration, and exact agreement with brute force under non-default settings.
#include "renderer/accel/bvh.h"

#include <tbb/task_arena.h>

#include <catch2/catch.hpp>

#include "io/gltf/loader.h"
#include "renderer/accel/bvh_wide.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/scene/scene.h"
#include "support/cross_check.h"
#include "support/sdf_trees.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {
std::vector<Ray> scene_rays(const LoadedScene& l, const Accelerator& ref,
                            std::span<const GeometryView> views) {
  const Bounds3f b = compute_bounds(l.scene);
  return all_rays(ref, views, b, lights_around(b), 1, 99);
}
}  // namespace

TEST_CASE("bvh: leaves respect max_leaf_size, every triangle is referenced once, a binary tree",
          "[accel][bvh]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  for (int leaf : {1, 4, 8}) {
    BvhConfig c;
    c.width = 2;
    c.max_leaf_size = leaf;
    const AccelStats s = make_bvh_accelerator(views, c)->stats();
    INFO("max_leaf_size " << leaf);
    CHECK(s.max_leaf_prims <= uint64_t(leaf));
    CHECK(s.references == s.triangles);  // a BVH partitions: no duplicates
    CHECK(s.nodes == 2 * s.leaves - 1);  // binary
    CHECK(s.empty_leaves == 0);
    CHECK(s.avg_leaf_prims == Approx(double(s.triangles) / double(s.leaves)));
    CHECK(s.max_depth >= uint64_t(std::ceil(std::log2(double(s.triangles) / leaf))));
    CHECK(s.bytes == s.nodes * 32 + s.triangles * 44);
    // SAH cost of the tree is below that of one leaf holding everything.
    CHECK(s.sah_cost > 0);
    CHECK(s.sah_cost < double(s.triangles));
  }
}

namespace {
/// The wide widths this CPU runs.
std::vector<int> wide_widths() {
  if (cpu_has_avx2()) return {4, 8};
  return {4};
}
}  // namespace

TEST_CASE("bvh: widths 4 and 8 collapse the binary tree into wide nodes of 128 bytes with leaf blocks",
          "[accel][bvh]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  for (int width : wide_widths())
    for (int leaf : {1, 4, 8}) {
      BvhConfig c2, cw;
      c2.width = 2;
      cw.width = width;
      c2.max_leaf_size = cw.max_leaf_size = leaf;
      const AccelStats s2 = make_bvh_accelerator(views, c2)->stats(),
                       s = make_bvh_accelerator(views, cw)->stats();
      INFO("width " << width << ", max_leaf_size " << leaf);
      CHECK(s.config.find("width " + std::to_string(width)) != std::string::npos);
      CHECK(s.references == s.triangles);
      CHECK(s.max_leaf_prims <= uint64_t(leaf));
      // Every wide node has 2 to `width` children and all but the root are someone's child.
      const uint64_t interior = s.nodes - s.leaves;
      CHECK(s.nodes - 1 <= uint64_t(width) * interior);
      CHECK(s.nodes - 1 >= 2 * interior);
      // Shallower than the binary tree, and no shallower than a perfect width-ary one.
      CHECK(s.max_depth < s2.max_depth);
      CHECK(s.max_depth >=
            uint64_t(std::ceil(std::log(double(s.triangles) / leaf) / std::log(double(width)))));
      // 128-byte nodes and 160-byte blocks of four: at least ceil(n / 4) blocks, at most one
      // partly filled block per leaf; plus a word per view for the hit ids.
      const uint64_t min_blocks = (s.triangles + 3) / 4, max_blocks = s.triangles / 4 + s.leaves;
      const uint64_t ids = (views.size() + 1) * 4;
      CHECK(s.bytes >= interior * 128 + min_blocks * 160 + ids);
      CHECK(s.bytes <= interior * 128 + max_blocks * 160 + ids);
      CHECK(s.sah_cost > 0);
    }
}

TEST_CASE("bvh: width 0 is the CPU's widest; width 8 needs AVX2", "[accel][bvh][quick]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  const AccelStats s = make_bvh_accelerator(views)->stats();
  CHECK(s.config.find(cpu_has_avx2() ? "width 8" : "width 4") != std::string::npos);
  BvhConfig c;
  c.width = 8;
  if (cpu_has_avx2())
    CHECK_NOTHROW(make_bvh_accelerator(views, c));
  else
    CHECK_THROWS_WITH(make_bvh_accelerator(views, c), Catch::Contains("AVX2"));
}

TEST_CASE("bvh: quantised 8-wide boxes contain their children", "[accel][bvh][quick]") {
  // Child boxes of every scale and position, degenerate ones included: each decoded box must
  // contain its child exactly (no ray that meets a child may miss its decoded box).
  Rng rng;
  const float scales[] = {1e-42f, 1e-36f, 1e-30f, 1e-6f, 1.0f, 3e4f, 1e30f};  // subnormal extents too
  const float offsets[] = {0.0f, -1.0f, 1e7f, -3e20f, 1e36f};
  for (float scale : scales)
    for (float offset : offsets)
      for (int trial = 0; trial < 50; ++trial) {
        Bounds3f boxes[8];
        const int n = 1 + int(rng.next_float() * 8) % 8;
        for (int i = 0; i < n; ++i) {
          Vec3f a, b;
          for (int k = 0; k < 3; ++k) {
            a[k] = offset + scale * (rng.next_float() - 0.5f);
            b[k] = trial % 5 == 0 ? a[k] : offset + scale * (rng.next_float() - 0.5f);  // flat boxes too
          }
          boxes[i] = merge(Bounds3f{a, a}, b);
        }
        QuantizedNode8 node{};
        set_child_boxes(node, boxes, n);
        INFO("scale " << scale << ", offset " << offset << ", trial " << trial);
        CHECK(node.valid == (1u << n) - 1);
        for (int i = 0; i < n; ++i)
          for (int k = 0; k < 3; ++k) {
            CHECK(node.dequantize(k, node.qlo[k][i]) <= boxes[i].lo[k]);
            CHECK(node.dequantize(k, node.qhi[k][i]) >= boxes[i].hi[k]);
          }
      }
}

TEST_CASE("bvh: axis-parallel rays through the faces and edges of wide node boxes", "[accel][bvh]") {
  // A 4 x 4 x 4 lattice of small cubes: node boxes share planes with the lattice rays, which
  // start on box faces and run inside them (0 * inf in the SSE slab test).
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        const uint32_t base = uint32_t(pos.size());
        for (int c = 0; c < 8; ++c)
          pos.push_back(
              {float(2 * i + (c & 1)), float(2 * j + ((c >> 1) & 1)), float(2 * k + ((c >> 2) & 1))});
        const uint32_t f[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 4, 6}, {0, 6, 2},
                                   {1, 3, 7}, {1, 7, 5}, {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3}};
        for (const auto& t : f) idx.insert(idx.end(), {base + t[0], base + t[1], base + t[2]});
      }
  const GeometryView view{pos, idx};
  const std::span<const GeometryView> views(&view, 1);
  std::vector<Ray> rays;
  for (int axis = 0; axis < 3; ++axis)
    for (float a = 0; a <= 8; a += 0.5f)
      for (float b = 0; b <= 8; b += 0.5f)
        for (float start : {-1.0f, 0.0f, 1.0f, 9.0f})
          for (float sign : {1.0f, -1.0f}) {
            Vec3f o, d;
            o[axis] = start;
            o[(axis + 1) % 3] = a;
            o[(axis + 2) % 3] = b;
            d[axis] = sign;
            rays.push_back({o, 0, d, kInfinity});
          }
  const auto brute = make_accelerator("brute", views);
  const Reference ref = reference(*brute, rays);
  for (int width : wide_widths())
    for (int leaf : {1, 2, 8}) {
      BvhConfig c;
      c.width = width;
      c.max_leaf_size = leaf;
      const auto bvh = make_bvh_accelerator(views, c);
      const auto r = cross_check(*bvh, ref, views, 14, true, 0.0f);
      INFO(summary("bvh width " + std::to_string(width) + " lattice leaf " + std::to_string(leaf), r));
      CHECK(r.failures() == 0);
      CHECK(r.hits > rays.size() / 4);
    }
}

TEST_CASE("bvh: any leaf size and bin count gives brute force's answers", "[accel][bvh]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  const auto brute = make_accelerator("brute", views);
  const Reference ref = reference(*brute, scene_rays(l, *brute, views));
  const float scale = length(compute_bounds(l.scene).extent());
  std::vector<int> widths = wide_widths();
  widths.push_back(2);
  for (int width : widths)
    for (auto [leaf, bins] : {std::pair{1, 2}, std::pair{2, 7}, std::pair{255, 256}, std::pair{4, 16}}) {
      BvhConfig c;
      c.width = width;
      c.max_leaf_size = leaf;
      c.bin_count = bins;
      c.parallel_threshold = 64;  // exercise the parallel build on a small scene
      const auto bvh = make_bvh_accelerator(views, c);
      const auto r = cross_check(*bvh, ref, views, scale, true, 0.0f);
      INFO(summary("bvh width " + std::to_string(c.width) + " leaf " + std::to_string(leaf) + " bins " +
                       std::to_string(bins),
                   r));
      CHECK(r.failures() == 0);
    }
}

TEST_CASE("bvh: the build is the same for 1 and 2 threads", "[accel][bvh]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  BvhConfig c;
  c.parallel_threshold = 16;
  AccelStats s1, s2;
  tbb::task_arena(1).execute([&] { s1 = make_bvh_accelerator(views, c)->stats(); });
  tbb::task_arena(2).execute([&] { s2 = make_bvh_accelerator(views, c)->stats(); });
  CHECK(s1.nodes == s2.nodes);
  CHECK(s1.max_depth == s2.max_depth);
  CHECK(s1.sah_cost == s2.sah_cost);
}

TEST_CASE("bvh: subtrees collapsed in parallel give the serial collapse's tree and answers bit for bit",
          "[accel][bvh]") {
  // parallel_threshold 16: the 4646-triangle default scene collapses its subtrees below the
  // second wide level as parallel jobs; 1 << 30: one serial collapse.
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  const auto brute = make_accelerator("brute", views);
  const std::vector<Ray> rays = scene_rays(l, *brute, views);
  for (int width : wide_widths()) {
    BvhConfig serial, jobs;
    serial.width = jobs.width = width;
    serial.parallel_threshold = size_t(1) << 30;
    jobs.parallel_threshold = 16;
    const auto a = make_bvh_accelerator(views, serial), b = make_bvh_accelerator(views, jobs);
    AccelStats sa = a->stats(), sb = b->stats();
    CHECK(sa.nodes == sb.nodes);
    CHECK(sa.leaves == sb.leaves);
    CHECK(sa.references == sb.references);
    CHECK(sa.max_depth == sb.max_depth);
    CHECK(sa.bytes == sb.bytes);
    CHECK(sa.sah_cost == Approx(sb.sah_cost).epsilon(1e-9));
    size_t differ = 0, hits = 0;
    for (const Ray& r : rays) {
      Hit ha, hb;
      const bool fa = a->intersect(r, ha), fb = b->intersect(r, hb);
      hits += fa;
      differ += fa != fb || (fa && (ha.t != hb.t || ha.u != hb.u || ha.v != hb.v ||
                                    ha.geom_id != hb.geom_id || ha.prim_id != hb.prim_id));
      differ += a->occluded(r) != b->occluded(r);
    }
    INFO("width " << width << ", " << rays.size() << " rays, " << hits << " hits");
    CHECK(hits > rays.size() / 4);
    CHECK(differ == 0);
  }
}

namespace {
/// Long thin triangles along the diagonal of a 20 m cube: boxes that overlap everywhere, the
/// case spatial splits are for.
struct DiagonalSlivers {
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  GeometryView view() const { return {pos, idx}; }
};
DiagonalSlivers diagonal_slivers(int n) {
  DiagonalSlivers s;
  Rng rng(11);
  for (int i = 0; i < n; ++i) {
    const Vec3f a{rng.next_float() * 20 - 10, rng.next_float() * 20 - 10, rng.next_float() * 20 - 10};
    const Vec3f w{rng.next_float() * 0.1f - 0.05f, rng.next_float() * 0.1f - 0.05f,
                  rng.next_float() * 0.1f - 0.05f};
    const uint32_t b = uint32_t(s.pos.size());
    s.pos.insert(s.pos.end(), {a, a + Vec3f{6, 6, 6}, a + Vec3f{6, 6, 6} + w});
    s.idx.insert(s.idx.end(), {b, b + 1, b + 2});
  }
  return s;
}

/// Calls fn(views, index) on the default scene (index 0) and on 2000 diagonal slivers (1).
template <typename Fn>
void for_default_and_slivers(Fn&& fn) {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const DiagonalSlivers slivers = diagonal_slivers(2000);
  const GeometryView sliver_view = slivers.view();
  const auto default_views = mesh_views(l.scene);
  fn(std::span<const GeometryView>(default_views), 0);
  fn(std::span<const GeometryView>(&sliver_view, 1), 1);
}
}  // namespace

TEST_CASE("bvh: the wide layouts' block test answers as the scalar watertight test, bit for bit",
          "[accel][bvh]") {
  // Brute force runs intersect_triangle_watertight on each triangle; the wide layouts finish
  // the lanes their SIMD filter keeps with block_confirm (double precision, two lanes per SSE
  // register). Same t on every ray; same u, v where both report the same triangle (two
  // triangles at exactly the same t may be reported either way). The slivers are where the
  // double-precision part decides t, u and v.
  for_default_and_slivers([](std::span<const GeometryView> views, int scene) {
    const auto brute = make_accelerator("brute", views);
    const Bounds3f b = brute->bounds();
    std::vector<Ray> rays = all_rays(*brute, views, b, lights_around(b), 1, 7);
    // Rays at the edges' midpoints and the corners of every 7th triangle, from off its plane:
    // edge functions near 0, where the double-precision part clamps to the float decision.
    const Vec3f from = b.hi + (b.hi - b.lo) * 0.3f;
    for (const GeometryView& v : views)
      for (size_t i = 0; i + 2 < v.indices.size(); i += 21) {
        const Vec3f p[3] = {v.positions[v.indices[i]], v.positions[v.indices[i + 1]],
                            v.positions[v.indices[i + 2]]};
        for (int e = 0; e < 3; ++e)
          for (const Vec3f target : {(p[e] + p[(e + 1) % 3]) * 0.5f, p[e]}) {
            Ray r;
            r.org = from;
            r.dir = normalize(target - from);
            rays.push_back(r);
          }
      }
    for (int width : wide_widths()) {
      BvhConfig c;
      c.width = width;
      const auto bvh = make_bvh_accelerator(views, c);
      size_t hits = 0, differ = 0, same_triangle = 0;
      for (const Ray& r : rays) {
        Hit hb, hw;
        const bool fb = brute->intersect(r, hb), fw = bvh->intersect(r, hw);
        hits += fb;
        differ += fb != fw || (fb && hb.t != hw.t) || brute->occluded(r) != bvh->occluded(r);
        if (fb && fw && hb.geom_id == hw.geom_id && hb.prim_id == hw.prim_id) {
          ++same_triangle;
          differ += hb.u != hw.u || hb.v != hw.v;
        }
      }
      INFO("scene " << scene << ", width " << width << ": " << rays.size() << " rays, " << hits << " hits, "
                    << same_triangle << " on the same triangle");
      CHECK(hits > 150);
      CHECK(same_triangle > hits * 9 / 10);
      CHECK(differ == 0);
    }
  });
}

TEST_CASE(
    "bvh: wide layouts meet boxes along axis-parallel and tiny directions, and tiny geometry, as "
    "brute force does",
    "[accel][bvh]") {
  // A ray along z with a direction of 1e-36 reaches a triangle at t ~ 1e36, beyond where a
  // finite stand-in for 1/0 on x and y would close the box (the test fails with one); origins
  // on box faces with zero components; and triangles 1e-13 across, 1e-13 from the origins,
  // where the filter's distance bound falls below FLT_MIN and its lanes go to the scalar test.
  std::vector<Vec3f> pos = {{-0.001f, -0.001f, 1}, {0.001f, -0.001f, 1}, {0, 0.001f, 1}, {5, 0, 1},
                            {5.1f, 0, 1},          {5, 0.1f, 1}};
  std::vector<uint32_t> idx = {0, 1, 2, 3, 4, 5};
  Rng rng(5);
  const uint32_t tiny_first = uint32_t(pos.size());
  for (int i = 0; i < 300; ++i) {
    const uint32_t b = uint32_t(pos.size());
    for (int v = 0; v < 3; ++v)
      pos.push_back(Vec3f{rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() + 1} * 1e-13f);
    idx.insert(idx.end(), {b, b + 1, b + 2});
  }
  const GeometryView view{pos, idx};
  const auto brute = make_accelerator("brute", std::span(&view, 1));
  std::vector<Ray> rays;
  for (float scale : {1.0f, 1e-36f}) {
    Ray r;
    r.dir = Vec3f{0, 0, 1} * scale;
    rays.push_back(r);
    for (const Vec3f org :
         {Vec3f{0.001f, 0, 0}, Vec3f{0, -0.001f, 0.5f}, Vec3f{5, 0, 0}, Vec3f{5.1f, 0.1f, 0}}) {
      r.org = org;  // on the boxes' faces
      rays.push_back(r);
    }
  }
  for (int i = 0; i < 3000; ++i) {
    Ray r;
    r.org = Vec3f{rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() * 0.5f} * 2e-13f;
    const Vec3f target = pos[tiny_first + uint32_t(rng.next_float() * 899.0f)];
    r.dir = normalize(target - r.org);  // t ~ 1e-13
    rays.push_back(r);
    // The same ray ending exactly at brute force's hit.
    Hit h;
    if (brute->intersect(r, h)) {
      Ray end = r;
      end.tfar = h.t;
      rays.push_back(end);
    }
  }
  for (int width : wide_widths()) {
    BvhConfig c;
    c.width = width;
    c.max_leaf_size = 1;
    const auto bvh = make_bvh_accelerator(std::span(&view, 1), c);
    size_t hits = 0, differ = 0;
    for (const Ray& r : rays) {
      Hit hb, hw;
      const bool fb = brute->intersect(r, hb), fw = bvh->intersect(r, hw);
      hits += fb;
      differ += fb != fw ||
                (fb && (hb.t != hw.t || hb.prim_id != hw.prim_id || hb.u != hw.u || hb.v != hw.v)) ||
                brute->occluded(r) != bvh->occluded(r);
    }
    INFO("width " << width << ": " << rays.size() << " rays, " << hits << " hits");
    CHECK(hits > rays.size() / 2);
    CHECK(differ == 0);
  }
}

TEST_CASE("bvh: spatial splits give brute force's answers in every width", "[accel][bvh]") {
  for_default_and_slivers([](std::span<const GeometryView> views, int scene) {
    const auto brute = make_accelerator("brute", views);
    Bounds3f b = brute->bounds();
    const Reference ref = reference(*brute, all_rays(*brute, views, b, lights_around(b), 1, 5));
    std::vector<int> widths = wide_widths();
    widths.push_back(2);
    for (int width : widths)
      for (float budget : {0.0f, 1.0f}) {
        BvhConfig c;
        c.width = width;
        c.spatial_alpha = 1e-5f;
        c.spatial_budget = budget;
        c.parallel_threshold = 64;
        const auto bvh = make_bvh_accelerator(views, c);
        const AccelStats s = bvh->stats();
        const auto r = cross_check(*bvh, ref, views, length(b.extent()), true, 0.0f);
        INFO(summary("scene " + std::to_string(scene) + " width " + std::to_string(width) + " budget " +
                         std::to_string(budget),
                     r));
        CHECK(r.failures() == 0);
        if (budget > 0) CHECK(s.references > s.triangles);  // parts of primitives in several leaves
        if (budget == 0) CHECK(s.references == s.triangles);
        CHECK(double(s.references) <= double(s.triangles) * (1 + budget));
        CHECK_THAT(s.config, Catch::Contains("spatial_alpha"));
      }
  });
}

TEST_CASE("bvh: spatial splits of huge diagonal strips under small objects miss nothing along their edges",
          "[accel][bvh]") {
  // Stacked 2000 m diagonal strips whose long edges run under small triangles near the
  // origin: their boxes overlap everywhere, so spatial splits cut them into nodes far smaller
  // than they are, where rounding at the crossings counts.
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  for (int k = 0; k < 64; ++k) {
    const float y = 0.001f * float(k);
    const uint32_t b = uint32_t(pos.size());
    pos.insert(pos.end(), {{-1000, y, -1000}, {1000, y, 1000}, {1000, y, 1000 + 4.0f + float(k)}});
    idx.insert(idx.end(), {b, b + 1, b + 2});
  }
  Rng rng(3);
  for (int i = 0; i < 600; ++i) {
    const float t = rng.next_float() * 4 - 2, off = rng.next_float() * 0.4f - 0.2f;
    const Vec3f a{t + off, 0.01f + rng.next_float() * 0.5f, t - off};
    const uint32_t b = uint32_t(pos.size());
    pos.insert(pos.end(), {a, a + Vec3f{0.02f, 0, 0}, a + Vec3f{0, 0.02f, 0.02f}});
    idx.insert(idx.end(), {b, b + 1, b + 2});
  }
  const GeometryView view{pos, idx};
  const auto brute = make_accelerator("brute", std::span(&view, 1));
  std::vector<Ray> rays;
  for (int i = 0; i < 20000; ++i) {
    // Down onto the strips within 1e-3 of their long edges (x = z), between the small triangles.
    const float t = rng.next_float() * 4 - 2, d = rng.next_float() * 1e-3f;
    rays.push_back({{t, 2, t + d}, 0, {0, -1, 0}, kInfinity});
  }
  const Reference ref = reference(*brute, rays);
  for (int width : {2, 4}) {
    BvhConfig c;
    c.width = width;
    c.spatial_alpha = 1e-8f;
    c.spatial_budget = 4;
    const auto bvh = make_bvh_accelerator(std::span(&view, 1), c);
    const auto r = cross_check(*bvh, ref, std::span(&view, 1), 2000, true, 0.0f);
    INFO(summary("width " + std::to_string(width), r));
    CHECK(bvh->stats().references > bvh->stats().triangles);
    CHECK(r.failures() == 0);
  }
}

TEST_CASE("bvh: spatial splits lower the SAH cost of overlapping slivers, the same for 1 and 2 threads",
          "[accel][bvh]") {
  const DiagonalSlivers slivers = diagonal_slivers(4000);
  const GeometryView view = slivers.view();
  for (int width : {2, 4}) {
    BvhConfig object, spatial;
    object.width = spatial.width = width;
    spatial.spatial_alpha = 1e-5f;
    spatial.parallel_threshold = 16;
    const AccelStats so = make_bvh_accelerator(std::span(&view, 1), object)->stats();
    AccelStats s1, s2;
    tbb::task_arena(1).execute([&] { s1 = make_bvh_accelerator(std::span(&view, 1), spatial)->stats(); });
    tbb::task_arena(2).execute([&] { s2 = make_bvh_accelerator(std::span(&view, 1), spatial)->stats(); });
    INFO("width " << width << ": SAH " << so.sah_cost << " without spatial splits, " << s1.sah_cost
                  << " with");
    // The greedy SAH gains about a fifth on binary nodes; collapsed nodes hide part of it.
    CHECK(s1.sah_cost < (width == 2 ? 0.9 : 0.99) * so.sah_cost);
    CHECK(s1.nodes == s2.nodes);
    CHECK(s1.references == s2.references);
    CHECK(s1.sah_cost == s2.sah_cost);
  }
}

TEST_CASE("bvh: identical centroids and huge leaves fall back to median splits", "[accel][bvh]") {
  // 1000 copies of one triangle: SAH cannot separate them; leaves must still be small.
  std::vector<Vec3f> pos{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  std::vector<uint32_t> idx;
  for (int i = 0; i < 1000; ++i) idx.insert(idx.end(), {0, 1, 2});
  const GeometryView view{pos, idx};
  const auto bvh = make_bvh_accelerator(std::span(&view, 1));
  CHECK(bvh->stats().max_leaf_prims <= 8);
  Hit h;
  REQUIRE(bvh->intersect({{0.2f, 0.2f, 1}, 0, {0, 0, -1}, kInfinity}, h));
  CHECK(h.t == 1);
}

TEST_CASE("bvh: configuration is validated", "[accel][bvh][quick]") {
  BvhConfig c;
  c.bin_count = 1;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("bin_count"));
  c = {};
  c.max_leaf_size = 256;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("max_leaf_size"));
  c = {};
  c.traversal_cost = 0;
  CHECK_THROWS_AS(validate(c), std::invalid_argument);
  c = {};
  c.width = 3;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("width must be 0"));
  for (float bad : {-1e-5f, 1.5f, std::nanf("")}) {
    c = {};
    c.spatial_alpha = bad;
    CHECK_THROWS_WITH(validate(c), Catch::Contains("spatial_alpha must be in [0, 1]"));
  }
  for (float bad : {-0.5f, 4.5f, std::nanf(""), kInfinity}) {
    c = {};
    c.spatial_budget = bad;
    CHECK_THROWS_WITH(validate(c), Catch::Contains("spatial_budget must be in [0, 4]"));
  }
  CHECK_NOTHROW(validate(BvhConfig{}));
}

namespace {

/// `s`'s vertices moved: every vertex displaced by a smooth field (a twist about Y and a wave)
/// of strength k, so triangles move, rotate and stretch.
Soup deformed(const Soup& s, float k) {
  Soup out = s;
  for (auto& mesh : out.positions)
    for (Vec3f& p : mesh) {
      const float a = k * p.y, c = std::cos(a), sn = std::sin(a);
      p = Vec3f{c * p.x - sn * p.z, p.y + 0.3f * k * std::sin(3 * p.x), sn * p.x + c * p.z};
    }
  return out;
}

/// A sphere, a plane and a shape: the scene the refit tests move.
Soup refit_scene() {
  Soup s = icosphere(3, 1, {0, 0.5f, 0});
  s.add_plane(1, -1.0f, -2.0f, 2.0f, 8);
  Soup small = icosphere(1, 0.3f, {1.5f, 1, 0.5f});
  s.add(small.positions[0], small.indices[0]);
  return s;
}

/// Every BVH layout the refit tests cover: each width, and spatial splits.
std::vector<std::pair<std::string, BvhConfig>> refit_configs() {
  std::vector<std::pair<std::string, BvhConfig>> out;
  std::vector<int> widths = wide_widths();
  widths.push_back(2);
  for (int width : widths) {
    BvhConfig c;
    c.width = width;
    out.push_back({"width " + std::to_string(width), c});
    c.spatial_alpha = 1e-5f;
    out.push_back({"width " + std::to_string(width) + ", spatial splits", c});
  }
  return out;
}

}  // namespace

TEST_CASE("bvh: a refitted tree answers exactly as brute force over the moved vertices",
          "[accel][bvh][refit][heavy]") {
  const Soup rest = refit_scene();
  const Shape ball = analytic_shape(ShapeKind::Sphere, 0.4f);
  for (const auto& [what, config] : refit_configs()) {
    std::vector<GeometryView> views = rest.views();
    views.push_back({{}, {}, &ball});
    const auto bvh = make_bvh_accelerator(views, config);
    for (float k : {0.2f, 0.8f, 1.6f}) {
      const Soup moved = deformed(rest, k);
      const Shape ball2 = analytic_shape(ShapeKind::Sphere, 0.4f + k);
      std::vector<GeometryView> next = moved.views();
      next.push_back({{}, {}, &ball2});
      REQUIRE(bvh->refit(next));
      const auto brute = make_accelerator("brute", next);
      const Bounds3f b = brute->bounds();
      CHECK(bvh->bounds().lo == b.lo);
      CHECK(bvh->bounds().hi == b.hi);
      const Reference ref = reference(*brute, all_rays(*brute, next, b, lights_around(b), 1, 17));
      const auto r = cross_check(*bvh, ref, next, length(b.extent()), true, 0.0f);
      INFO(summary("bvh " + what + " refitted, twist " + std::to_string(k), r));
      CHECK(r.failures() == 0);
      // The tree kept its shape: leaves and references are the build's.
      const AccelStats s = bvh->stats();
      CHECK(s.references == make_bvh_accelerator(views, config)->stats().references);
      CHECK(s.sah_cost > 0);
    }
  }
}

TEST_CASE("bvh: refitting to a translated copy keeps the SAH cost; stretching raises it",
          "[accel][bvh][refit]") {
  const Soup rest = refit_scene();
  for (const auto& [what, config] : refit_configs()) {
    INFO(what);
    const std::vector<GeometryView> views = rest.views();
    const auto bvh = make_bvh_accelerator(views, config);
    const double built = bvh->stats().sah_cost;
    // A translation by a power of two moves every box exactly; the SAH is relative to the root.
    Soup shifted = rest;
    for (auto& mesh : shifted.positions)
      for (Vec3f& p : mesh) p = p + Vec3f{4, -8, 2};
    REQUIRE(bvh->refit(shifted.views()));
    if (config.spatial_alpha > 0)  // refitted leaves bound whole triangles, not their split parts
      CHECK(bvh->stats().sah_cost >= built * (1 - 1e-5));
    else
      CHECK(bvh->stats().sah_cost == Approx(built).epsilon(1e-5));
    // Scrambling the vertices among themselves (same layout) stretches every triangle across
    // the scene: the refitted tree's cost grows many times over.
    Soup scrambled = rest;
    std::mt19937 rng(5);
    for (auto& mesh : scrambled.positions) std::shuffle(mesh.begin(), mesh.end(), rng);
    REQUIRE(bvh->refit(scrambled.views()));
    CHECK(bvh->stats().sah_cost > 4 * built);
  }
}

TEST_CASE("bvh: refit refuses another layout and non-finite vertices, and stays as it was",
          "[accel][bvh][refit][quick]") {
  const Soup rest = refit_scene();
  const std::vector<GeometryView> views = rest.views();
  for (const auto& [what, config] : refit_configs()) {
    INFO(what);
    const auto bvh = make_bvh_accelerator(views, config);
    const Bounds3f before = bvh->bounds();
    CHECK_FALSE(bvh->refit(std::span(views).first(2)));  // a view fewer
    Soup fewer = rest;
    fewer.indices[1].resize(fewer.indices[1].size() - 3);  // a triangle fewer
    CHECK_FALSE(bvh->refit(fewer.views()));
    Soup nan = rest;
    nan.positions[0][3].x = std::numeric_limits<float>::quiet_NaN();
    CHECK_FALSE(bvh->refit(nan.views()));
    const Shape ball = analytic_shape(ShapeKind::Sphere, 1);
    std::vector<GeometryView> kinds = views;
    kinds[2] = {{}, {}, &ball};  // a mesh became a shape
    CHECK_FALSE(bvh->refit(kinds));
    CHECK(bvh->bounds().lo == before.lo);
    CHECK(bvh->bounds().hi == before.hi);
  }
  // A build that dropped a non-finite triangle cannot refit (its leaves lack that triangle).
  Soup nan = rest;
  nan.positions[0][3].x = std::numeric_limits<float>::infinity();
  const auto bvh = make_bvh_accelerator(nan.views());
  CHECK_FALSE(bvh->refit(rest.views()));
  // The other back ends do not refit.
  for (const std::string name : {"kdtree", "grid", "brute", "embree"})
    CHECK_FALSE(make_accelerator(name, views)->refit(views));
}
