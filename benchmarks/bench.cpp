// penumbra-bench: measures acceleration structures on the same scenes (glTF, PLY or
// seeded generated scenes) and the same pre-generated ray sets (primary, shadow, diffuse,
// random), verifies every structure's answers against Embree (disagreements settled by the exact
// brute-force scan), and prints a table; optionally CSV, JSON with the machine and versions, an
// SVG chart and traversal-cost heat maps; with --marching-cubes, instead, isosurface extraction of
// the classic CSG part in cells per second; with --noise, noise evaluations per second; with
// --raster, rasterised against ray-traced primary visibility in frames per second. The table
// and chart are formatted by benchmarks/report.h, the SAH column by benchmarks/sah.h. See README,
// "Benchmarks", and benchmarks/RESULTS.md.
#include <sys/utsname.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/version.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "benchmarks/chart.h"
#include "benchmarks/collision.h"
#include "benchmarks/machine.h"
#include "benchmarks/queries.h"
#include "benchmarks/report.h"
#include "benchmarks/sah.h"
#include "benchmarks/scenegen.h"
#include "benchmarks/timing.h"
#include "io/files/atomic_file.h"
#include "io/files/error.h"
#include "io/files/points_file.h"
#include "io/gltf/loader.h"
#include "io/image/image_output.h"
#include "io/mesh/ply_loader.h"
#include "io/mesh/point_cloud.h"
#include "render/accel_params.h"
#include "render/session.h"
#include "renderer/accel/embree.h"
#include "renderer/accel/factory.h"
#include "renderer/core/rng.h"
#include "renderer/integrators/cost_map.h"
#include "renderer/integrators/raster.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/integrators/visibility.h"
#include "renderer/procedural/noise.h"
#include "renderer/scene/camera.h"
#include "renderer/scene/interaction.h"
#include "renderer/scene/scene.h"
#include "renderer/shapes/marching_cubes.h"

using namespace penumbra;

namespace {

using bench::Clock;
using bench::median;
using bench::median_seconds;
using bench::Row;
using bench::seconds_since;

struct RaySet {
  std::string kind;  // primary, shadow, diffuse, random, motion, splat
  std::vector<Ray> rays;
  bool any_hit = false;  // shadow rays are occlusion queries
  /// splat: each ray gathers and blends this scene's splats (blend_splats) from a structure
  /// over its splat geometry.
  const Scene* splats = nullptr;
};

Vec3f random_direction(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0, 1);
  const float a = u(rng), b = u(rng);
  return sample_uniform_sphere({a, b});
}

/// The camera the primary rays and heat maps use: the scene's first, or one framing the bounds.
Camera bench_camera(const Scene& scene, int w, int h) {
  return scene.cameras.empty() ? frame_bounds(compute_bounds(scene), float(w) / float(h)) : scene.cameras[0];
}

/// The four ray kinds of the benchmark (primary, shadow, diffuse, random), generated once per scene from a
/// fixed seed. Primary rays come from the scene's first camera (or one framing the bounds) on a w x h grid;
/// shadow and diffuse rays start at the primary hits (found with Embree, on triangles or shapes), offset
/// off the surface as the integrators offset them.
std::vector<RaySet> make_ray_sets(const Scene& scene, const Accelerator& embree, int w, int h,
                                  const std::vector<std::string>& kinds) {
  const Bounds3f b = compute_bounds(scene);
  const Camera cam = bench_camera(scene, w, h);
  std::vector<Ray> primary;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) primary.push_back(generate_camera_ray(cam, w, h, x + 0.5f, y + 0.5f));
  std::vector<SurfaceInteraction> surf;  // triangles and shapes alike
  for (const Ray& r : primary) {
    Hit hit;
    if (!embree.intersect(r, hit)) continue;
    surf.push_back(make_interaction(scene, r, hit));
  }
  std::vector<Vec3f> lights;
  for (const auto& l : scene.lights)
    if (l.type != LightType::Directional) lights.push_back(l.position);
  if (lights.empty()) {
    const Vec3f e = b.extent() * 0.5f;
    lights = {b.hi + e, Vec3f{b.lo.x - e.x, b.hi.y + e.y, b.hi.z}};
  }
  std::mt19937 rng(20261122u);
  std::vector<RaySet> sets;
  for (const auto& kind : kinds) {
    RaySet s{kind, {}, kind == "shadow"};
    if (kind == "primary") {
      s.rays = primary;
    } else if (kind == "shadow") {
      for (size_t i = 0; i < surf.size(); ++i) {
        const Vec3f l = lights[i % lights.size()];
        const Vec3f d = l - surf[i].p;
        const float dist = length(d);
        if (!(dist > 0)) continue;
        const Vec3f dir = d / dist;
        s.rays.push_back({spawn_origin(surf[i], dir), 0, dir, dist * (1 - 1e-4f)});
      }
    } else if (kind == "diffuse") {
      for (const auto& p : surf) {
        Vec3f dir = normalize(p.ng + random_direction(rng));
        if (!(dot(dir, p.ng) > 0)) dir = p.ng;
        s.rays.push_back({spawn_origin(p, dir), 0, dir, kInfinity});
      }
    } else if (kind == "random") {
      std::uniform_real_distribution<float> u(0, 1);
      for (size_t i = 0; i < primary.size(); ++i) {
        Vec3f o;
        for (int k = 0; k < 3; ++k) o[k] = b.lo[k] + u(rng) * (b.hi[k] - b.lo[k]);
        s.rays.push_back({o, 0, random_direction(rng), kInfinity});
      }
    } else {
      throw std::invalid_argument("--rays: unknown ray kind '" + kind +
                                  "' (known: primary, shadow, diffuse, random)");
    }
    sets.push_back(std::move(s));
  }
  return sets;
}

/// Seconds to answer every ray of `set` with `threads` threads (0: one TBB task per chunk on all).
double trace_seconds(const Accelerator& a, const RaySet& set, int threads, uint64_t& hits) {
  std::vector<uint8_t> result(set.rays.size());
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(std::max(threads, 1)));
  const auto t0 = Clock::now();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, set.rays.size(), 1024),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i < r.end(); ++i) {
                        if (set.splats) {
                          result[i] = blend_splats(*set.splats, a, set.rays[i], kInfinity).count > 0;
                        } else if (set.any_hit) {
                          result[i] = a.occluded(set.rays[i]);
                        } else {
                          Hit h;
                          result[i] = a.intersect(set.rays[i], h);
                        }
                      }
                    });
  const double s = seconds_since(t0);
  hits = 0;
  for (uint8_t v : result) hits += v;
  return s;
}

/// SDF evaluations (sphere-tracing steps) per ray of `set`, from intersect_counted.
double evaluations_per_ray(const Accelerator& a, const RaySet& set) {
  TraversalCost cost;
  for (const Ray& r : set.rays) {
    Hit h;
    a.intersect_counted(r, h, cost);
  }
  return set.rays.empty() ? 0.0 : double(cost.evaluations) / double(set.rays.size());
}

struct Agreement {
  uint64_t wrong = 0;  ///< rays where `a` differs from Embree and from the exact scan: must be 0
  uint64_t ties = 0;   ///< rays where `a` differs from Embree but gives the exact scan's answer
};

/// Whether two answers to `r` agree: same hit/miss (occluded or not), and for closest hits t
/// within 1e-4 relative (with a floor of 1e-3 of the scene size).
bool same_answer(const Accelerator& a, const Accelerator& b, const Ray& r, bool any_hit, float scale) {
  if (any_hit) return a.occluded(r) == b.occluded(r);
  Hit ha, hb;
  const bool x = a.intersect(r, ha), y = b.intersect(r, hb);
  return x == y && (!x || std::fabs(ha.t - hb.t) <= 1e-4f * std::max({ha.t, hb.t, 1e-3f * scale}));
}

/// Checks `a` against Embree on every ray of `set`. A disagreement is settled by the brute-force
/// scan with the watertight test (the exact answer of the triangle test the own structures
/// share): if `a` gives the scan's answer, Embree's own triangle test rounded the other way on
/// that ray (a hit exactly on an edge, or at the end of the ray) and it is counted as a tie;
/// otherwise `a` is wrong.
/// Splat rays: the same blended radiance and transmittance within 1e-4.
bool same_blend(const Scene& scene, const Accelerator& a, const Accelerator& b, const Ray& r) {
  const SplatLayer x = blend_splats(scene, a, r, kInfinity), y = blend_splats(scene, b, r, kInfinity);
  return max_component(abs(x.radiance - y.radiance)) <= 1e-4f &&
         std::abs(x.transmittance - y.transmittance) <= 1e-4f;
}

Agreement check_against_embree(const Accelerator& a, const Accelerator& embree, const Accelerator& exact,
                               const RaySet& set, float scale) {
  Agreement g;
  for (const Ray& r : set.rays) {
    if (set.splats) {
      if (same_blend(*set.splats, a, embree, r)) continue;
      if (same_blend(*set.splats, a, exact, r))
        ++g.ties;
      else
        ++g.wrong;
      continue;
    }
    if (same_answer(a, embree, r, set.any_hit, scale)) continue;
    if (same_answer(a, exact, r, set.any_hit, scale))
      ++g.ties;
    else
      ++g.wrong;
  }
  return g;
}

/// A benchmark scene: "gen:NAME" or "gen:NAME:TRIANGLES" (seeded generator), a .ply file, or a
/// glTF file. Returns the scene and the name used in the table.
Scene load_bench_scene(const std::string& spec, uint64_t seed, std::string& name) {
  if (spec.rfind("gen:", 0) == 0) {
    const std::string rest = spec.substr(4);
    const size_t colon = rest.find(':');
    uint64_t n = 0;
    if (colon != std::string::npos) {
      const std::string count = rest.substr(colon + 1);
      char* end = nullptr;
      n = std::strtoull(count.c_str(), &end, 10);
      if (count.empty() || *end != 0)
        throw std::invalid_argument(spec + ": triangle count '" + count + "' is not a number");
    }
    if (rest.substr(0, colon) == "cloud") {
      // A point set: a third in a few dense clusters, the rest uniform in the unit cube.
      const uint64_t count = n ? n : 1000000;
      if (count > (1ull << 28)) throw std::invalid_argument(spec + ": more than 2^28 points");
      std::mt19937 rng{uint32_t(seed)};
      std::uniform_real_distribution<float> u(-1, 1);
      std::normal_distribution<float> g(0, 0.03f);
      std::vector<Vec3f> centres;
      for (int c = 0; c < 16; ++c) centres.push_back({u(rng), u(rng), u(rng)});
      std::vector<Vec3f> pts(count);
      for (uint64_t i = 0; i < count; ++i)
        pts[i] = i % 3 ? Vec3f{u(rng), u(rng), u(rng)} : centres[i % 16] + Vec3f{g(rng), g(rng), g(rng)};
      Scene scene;
      add_world_mesh(scene, make_point_set(std::move(pts), "cloud"));
      name = "cloud-" + std::to_string(count / 1000) + "k";
      return scene;
    }
    Scene scene = bench::generate_scene(rest.substr(0, colon), seed, n);
    name = rest.substr(0, colon) + "-" +
           (scene.shapes.empty() ? std::to_string(count_triangles(scene) / 1000) + "k"
                                 : std::to_string(count_shape_instances(scene)) + "shapes");
    return scene;
  }
  name = std::filesystem::path(spec).filename().string();
  if (std::filesystem::path(spec).extension() == ".ply") return load_ply_or_points(spec, size_t(1) << 28);
  if (is_point_cloud_file(spec)) return load_point_cloud(spec, size_t(1) << 28);
  // Flattened: the benchmark measures single-level structures over world-space triangles
  // (geom_id = mesh index).
  GltfLoadOptions options;
  options.flatten = true;
  return load_gltf(spec, options).scene;
}

/// The shaded raster preview of `loaded` as `penumbra render --integrator raster` renders it,
/// through the render session (its default key light included when the scene has no light):
/// `shadows` "none" or "map", `cfg`'s size and threads, the bench camera; the median seconds.
double preview_seconds(LoadedScene& loaded, const Accelerator* accel, const Camera& cam,
                       const RenderConfig& cfg, const char* shadows, int repeats) {
  RenderSpec spec;
  spec.integrator = "raster";
  spec.raster_shadows = shadows;
  spec.width = cfg.width;
  spec.height = cfg.height;
  spec.spp = cfg.spp;
  spec.threads = cfg.threads;
  PrepareOptions o;
  o.camera_index = -1;
  o.place = [&](const Scene&, int, int, int) { return cam; };
  const PreparedRender prepared = prepare_render(loaded, spec, o);
  const double s = median_seconds(repeats, [&] { render_image(loaded.scene, accel, prepared); });
  finish_render(loaded, prepared);
  return s;
}

/// --raster: frames per second of primary visibility at width x height, one sample per pixel
/// centre: the rasteriser's visibility buffer against Embree's and the BVH's camera rays (with
/// and without their build), and the raster preview's shaded frame (no shadows, shadow maps).
int run_raster(const std::vector<std::string>& scenes, uint64_t seed, int width, int height,
               const std::vector<int>& threads, int builds, int repeats) {
  std::printf("%-22s %9s %3s %9s %9s %9s %9s %9s %9s %9s %9s %8s %8s\n", "scene", "tris", "T", "raster",
              "preview", "+maps", "embree", "+build", "bvh", "+build", "raster", "vs", "vs");
  std::printf("%-22s %9s %3s %9s %9s %9s %9s %9s %9s %9s %9s %8s %8s\n", "", "", "", "vis ms", "ms", "ms",
              "ms", "ms", "ms", "ms", "fps", "embree", "+build");
  for (const std::string& spec : scenes) {
    std::string name;
    LoadedScene loaded;  // the render session's form of a scene, for the shaded preview
    loaded.scene = load_bench_scene(spec, seed, name);
    const Scene& scene = loaded.scene;
    const Camera cam = bench_camera(scene, width, height);
    for (int t : threads) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(thread_count(t)));
      RenderConfig cfg;
      cfg.width = width;
      cfg.height = height;
      cfg.spp = 1;
      cfg.threads = t;
      validate(cfg);
      CameraView cv;
      make_camera_view(cam, width, height, cv);
      RasterPass pass = camera_raster_pass(cfg);
      pass.position = nullptr;  // pixel centres, as the camera rays below
      pass.margin = 0;
      std::atomic<uint64_t> visible{0};
      RasterStats rs;
      const double vis = median_seconds(repeats, [&] {
        visible = 0;
        rasterize(
            scene, cv.view, pass,
            [&](const RasterTile& tile) {
              const size_t n = size_t(tile.pixels.width()) * size_t(tile.pixels.height());
              uint64_t v = 0;
              for (size_t i = 0; i < n; ++i)
                v += tile.opaque[i].hit.valid() || tile.blend_begin[i + 1] > tile.blend_begin[i];
              visible += v;
            },
            &rs);
      });
      double build_s[2] = {0, 0}, trace_s[2] = {0, 0};
      uint64_t hits[2] = {0, 0};
      std::unique_ptr<Accelerator> embree;
      const char* names[2] = {"embree", "bvh"};
      for (int k = 0; k < 2; ++k) {
        std::unique_ptr<Accelerator> a;
        std::vector<double> b;
        for (int i = 0; i < builds; ++i) {
          const auto t0 = Clock::now();
          a = make_scene_accelerator(names[k], scene);
          b.push_back(seconds_since(t0));
        }
        build_s[k] = median(b);
        const std::vector<RaySet> sets = make_ray_sets(scene, *a, width, height, {"primary"});
        trace_s[k] = median_seconds(repeats, [&] { trace_seconds(*a, sets[0], t, hits[k]); });
        if (k == 0) embree = std::move(a);
      }
      const double preview = preview_seconds(loaded, embree.get(), cam, cfg, "none", repeats);
      const double maps = preview_seconds(loaded, embree.get(), cam, cfg, "map", repeats);
      std::printf("%-22s %9llu %3d %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %7.2fx %7.2fx\n",
                  name.c_str(), static_cast<unsigned long long>(count_triangles(scene)), thread_count(t),
                  vis * 1e3, preview * 1e3, maps * 1e3, trace_s[0] * 1e3, (trace_s[0] + build_s[0]) * 1e3,
                  trace_s[1] * 1e3, (trace_s[1] + build_s[1]) * 1e3, 1 / vis, trace_s[0] / vis,
                  (trace_s[0] + build_s[0]) / vis);
      std::printf(
          "  raster phases (last pass): set-up %.1f ms, binning %.1f ms, tiles %.1f ms; %llu of %llu "
          "triangles set up, %llu bin references\n",
          rs.setup_seconds * 1e3, rs.bin_seconds * 1e3, rs.tile_seconds * 1e3,
          static_cast<unsigned long long>(rs.triangles_setup),
          static_cast<unsigned long long>(rs.triangles_in),
          static_cast<unsigned long long>(rs.bin_references));
      if (visible.load() != hits[0])
        std::printf("  (visible samples: raster %llu, embree %llu)\n",
                    static_cast<unsigned long long>(visible.load()),
                    static_cast<unsigned long long>(hits[0]));
    }
  }
  return 0;
}

/// The classic CSG part: a sphere of radius 1.35 intersected with the cube [-1, 1]^3, minus three
/// cylinders of radius 0.5 along X, Y and Z (the shape of the marching-cubes tests).
SdfTree csg_part_tree() {
  SdfTree t;
  const auto add = [&](SdfKind kind, Vec3f size, float radius, int a = -1, int b = -1) {
    SdfNode n;
    n.kind = kind, n.size = size, n.radius = radius, n.a = a, n.b = b;
    t.nodes.push_back(n);
    return int(t.nodes.size()) - 1;
  };
  const int body = add(SdfKind::Intersection, {}, 0, add(SdfKind::Sphere, {1.35f, 0, 0}, 0),
                       add(SdfKind::Box, {1, 1, 1}, 0));
  const int along_y = add(SdfKind::Cylinder, {0, 1.5f, 0}, 0.5f);
  const int along_x = add(SdfKind::Cylinder, {0, 1.5f, 0}, 0.5f);
  const int along_z = add(SdfKind::Cylinder, {0, 1.5f, 0}, 0.5f);
  t.nodes[size_t(along_x)].to_local = {{{0, 1, 0, 0}, {1, 0, 0, 0}, {0, 0, -1, 0}}};  // local y = x
  t.nodes[size_t(along_z)].to_local = {{{1, 0, 0, 0}, {0, 0, 1, 0}, {0, -1, 0, 0}}};  // local y = z
  const int holes = add(SdfKind::Union, {}, 0, along_x, add(SdfKind::Union, {}, 0, along_y, along_z));
  t.root = add(SdfKind::Subtraction, {}, 0, body, holes);
  return t;
}

/// --marching-cubes: extracts the CSG part's surface at each resolution on arenas of each thread
/// count (one warm-up, then the median of `repeats`) and prints grid cells per second.
int run_marching_cubes(const std::vector<int>& resolutions, const std::vector<int>& threads, int repeats) {
  const SdfTree part = csg_part_tree();
  const Bounds3f box{{-1, -1, -1}, {1, 1, 1}};
  for (int r : resolutions) marching_cubes_grid(box, r, {});  // bad resolutions fail before measuring
  std::printf("%-10s %5s %12s %10s %10s %9s", "shape", "res", "cells", "vertices", "triangles", "MiB");
  for (int t : threads) std::printf("  %4dT ms  Mcells/s", t > 0 ? t : int(tbb::info::default_concurrency()));
  std::printf("\n");
  for (int r : resolutions) {
    const MarchingCubesGrid g = marching_cubes_grid(box, r, {});
    const double cells = double(g.n[0]) * double(g.n[1]) * double(g.n[2]);
    IsosurfaceMesh mesh;
    std::vector<double> ms;
    for (int t : threads) {
      tbb::task_arena arena(t > 0 ? t : int(tbb::info::default_concurrency()));
      std::vector<double> secs;
      for (int i = 0; i <= repeats; ++i) {
        mesh = {};
        const auto t0 = Clock::now();
        arena.execute([&] { mesh = extract_isosurface(part, box, r); });
        if (i > 0) secs.push_back(seconds_since(t0));  // the first run warms up
      }
      ms.push_back(median(secs) * 1e3);
    }
    std::printf("%-10s %5d %12.0f %10zu %10zu %9.1f", "csg-part", r, cells, mesh.positions.size(),
                mesh.indices.size() / 3, double(marching_cubes_bytes(box, r)) / (1 << 20));
    for (double m : ms) std::printf("  %8.1f %9.2f", m, cells / (m * 1e-3) / 1e6);
    std::printf("\n");
    std::fflush(stdout);
  }
  return 0;
}

/// One --noise row: `eval` at every point, one warm-up pass, then the median of `repeats` passes.
template <class Eval>
void measure_noise(const char* name, const std::vector<Vec3f>& points, int repeats, const Eval& eval) {
  std::vector<double> secs;
  volatile float sink = 0;
  for (int i = 0; i <= repeats; ++i) {
    const auto t0 = Clock::now();
    float sum = 0;
    for (const Vec3f& p : points) sum += eval(p);
    if (i > 0) secs.push_back(seconds_since(t0));  // the first pass warms up
    sink = sink + sum;
  }
  const double s = median(secs), n = double(points.size());
  std::printf("%-10s %12.0f %10.1f %10.2f %9.1f\n", name, n, s * 1e3, n / s / 1e6, s / n * 1e9);
  std::fflush(stdout);
}

/// --noise: evaluates 3D Perlin noise, 5-octave fBm (detail 4) and Worley F1 at `count` seeded
/// random points in [-64, 64]^3 on one thread and prints evaluations per second.
int run_noise(int count, int repeats) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-64, 64);
  std::vector<Vec3f> points(static_cast<size_t>(count));
  for (Vec3f& p : points) p = {u(rng), u(rng), u(rng)};
  const PerlinTable table = make_perlin_table(1);
  const FractalParams fbm;  // detail 4: five octaves
  const WorleyParams f1;
  std::printf("%-10s %12s %10s %10s %9s\n", "noise", "evaluations", "1T ms", "Mevals/s", "ns/eval");
  measure_noise("perlin-3d", points, repeats, [&](Vec3f p) { return perlin(table, p).value; });
  measure_noise("fbm-5", points, repeats, [&](Vec3f p) { return fractal_noise(table, p, fbm).value; });
  measure_noise("worley-f1", points, repeats, [&](Vec3f p) { return worley(1, p, f1).value; });
  return 0;
}

std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o;
}

/// The first line of `file` starting with `key`, with the key and separators stripped.
std::string read_field(const char* file, const std::string& key) {
  std::ifstream f(file);
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind(key, 0) != 0) continue;
    std::string v = line.substr(key.size());
    const size_t b = v.find_first_not_of(" \t:=\"");
    v = b == std::string::npos ? "" : v.substr(b);
    while (!v.empty() && (v.back() == '"' || v.back() == ' ')) v.pop_back();
    return v;
  }
  return "unknown";
}

/// The machine, build and library versions, as the body of a JSON object.
std::string machine_json() {
  utsname u{};
  uname(&u);
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  std::string s;
  auto field = [&](const char* k, const std::string& v, bool last = false) {
    s += std::string("    \"") + k + "\": \"" + json_escape(v) + "\"" + (last ? "\n" : ",\n");
  };
  field("date", date);
  field("cpu", read_field("/proc/cpuinfo", "model name"));
  field("hardware_threads", std::to_string(std::thread::hardware_concurrency()));
  field("cores", std::to_string(bench::read_machine_info().cores));
  field("memory", read_field("/proc/meminfo", "MemTotal"));
  field("os", read_field("/etc/os-release", "PRETTY_NAME"));
  field("kernel", std::string(u.sysname) + " " + u.release + " " + u.machine);
  field("compiler", __VERSION__);
  field("build_type", PENUMBRA_BUILD_TYPE);
  field("flags", PENUMBRA_CXX_FLAGS);
  field("penumbra", PENUMBRA_VERSION);
  field("embree", embree_version());
  field("tbb", TBB_runtime_version());
  field("tbb_interface", std::to_string(TBB_runtime_interface_version()), true);
  return s;
}

/// The software of a run, one line for the chart's caption: versions, OS, compiler, build type.
std::string software_line() {
  utsname u{};
  uname(&u);
  return std::string("Penumbra ") + PENUMBRA_VERSION + ", Embree " + embree_version() + ", oneTBB " +
         TBB_runtime_version() + ", " + read_field("/etc/os-release", "PRETTY_NAME") + ", " + u.sysname +
         " " + u.release + ", " +
#ifdef __clang__
         "Clang " __clang_version__
#else
         "GCC " __VERSION__
#endif
         + ", " + PENUMBRA_BUILD_TYPE + " build";
}

/// Work per ray (nodes or cells visited, triangles and shapes tested) over closest-hit queries.
struct CostDistribution {
  double mean = 0, median = 0, p99 = 0, max = 0;
};

CostDistribution per_ray_cost(const Accelerator& a, const std::vector<RaySet>& sets) {
  std::vector<uint64_t> c;
  for (const RaySet& set : sets)
    for (const Ray& r : set.rays) {
      TraversalCost k;
      Hit h;
      a.intersect_counted(r, h, k);
      c.push_back(k.nodes + k.triangles + k.shapes);
    }
  CostDistribution d;
  if (c.empty()) return d;
  std::sort(c.begin(), c.end());
  double sum = 0;
  for (uint64_t v : c) sum += double(v);
  d.mean = sum / double(c.size());
  d.median = double(c[c.size() / 2]);
  d.p99 = double(c[std::min(c.size() - 1, size_t(0.99 * double(c.size())))]);
  d.max = double(c.back());
  return d;
}

/// One structure on one scene in the trade-off table.
struct TradeoffRow {
  std::string scene, accel;
  uint64_t triangles = 0, bytes = 0, references = 0, wrong = 0, ties = 0;
  bench::Spread build[2];                ///< seconds with 1 thread and with every core
  std::optional<CostDistribution> cost;  ///< nullopt: the back end does not count
  double mrays[2] = {0, 0};              ///< primary, random; 1 thread
};

/// Builds `name` over `scene` `builds` times with `threads` threads; the spread of the seconds.
bench::Spread timed_builds(const std::string& name, const Scene& scene, const AccelConfig& config, int builds,
                           int threads, std::unique_ptr<Accelerator>& last) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  std::vector<double> s;
  for (int i = 0; i < builds; ++i) {
    last.reset();
    const auto t0 = Clock::now();
    last = make_scene_accelerator(name, scene, config);
    s.push_back(seconds_since(t0));
  }
  return bench::spread_of(s);
}

/// --tradeoffs: per scene and structure the
/// memory, the build time with 1 thread and with every core, the distribution of work per ray
/// (closest hits of the primary and random rays) and the throughput of one thread, with every
/// answer checked against Embree as the main table checks it.
std::vector<TradeoffRow> measure_tradeoffs(const std::vector<std::string>& scenes, uint64_t seed,
                                           const std::vector<std::string>& accels, const AccelConfig& config,
                                           int width, int height, int builds, int repeats) {
  std::vector<TradeoffRow> rows;
  const int all = int(tbb::info::default_concurrency());
  for (const std::string& spec : scenes) {
    std::string name;
    const Scene scene = load_bench_scene(spec, seed, name);
    const auto embree = make_scene_accelerator("embree", scene, config);
    const auto exact = make_scene_accelerator("brute", scene, config);
    const std::vector<RaySet> sets = make_ray_sets(scene, *embree, width, height, {"primary", "random"});
    const float scale = length(compute_bounds(scene).extent());
    for (const std::string& accel : accels) {
      TradeoffRow row{name, accel};
      row.triangles = count_triangles(scene);
      std::unique_ptr<Accelerator> a;
      row.build[0] = timed_builds(accel, scene, config, builds, 1, a);
      row.build[1] = timed_builds(accel, scene, config, builds, all, a);
      const AccelStats st = a->stats();
      row.bytes = st.bytes;
      row.references = st.references;
      if (a->counts_traversal()) row.cost = per_ray_cost(*a, sets);
      for (int k = 0; k < 2; ++k) {
        uint64_t hits = 0;
        std::vector<double> s;
        for (int r = 0; r < repeats; ++r) s.push_back(trace_seconds(*a, sets[size_t(k)], 1, hits));
        row.mrays[k] = double(sets[size_t(k)].rays.size()) / median(s) / 1e6;
        const Agreement g = check_against_embree(*a, *embree, *exact, sets[size_t(k)], scale);
        row.wrong += g.wrong;
        row.ties += g.ties;
      }
      std::printf(
          "%-16s %-7s %9llu %9.1f %6.1f %5.2f %9.1f %9.1f %5.2f %7.0f %7.0f %8.0f %7.2f %7.2f %5llu\n",
          row.scene.c_str(), row.accel.c_str(), static_cast<unsigned long long>(row.triangles),
          double(row.bytes) / 1048576.0, row.triangles ? double(row.bytes) / double(row.triangles) : 0.0,
          row.triangles ? double(row.references) / double(row.triangles) : 0.0, row.build[0].median * 1e3,
          row.build[1].median * 1e3,
          row.build[1].median > 0 ? row.build[0].median / row.build[1].median : 0.0,
          row.cost ? row.cost->median : -1.0, row.cost ? row.cost->p99 : -1.0,
          row.cost ? row.cost->max : -1.0, row.mrays[0], row.mrays[1],
          static_cast<unsigned long long>(row.wrong));
      std::fflush(stdout);
      rows.push_back(row);
    }
  }
  return rows;
}

/// The trade-off table's chart: one row of panels per scene (memory per triangle, build time
/// with 1 thread and every core, work per ray at the median and the 99th percentile, one
/// thread's throughput), one bar per structure.
bench::BarChart tradeoff_chart(const std::vector<TradeoffRow>& rows, const std::vector<std::string>& accels,
                               const std::string& caption) {
  bench::BarChart chart;
  chart.title = "Spatial structures: memory, build, work per ray, throughput";
  chart.series = accels;
  chart.caption = {caption};
  const auto value = [](double v) { return std::optional<bench::Spread>(bench::Spread{v, v, v}); };
  for (const TradeoffRow& first : rows) {
    if (!chart.row_labels.empty() && chart.row_labels.back() == first.scene) continue;
    chart.row_labels.push_back(first.scene);
    bench::BarPanel mem{"memory", "", "memory", "bytes/triangle", {"bytes"}, {}};
    bench::BarPanel build{"build", "threads", "build", "ms", {"1", "all"}, {}};
    bench::BarPanel cost{"work per ray", "percentile", "nodes + tests", "per ray", {"median", "99th"}, {}};
    bench::BarPanel speed{"1 thread", "rays", "throughput", "Mrays/s", {"primary", "random"}, {}};
    mem.values.assign(1, std::vector<std::optional<bench::Spread>>(accels.size()));
    build.values.assign(2, std::vector<std::optional<bench::Spread>>(accels.size()));
    cost.values.assign(2, std::vector<std::optional<bench::Spread>>(accels.size()));
    speed.values.assign(2, std::vector<std::optional<bench::Spread>>(accels.size()));
    for (const TradeoffRow& r : rows) {
      if (r.scene != first.scene) continue;
      const size_t s = size_t(std::find(accels.begin(), accels.end(), r.accel) - accels.begin());
      mem.values[0][s] = value(r.triangles ? double(r.bytes) / double(r.triangles) : 0.0);
      for (int k = 0; k < 2; ++k) {
        bench::Spread b = r.build[k];
        b.min *= 1e3, b.median *= 1e3, b.max *= 1e3;
        build.values[size_t(k)][s] = b;
        speed.values[size_t(k)][s] = value(r.mrays[k]);
      }
      if (r.cost) {
        cost.values[0][s] = value(r.cost->median);
        cost.values[1][s] = value(r.cost->p99);
      }
    }
    chart.rows.push_back({mem, build, cost, speed});
  }
  return chart;
}

int run_tradeoffs(const std::vector<std::string>& scenes, uint64_t seed,
                  const std::vector<std::string>& accels, const AccelConfig& config, int width, int height,
                  int builds, int repeats, const std::string& csv, const std::string& svg,
                  const std::string& command) {
  std::printf("%-16s %-7s %9s %9s %6s %5s %9s %9s %5s %7s %7s %8s %7s %7s %5s\n", "scene", "accel", "tris",
              "MiB", "B/tri", "refs", "build 1T", "build", "x", "work", "work", "work", "prim", "rand",
              "wrong");
  std::printf("%-16s %-7s %9s %9s %6s %5s %9s %9s %5s %7s %7s %8s %7s %7s %5s\n", "", "", "", "", "", "/tri",
              "ms", "all ms", "", "median", "p99", "max", "Mr/s", "Mr/s", "");
  const std::vector<TradeoffRow> rows =
      measure_tradeoffs(scenes, seed, accels, config, width, height, builds, repeats);
  uint64_t wrong = 0;
  for (const TradeoffRow& r : rows) wrong += r.wrong;
  if (!csv.empty())
    write_atomically(csv, [&](const std::filesystem::path& tmp) {
      std::ofstream f(tmp);
      f << "scene,accel,triangles,bytes,references,build_1t_s,build_all_s,work_mean,work_median,work_p99,"
           "work_max,mrays_primary_1t,mrays_random_1t,wrong,ties\n";
      for (const TradeoffRow& r : rows) {
        f << r.scene << ',' << r.accel << ',' << r.triangles << ',' << r.bytes << ',' << r.references << ','
          << r.build[0].median << ',' << r.build[1].median << ',';
        if (r.cost)
          f << r.cost->mean << ',' << r.cost->median << ',' << r.cost->p99 << ',' << r.cost->max << ',';
        else
          f << ",,,,";
        f << r.mrays[0] << ',' << r.mrays[1] << ',' << r.wrong << ',' << r.ties << '\n';
      }
      if (!f) throw std::runtime_error(csv + ": cannot write");
    });
  if (!svg.empty())
    write_atomically(svg, [&](const std::filesystem::path& tmp) {
      std::ofstream f(tmp);
      f << bench::bar_chart_svg(tradeoff_chart(
          rows, accels,
          command + " -- " + bench::describe(bench::read_machine_info()) + "; " + software_line()));
      if (!f) throw std::runtime_error(svg + ": cannot write");
    });
  std::printf(
      "work = nodes or cells visited + triangles and shapes tested per closest-hit ray (primary and "
      "random rays); builds: median of %d; throughput: median of %d passes, 1 thread\n",
      builds, repeats);
  if (wrong > 0)
    std::fprintf(stderr, "penumbra-bench: %llu wrong answers\n", static_cast<unsigned long long>(wrong));
  return wrong > 0 ? 1 : 0;
}

/// The end of a glTF file's animations: the largest "max" of the animation samplers' input
/// accessors (the spec requires it). 0 for a file without animations, or whose JSON cannot be
/// read so (a GLB, or members of other types).
double animation_end(const std::string& file) {
  std::ifstream in(file);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  double end = 0;
  if (j.is_discarded() || !j.is_object() || !j.contains("animations")) return end;
  try {
    for (const auto& a : j.at("animations"))
      for (const auto& s : a.value("samplers", nlohmann::json::array())) {
        const auto& acc = j.at("accessors").at(s.at("input").get<size_t>());
        if (acc.contains("max")) end = std::max(end, acc.at("max").at(0).get<double>());
      }
  } catch (const nlohmann::json::exception&) {
    return 0;
  }
  return end;
}

/// Mean work per closest-hit ray of `rays` (nodes + triangles + shapes).
double mean_work(const Accelerator& a, const std::vector<Ray>& rays) {
  TraversalCost k;
  for (const Ray& r : rays) {
    Hit h;
    a.intersect_counted(r, h, k);
  }
  return rays.empty() ? 0.0 : double(k.nodes + k.triangles + k.shapes) / double(rays.size());
}

/// --refit FILE: the BVH over an animated file's frames, each frame loaded at its time: a
/// fresh build per frame, a refit of the first frame's tree (never rebuilt) and the rebuild
/// policy (refit_or_rebuild with the configured bvh.refit_max_growth); per frame the update
/// time, the SAH cost and the mean work of the camera's primary rays (a fixed camera framing
/// the first frame). Prints a row every 24 frames and the totals; --csv writes every frame.
int run_refit(const std::string& file, int frames, const AccelConfig& config, int width, int height,
              int threads, const std::string& csv) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(thread_count(threads)));
  Scene scene = load_gltf(file).scene;  // the loader's checks and errors come first
  const double end = animation_end(file);
  if (!(end > 0))
    throw std::invalid_argument(file +
                                ": no animation to refit over (--refit needs a .gltf file with animations)");
  const auto load = [&](int f) {
    GltfLoadOptions o;
    o.time = end * double(f) / double(frames);
    return load_gltf(file, o).scene;
  };
  scene = load(0);
  const Camera cam = frame_bounds(compute_bounds(scene), float(width) / float(height));
  std::vector<Ray> rays;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      rays.push_back(generate_camera_ray(cam, width, height, x + 0.5f, y + 0.5f));
  AccelConfig never = config;
  never.bvh.refit_max_growth = 1000;
  std::unique_ptr<Accelerator> refitted = make_scene_accelerator("bvh", scene, config);
  std::unique_ptr<Accelerator> policy = make_scene_accelerator("bvh", scene, config);
  double refitted_sah = refitted->stats().sah_cost, policy_sah = policy->stats().sah_cost;
  const double first_sah = refitted_sah;
  std::ostringstream out;
  out << "frame,time_s,rebuild_s,refit_s,policy_s,policy_rebuilt,sah_rebuild,sah_refit,sah_policy,work_"
         "rebuild,"
         "work_refit,work_policy\n";
  double total[3] = {0, 0, 0}, work[3] = {0, 0, 0};
  int rebuilds = 0;
  std::printf("%s: %d frames over %.3f s, %llu triangles, %dx%d primary rays, %d threads\n", file.c_str(),
              frames, end, static_cast<unsigned long long>(count_triangles(scene)), width, height,
              thread_count(threads));
  std::printf("%6s %10s %10s %10s %9s %9s %9s %9s %9s %9s\n", "frame", "build ms", "refit ms", "policy ms",
              "SAH new", "refit", "policy", "work new", "refit", "policy");
  for (int f = 1; f <= frames; ++f) {
    scene = load(f);
    auto t0 = Clock::now();
    const auto fresh = make_scene_accelerator("bvh", scene, config);
    const double rebuild_s = seconds_since(t0);
    t0 = Clock::now();
    const RefitReport r1 = refit_or_rebuild_scene(refitted, refitted_sah, "bvh", scene, never);
    const double refit_s = seconds_since(t0);
    if (!r1.refitted) throw std::runtime_error(file + ": frame " + std::to_string(f) + ": " + r1.reason);
    t0 = Clock::now();
    const RefitReport r2 = refit_or_rebuild_scene(policy, policy_sah, "bvh", scene, config);
    const double policy_s = seconds_since(t0);
    rebuilds += !r2.refitted;
    const double sah[3] = {fresh->stats().sah_cost, refitted->stats().sah_cost, policy->stats().sah_cost};
    const double w[3] = {mean_work(*fresh, rays), mean_work(*refitted, rays), mean_work(*policy, rays)};
    const double s[3] = {rebuild_s, refit_s, policy_s};
    for (int k = 0; k < 3; ++k) total[k] += s[k], work[k] += w[k];
    out << f << ',' << end * f / frames << ',' << rebuild_s << ',' << refit_s << ',' << policy_s << ','
        << !r2.refitted << ',' << sah[0] << ',' << sah[1] << ',' << sah[2] << ',' << w[0] << ',' << w[1]
        << ',' << w[2] << '\n';
    if (f % 24 == 0 || f == frames)
      std::printf("%6d %10.2f %10.2f %10.2f %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f\n", f, rebuild_s * 1e3,
                  refit_s * 1e3, policy_s * 1e3, sah[0], sah[1], sah[2], w[0], w[1], w[2]);
    std::fflush(stdout);
  }
  std::printf(
      "total: rebuild every frame %.3f s, refit %.3f s (%.1fx faster), policy %.3f s with %d rebuilds "
      "(bvh.refit_max_growth %g); mean work per ray: rebuilt %.1f, refitted %.1f (%.2fx), policy %.1f "
      "(%.2fx); SAH of frame 0's build %.1f\n",
      total[0], total[1], total[1] > 0 ? total[0] / total[1] : 0.0, total[2], rebuilds,
      double(config.bvh.refit_max_growth), work[0] / frames, work[1] / frames, work[1] / work[0],
      work[2] / frames, work[2] / work[0], first_sah);
  if (!csv.empty())
    write_atomically(csv, [&](const std::filesystem::path& tmp) {
      std::ofstream f(tmp);
      f << out.str();
      if (!f) throw std::runtime_error(csv + ": cannot write");
    });
  return 0;
}

/// The command line of penumbra-bench (defaults as --help prints them).
struct BenchOptions {
  std::vector<std::string> scenes, accels{"embree", "bvh", "kdtree", "grid"},
      kinds{"primary", "shadow", "diffuse", "random"}, params;
  std::vector<int> threads{1, 0};
  int width = 512, height = 288, builds = 5, repeats = 3;
  std::string csv, json, svg, heatmaps;
  uint64_t seed = 1;
  std::vector<int> mc_resolutions;
  int noise_count = 0;
  bool raster = false, tradeoffs = false, collision = false;
  std::string refit_file;
  int refit_frames = 240;
  std::vector<std::string> queries;  ///< --queries: the kinds
  int query_count = 20000, k = 8;
  std::string command;  ///< the command line as typed, for the JSON
};

/// Declares every option on `app`, bound to `o`.
void add_bench_options(CLI::App& app, BenchOptions& o) {
  app.add_option("scenes", o.scenes,
                 "glTF or PLY files, or generated scenes gen:NAME[:TRIANGLES] with NAME one of atrium, soup, "
                 "stadium, slivers, terrain (default: scenes/default.gltf)");
  app.add_option("--seed", o.seed, "seed of the generated scenes (default 1)");
  app.add_option("--accel", o.accels,
                 "structures to measure, comma separated: " + accelerator_list() +
                     " (default embree,bvh,kdtree,grid)")
      ->delimiter(',');
  app.add_option("--rays", o.kinds,
                 "ray kinds: primary,shadow,diffuse,random (default), motion (primary rays at random "
                 "times through the scene's meshes deforming over the shutter) and splat (primary rays "
                 "gathering and blending the scene's Gaussian splats, or a generated sphere of 100k)")
      ->delimiter(',');
  app.add_option("--threads", o.threads, "thread counts, comma separated; 0 = all cores (default 1,0)")
      ->delimiter(',')
      ->check(CLI::Range(0, 1024));
  app.add_option("--width", o.width, "primary rays per row (default 512)")->check(CLI::Range(1, 8192));
  app.add_option("--height", o.height, "primary rays per column (default 288)")->check(CLI::Range(1, 8192));
  app.add_option("--builds", o.builds, "builds per structure; the median is reported (default 5)")
      ->check(CLI::Range(1, 100));
  app.add_option("--repeats", o.repeats, "timed passes over each ray set; the median is reported (default 3)")
      ->check(CLI::Range(1, 100));
  app.add_option("--accel-param", o.params, "build parameter KEY=VALUE, as for penumbra render");
  app.add_option("--csv", o.csv, "also write the table as CSV (written atomically)");
  app.add_option(
      "--json", o.json,
      "also write the results, machine, build, versions and command line as JSON (written atomically)");
  app.add_option(
      "--heatmaps", o.heatmaps,
      "also write a traversal-cost heat map (nodes + triangles per primary ray) per scene and structure "
      "into this folder: SCENE.ACCEL.cost.png (for embree, which keeps no counts: nanoseconds per ray)");
  app.add_option("--svg", o.svg,
                 "also write a bar chart of throughput and build time as SVG (written atomically)");
  app.add_option("--marching-cubes", o.mc_resolutions,
                 "instead of the structures: extract the CSG part's surface at these resolutions (comma "
                 "separated, e.g. 64,128,256,512) with each --threads count, --repeats times")
      ->delimiter(',');
  app.add_option("--noise", o.noise_count,
                 "instead of the structures: evaluate 3D Perlin noise, 5-octave fBm and Worley F1 at this "
                 "many random points on one thread, --repeats times, and print evaluations per second")
      ->check(CLI::Range(1, 1000000000));
  app.add_flag("--tradeoffs", o.tradeoffs,
               "instead of the main table: per scene and structure the memory, the build time with 1 thread "
               "and every core, the work per ray (median, 99th percentile, max of nodes + tests) and one "
               "thread's throughput on primary and random rays");
  app.add_option("--refit", o.refit_file,
                 "instead of the structures: an animated glTF file's frames with the BVH rebuilt, refitted "
                 "and under the rebuild policy (bvh.refit_max_growth): update times, SAH and work per ray");
  app.add_option("--refit-frames", o.refit_frames, "frames spanning the animation for --refit (default 240)")
      ->check(CLI::Range(1, 100000));
  app.add_option(
         "--queries", o.queries,
         "instead of the rays: spatial queries per structure, comma separated: nearest (the nearest "
         "primitive), knn (the --k nearest points of the scene's point sets, or of its vertices), within "
         "(a radius of 1% of the diagonal), overlap (boxes 2% of it); queries per second on the first "
         "--threads count, build time, memory, answers checked against brute force, nanoflann beside "
         "knn; scenes also gen:cloud:N (N points) and point files (.npy, .txt, .xyz, .ply vertices)")
      ->delimiter(',');
  app.add_option("--query-count", o.query_count, "query points per kind for --queries (default 20000)")
      ->check(CLI::Range(1, 100000000));
  app.add_option("--k", o.k, "neighbours per knn query (default 8)")->check(CLI::Range(1, 1024));
  app.add_flag(
      "--collision", o.collision,
      "instead of the rays: collision queries on each model (its meshes as one body): per proxy kind "
      "the fit time, bytes, distance tests per second and tightness; tests per second for every pair "
      "of kinds; the model against a turned copy at increasing overlap by the own trees, Embree's "
      "rtcCollide and FCL (when built with it), which must agree");
  app.add_flag("--raster", o.raster,
               "instead of the structures: frames per second of primary visibility at --width x --height, "
               "rasterised against Embree's and the BVH's camera rays, and the shaded raster preview");
}

/// Prints `e` and returns the exit code: 2 for bad input (std::invalid_argument, InputError),
/// else 1.
int report_error(const std::exception& e) {
  std::fprintf(stderr, "penumbra-bench: error: %s\n", e.what());
  const bool input = dynamic_cast<const std::invalid_argument*>(&e) || dynamic_cast<const InputError*>(&e);
  return input ? 2 : 1;
}

/// --noise, --marching-cubes, --refit, --tradeoffs, --collision, --raster or --queries: the mode's exit code;
/// nullopt when none is asked for (the main table).
std::optional<int> run_mode(const BenchOptions& o) {
  if (o.noise_count > 0) return run_noise(o.noise_count, o.repeats);
  try {
    if (!o.mc_resolutions.empty()) return run_marching_cubes(o.mc_resolutions, o.threads, o.repeats);
    if (!o.refit_file.empty() || o.tradeoffs) {
      AccelConfig config;
      for (const auto& p : o.params) apply_accel_param(config, p);
      validate(config);
      if (!o.refit_file.empty())
        return run_refit(o.refit_file, o.refit_frames, config, o.width, o.height, o.threads[0], o.csv);
      return run_tradeoffs(o.scenes, o.seed, o.accels, config, o.width, o.height, o.builds, o.repeats, o.csv,
                           o.svg, o.command);
    }
    if (o.collision) {
      bench::CollisionBenchConfig c;
      c.builds = o.builds;
      c.repeats = o.repeats;
      c.seed = o.seed;
      c.csv = o.csv;
      std::vector<std::pair<std::string, Scene>> scenes;
      for (const auto& spec : o.scenes) {
        std::string name;
        Scene scene = load_bench_scene(spec, o.seed, name);
        scenes.emplace_back(name, std::move(scene));
      }
      return bench::run_collision(scenes, c);
    }
    if (o.raster) return run_raster(o.scenes, o.seed, o.width, o.height, o.threads, o.builds, o.repeats);
    if (!o.queries.empty()) {
      AccelConfig config;
      for (const auto& p : o.params) apply_accel_param(config, p);
      validate(config);
      bench::QueryBenchConfig q;
      q.kinds = o.queries;
      q.accels = o.accels;
      q.count = o.query_count;
      q.k = o.k;
      q.threads = o.threads[0];
      q.builds = o.builds;
      q.repeats = o.repeats;
      q.seed = o.seed;
      q.csv = o.csv;
      q.svg = o.svg;
      q.caption = "Machine: " + bench::describe(bench::read_machine_info()) + "; " + software_line();
      std::vector<std::pair<std::string, Scene>> scenes;
      for (const auto& spec : o.scenes) {
        std::string name;
        Scene scene = load_bench_scene(spec, o.seed, name);
        scenes.emplace_back(name, std::move(scene));
      }
      return bench::run_queries(scenes, config, q);
    }
  } catch (const std::exception& e) {
    return report_error(e);
  }
  return std::nullopt;
}

/// The main table's options, checked before measuring for minutes: the output folders, the ray
/// kinds, the structures' names and parameters. Returns the parameters' configuration. Throws
/// std::invalid_argument.
AccelConfig check_table_options(const BenchOptions& o) {
  // Check the output folders before measuring for minutes.
  for (const std::string* out : {&o.csv, &o.json, &o.svg}) {
    if (out->empty()) continue;
    const std::filesystem::path dir =
        std::filesystem::path(*out).has_parent_path() ? std::filesystem::path(*out).parent_path() : ".";
    if (!std::filesystem::is_directory(dir))
      throw std::invalid_argument(*out + ": directory '" + dir.string() + "' does not exist");
  }
  if (!o.heatmaps.empty() && !std::filesystem::is_directory(o.heatmaps))
    throw std::invalid_argument("--heatmaps: directory '" + o.heatmaps + "' does not exist");
  for (const auto& k : o.kinds)
    if (k != "primary" && k != "shadow" && k != "diffuse" && k != "random" && k != "motion" && k != "splat")
      throw std::invalid_argument("--rays: unknown ray kind '" + k +
                                  "' (known: primary, shadow, diffuse, random, motion, splat)");
  AccelConfig config;
  for (const auto& p : o.params) apply_accel_param(config, p);
  validate(config);  // every structure's parameters, as the render session checks them
  for (const auto& a : o.accels) {
    const auto names = accelerator_names();
    if (std::find(names.begin(), names.end(), a) == names.end())
      throw std::invalid_argument("--accel: unknown accelerator '" + a + "'");
  }
  return config;
}

/// One scene's ray sets and the references every answer is checked against.
struct TableScene {
  std::string name;
  Scene scene;
  std::vector<GeometryView> views;
  std::vector<InstanceView> instances;
  std::unique_ptr<Accelerator> embree, exact;  ///< Embree, and brute force to settle disagreements
  std::vector<RaySet> sets;
  float scale = 0;
};

/// The rows of structure `accel_name` over the scene's ray sets, each printed as it is measured:
/// the median build, memory, SAH, agreement with Embree and throughput per thread count.
void measure_structure(const BenchOptions& o, const AccelConfig& config, const TableScene& ts,
                       const std::string& accel_name, std::vector<Row>& rows) {
  const std::string& name = ts.name;
  const Scene& scene = ts.scene;
  const auto& views = ts.views;
  const auto& instances = ts.instances;
  const auto& sets = ts.sets;
  const Accelerator& embree = *ts.embree;
  const Accelerator& exact = *ts.exact;
  const float scale = ts.scale;
  // Build: median of `o.builds` o.builds (the last one is measured).
  std::vector<double> times;
  std::unique_ptr<Accelerator> accel;
  for (int i = 0; i < o.builds; ++i) {
    accel.reset();
    const auto t0 = Clock::now();
    accel = make_accelerator(accel_name, views, instances, config);
    times.push_back(seconds_since(t0));
  }
  const AccelStats st = accel->stats();
  // The SAH under the benchmark's one set of constants, from this tree's node boxes.
  const bench::StructureSah sah = bench::measure_structure_sah(accel_name, views, instances, config, *accel);
  if (!sah.cost && accel_name == "bvh")
    std::fprintf(stderr, "penumbra-bench: %s %s: SAH n/a: %s\n", name.c_str(), accel_name.c_str(),
                 sah.note.c_str());
  if (!o.heatmaps.empty()) {
    RenderConfig rc;
    rc.width = o.width;
    rc.height = o.height;
    rc.spp = 1;
    validate(rc);
    const CostImage cost = render_cost(*accel, bench_camera(scene, o.width, o.height), rc);
    write_heatmap(total_cost(cost), o.width, o.height,
                  std::filesystem::path(o.heatmaps) / (name + "." + accel_name + ".cost.png"),
                  name + " " + cost_caption(cost, accel_name));
  }
  for (const auto& set : sets) {
    Row row{name, accel_name, set.kind, st.config, st.triangles, st.shapes, set.rays.size()};
    row.bytes = st.bytes;
    if (accel->counts_traversal() && st.shapes > 0) row.evals = evaluations_per_ray(*accel, set);
    row.build_s = bench::spread_of(times);
    row.sah = sah.cost;
    row.builder_sah = st.sah_cost;
    const Agreement g = check_against_embree(*accel, embree, exact, set, scale);
    row.mismatches = g.wrong;
    row.ties = g.ties;
    for (int t : o.threads) {
      const int n = t > 0 ? t : int(tbb::info::default_concurrency());
      uint64_t hits = 0;
      trace_seconds(*accel, set, n, hits);  // warm-up
      std::vector<double> mrays;
      for (int r = 0; r < o.repeats; ++r)
        mrays.push_back(double(set.rays.size()) / trace_seconds(*accel, set, n, hits) / 1e6);
      row.hits = hits;
      row.mrays.push_back({n, bench::spread_of(mrays)});
    }
    // Ratio to Embree on the same rays (Embree is measured first, see above).
    for (const auto& e : rows)
      if (e.scene == name && e.accel == "embree" && e.kind == row.kind)
        for (size_t i = 0; i < row.mrays.size(); ++i)
          row.vs_embree.push_back(row.mrays[i].mrays.median / e.mrays[i].mrays.median);
    if (accel_name == "embree")
      for (size_t i = 0; i < row.mrays.size(); ++i) row.vs_embree.push_back(1.0);
    std::printf("%s", bench::table_row(row).c_str());
    std::fflush(stdout);
    rows.push_back(row);
  }
}

/// Makes every mesh of `scene` deform over a shutter of 3 motion steps: step k moves each vertex
/// p by (k - 1) D (sin(7 y / L), sin(5 z / L), sin(3 x / L)) with L the bounds' diagonal and D 1 %
/// of it, a smooth, spatially varying motion in which neighbouring triangles move together as in
/// a skinned character (the still pose is step 1).
void deform_for_motion(Scene& scene) {
  const float L = std::max(length(compute_bounds(scene).extent()), 1e-30f), D = 0.01f * L;
  for (Mesh& m : scene.meshes) {
    if (m.positions.empty()) continue;
    m.motion_steps = 3;
    m.motion_positions.clear();
    for (int k = 0; k < 3; ++k)
      for (const Vec3f& p : m.positions) {
        const Vec3f d{std::sin(7 * p.y / L), std::sin(5 * p.z / L), std::sin(3 * p.x / L)};
        m.motion_positions.push_back(p + d * (float(k - 1) * D));
      }
  }
}

/// The motion ray set: the primary rays of make_ray_sets, each at a random time in [0, 1].
RaySet motion_rays(const Scene& scene, int w, int h) {
  const Camera cam = bench_camera(scene, w, h);
  std::mt19937 rng(20261205u);
  std::uniform_real_distribution<float> u(0, 1);
  RaySet set{"motion", {}, false};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Ray r = generate_camera_ray(cam, w, h, x + 0.5f, y + 0.5f);
      r.time = u(rng);
      set.rays.push_back(r);
    }
  return set;
}

/// The splat rows: every structure over the scene's splats (a generated sphere of 100k splats
/// fitted to its bounds when it has none) answering its primary rays with blend_splats.
void measure_splats(const BenchOptions& o, const AccelConfig& config, TableScene& t, std::vector<Row>& rows) {
  Scene& scene = t.scene;
  if (scene.splat_instances.empty()) {
    const Bounds3f b = compute_bounds(scene);
    SplatSphereConfig sc;
    sc.centre = (b.lo + b.hi) * 0.5f;
    const Vec3f e = b.extent();
    sc.radius = 0.3f * std::max(std::min({e.x, e.y, e.z}), 0.3f * max_component(e));
    sc.count = 100000;
    sc.opacity = 0.8f;
    scene.splat_clouds.push_back(make_splat_sphere(sc));
    scene.splat_instances.push_back({int(scene.splat_clouds.size()) - 1, Affine3f{}, -1});
  }
  const SplatGeometry g = splat_geometry(scene);
  t.views = g.views;
  t.instances = g.instances;
  t.embree = make_accelerator("embree", t.views, t.instances);
  t.exact = make_accelerator("brute", t.views, t.instances);
  const Camera cam = bench_camera(scene, o.width, o.height);
  RaySet set{"splat", {}, false, &scene};
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x)
      set.rays.push_back(generate_camera_ray(cam, o.width, o.height, x + 0.5f, y + 0.5f));
  t.sets = {std::move(set)};
  for (const auto& accel_name : o.accels) measure_structure(o, config, t, accel_name, rows);
}

/// Every scene and structure of the main table, each row printed as it is measured (Embree's
/// first, so that every later row shows its ratio); `embree_reference` receives the settings of
/// the Embree every answer is checked against.
std::vector<Row> measure_table(const BenchOptions& o, const AccelConfig& config,
                               std::string& embree_reference) {
  std::vector<Row> rows;
  for (const auto& file : o.scenes) {
    TableScene t;
    t.scene = load_bench_scene(file, o.seed, t.name);
    t.views = mesh_views(t.scene);
    t.instances = instance_views(t.scene);  // identity placements unless shapes are placed
    t.embree = make_accelerator("embree", t.views, t.instances);
    t.exact = make_accelerator("brute", t.views, t.instances);
    embree_reference = t.embree->stats().config;
    std::vector<std::string> still;
    std::copy_if(o.kinds.begin(), o.kinds.end(), std::back_inserter(still),
                 [](const std::string& k) { return k != "motion" && k != "splat"; });
    t.scale = length(compute_bounds(t.scene).extent());
    if (!still.empty()) {
      t.sets = make_ray_sets(t.scene, *t.embree, o.width, o.height, still);
      for (const auto& accel_name : o.accels) measure_structure(o, config, t, accel_name, rows);
    }
    if (std::count(o.kinds.begin(), o.kinds.end(), "splat")) measure_splats(o, config, t, rows);
    if (!std::count(o.kinds.begin(), o.kinds.end(), "motion")) continue;
    // The motion rays: the same scene deforming, every structure built over it anew.
    t.views = mesh_views(t.scene);
    t.instances = instance_views(t.scene);
    deform_for_motion(t.scene);
    t.views = mesh_views(t.scene);
    t.embree = make_accelerator("embree", t.views, t.instances);
    t.exact = make_accelerator("brute", t.views, t.instances);
    t.sets = {motion_rays(t.scene, o.width, o.height)};
    for (const auto& accel_name : o.accels) measure_structure(o, config, t, accel_name, rows);
  }
  return rows;
}

/// The table as CSV at `path`, written atomically.
void write_table_csv(const std::string& path, const std::vector<Row>& rows,
                     const std::vector<int>& thread_counts) {
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp);
    f << "scene,accel,rays,triangles,shapes,build_s,bytes,sah_cost,ray_count,hits,mismatches,ties,evals_"
         "per_ray";
    for (int t : thread_counts) f << ",mrays_" << t << "t,vs_embree_" << t << "t";
    f << ",builder_sah_cost,build_s_min,build_s_max";
    for (int t : thread_counts) f << ",mrays_min_" << t << "t,mrays_max_" << t << "t";
    f << "\n";
    for (const auto& r : rows) {
      f << r.scene << ',' << r.accel << ',' << r.kind << ',' << r.triangles << ',' << r.shapes << ','
        << r.build_s.median << ',' << r.bytes << ',';
      if (r.sah) f << *r.sah;  // empty: no SAH
      f << ',' << r.rays << ',' << r.hits << ',' << r.mismatches << ',' << r.ties << ',';
      if (r.evals >= 0) f << r.evals;
      for (size_t i = 0; i < r.mrays.size(); ++i)
        f << ',' << r.mrays[i].mrays.median << ',' << (i < r.vs_embree.size() ? r.vs_embree[i] : 0);
      f << ',' << r.builder_sah << ',' << r.build_s.min << ',' << r.build_s.max;
      for (const auto& m : r.mrays) f << ',' << m.mrays.min << ',' << m.mrays.max;
      f << "\n";
    }
    if (!f) throw std::runtime_error(path + ": cannot write");
  });
}

/// The results with the machine, the Embree reference, the SAH constants and the command line
/// as JSON at --json, written atomically.
void write_table_json(const BenchOptions& o, const std::vector<Row>& rows,
                      const std::string& embree_reference) {
  write_atomically(o.json, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp);
    const auto per_thread = [&](const Row& r, double bench::Spread::*field) {
      std::ostringstream out;
      for (size_t k = 0; k < r.mrays.size(); ++k)
        out << (k ? ", " : "") << '"' << r.mrays[k].threads << "\": " << r.mrays[k].mrays.*field;
      return "{" + out.str() + "}";
    };
    f << "{\n  \"command\": \"" << json_escape(o.command) << "\",\n  \"machine\": {\n"
      << machine_json() << "  },\n"
      << "  \"embree_reference\": \"" << json_escape(embree_reference) << "\",\n"
      << "  \"sah_constants\": {\"traversal\": " << bench::kSahConstants.traversal
      << ", \"intersection\": " << bench::kSahConstants.intersection << "},\n  \"results\": [\n";
    for (size_t i = 0; i < rows.size(); ++i) {
      const auto& r = rows[i];
      f << "    {\"scene\": \"" << json_escape(r.scene) << "\", \"accel\": \"" << r.accel
        << "\", \"config\": \"" << json_escape(r.config) << "\", \"rays\": \"" << r.kind
        << "\", \"triangles\": " << r.triangles << ", \"shapes\": " << r.shapes
        << ", \"evals_per_ray\": " << (r.evals >= 0 ? std::to_string(r.evals) : std::string("null"))
        << ", \"build_s\": " << r.build_s.median << ", \"build_s_min\": " << r.build_s.min
        << ", \"build_s_max\": " << r.build_s.max << ", \"bytes\": " << r.bytes
        << ", \"sah_cost\": " << (r.sah ? std::to_string(*r.sah) : std::string("null"))
        << ", \"builder_sah_cost\": " << r.builder_sah << ", \"ray_count\": " << r.rays
        << ", \"mismatches\": " << r.mismatches << ", \"ties\": " << r.ties
        << ", \"mrays\": " << per_thread(r, &bench::Spread::median)
        << ", \"mrays_min\": " << per_thread(r, &bench::Spread::min)
        << ", \"mrays_max\": " << per_thread(r, &bench::Spread::max) << "}"
        << (i + 1 < rows.size() ? "," : "") << "\n";
    }
    f << "  ]\n}\n";
    if (!f) throw std::runtime_error(o.json + ": cannot write");
  });
}

/// The bar chart of throughput and build time as SVG at --svg, written atomically.
void write_table_svg(const BenchOptions& o, const std::vector<Row>& rows,
                     const std::vector<int>& thread_counts) {
  write_atomically(o.svg, [&](const std::filesystem::path& tmp) {
    bench::RunSettings rs;
    rs.width = o.width, rs.height = o.height, rs.builds = o.builds, rs.repeats = o.repeats;
    rs.build_threads = int(tbb::info::default_concurrency());
    rs.threads = thread_counts;
    rs.machine = bench::describe(bench::read_machine_info());
    rs.software = software_line();
    std::ofstream f(tmp);
    f << bench::bar_chart_svg(bench::results_chart(rows, rs));
    if (!f) throw std::runtime_error(o.svg + ": cannot write");
  });
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "penumbra-bench: acceleration structures on the same scenes and rays, verified against Embree"};
  BenchOptions o;
  add_bench_options(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // usage errors exit 2, as for penumbra
  }
  for (int i = 0; i < argc; ++i) o.command += (i ? " " : "") + std::string(argv[i]);
  if (o.scenes.empty()) o.scenes.push_back(PENUMBRA_SOURCE_DIR "/scenes/default.gltf");
  if (const std::optional<int> rc = run_mode(o)) return *rc;
  try {
    const AccelConfig config = check_table_options(o);
    // Embree first, so every later row can show its ratio as soon as it is measured.
    if (auto it = std::find(o.accels.begin(), o.accels.end(), "embree"); it != o.accels.end())
      std::rotate(o.accels.begin(), it, it + 1);
    // The table, one row as soon as it is measured (long runs show progress).
    std::vector<int> thread_counts;  // 0 resolved to all cores
    for (int t : o.threads) thread_counts.push_back(t > 0 ? t : int(tbb::info::default_concurrency()));
    std::printf("%s%s", bench::sah_legend().c_str(), bench::table_header(thread_counts).c_str());
    std::string embree_reference;
    const std::vector<Row> rows = measure_table(o, config, embree_reference);
    uint64_t wrong = 0;
    for (const auto& r : rows) wrong += r.mismatches;
    if (!o.csv.empty()) write_table_csv(o.csv, rows, thread_counts);
    if (!o.json.empty()) write_table_json(o, rows, embree_reference);
    if (!o.svg.empty()) write_table_svg(o, rows, thread_counts);
    if (wrong > 0) {
      std::fprintf(stderr, "penumbra-bench: %llu rays disagree with Embree: these results do not count\n",
                   static_cast<unsigned long long>(wrong));
      return 1;
    }
    return 0;
  } catch (const std::exception& e) {
    return report_error(e);
  }
}
