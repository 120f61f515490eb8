// penumbra-bench --queries; see queries.h.
#include "benchmarks/queries.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <stdexcept>

#include "benchmarks/chart.h"
#include "benchmarks/point_kdtree.h"
#include "benchmarks/timing.h"
#include "io/files/atomic_file.h"
#include "renderer/accel/query.h"
#include "renderer/core/parallel.h"
#include "renderer/integrators/scene_accel.h"

namespace penumbra::bench {

namespace {

// One row of the table.
struct QueryRow {
  std::string scene, kind, structure;
  uint64_t primitives = 0;
  double build_ms = 0, bytes = 0, queries_per_second = 0;
  uint64_t verified = 0, wrong = 0;
};

void print_row(const QueryRow& r) {
  std::printf("%-22s %-8s %-8s %10llu %10.1f %9.1f %7.1f %12.0f %6llu/%llu\n", r.scene.c_str(),
              r.kind.c_str(), r.structure.c_str(), static_cast<unsigned long long>(r.primitives), r.build_ms,
              r.bytes / (1 << 20), r.primitives ? r.bytes / double(r.primitives) : 0.0, r.queries_per_second,
              static_cast<unsigned long long>(r.wrong), static_cast<unsigned long long>(r.verified));
  std::fflush(stdout);
}

// The geometry a kind runs on: the triangles and placed shapes, or one point set.
struct Target {
  std::vector<GeometryView> views;
  std::vector<InstanceView> instances;  // empty: single level
  std::vector<Vec3f> points;            // the point set's positions (knn)
  std::vector<uint32_t> degenerate;     // (i, i, i) per point
  Bounds3f bounds;
  uint64_t primitives = 0;
  QueryScene query() const { return {views, instances}; }
};

// Every instance of the scene but those of point sets, over every mesh and shape.
Target surface_target(const Scene& scene) {
  Target t;
  t.views = mesh_views(scene);
  const std::vector<InstanceView> all = instance_views(scene);
  for (size_t i = 0; i < all.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.shape < 0 && scene.meshes[size_t(inst.mesh)].points) continue;
    t.instances.push_back(all[i]);
    t.primitives += inst.shape >= 0 ? 1 : scene.meshes[size_t(inst.mesh)].indices.size() / 3;
  }
  t.bounds = compute_bounds(scene);
  return t;
}

Target point_target(const Scene& scene) {
  Target t;
  bool has_points = false;
  for (const Mesh& m : scene.meshes) has_points = has_points || m.points;
  for (const Mesh& m : scene.meshes)
    if (m.points == has_points) t.points.insert(t.points.end(), m.positions.begin(), m.positions.end());
  t.degenerate.resize(t.points.size() * 3);
  for (size_t i = 0; i < t.points.size(); ++i)
    t.degenerate[3 * i] = t.degenerate[3 * i + 1] = t.degenerate[3 * i + 2] = uint32_t(i);
  for (Vec3f p : t.points) t.bounds = merge(t.bounds, p);
  t.views.push_back({t.points, t.degenerate});
  t.primitives = t.points.size();
  return t;
}

// Query points: half uniform over the bounds grown by 10%, half near the geometry (sample
// points moved by 1% of the diagonal).
std::vector<Vec3f> query_points(const Target& t, int count, uint64_t seed) {
  std::mt19937 rng(uint32_t(seed * 7919 + 17));
  std::uniform_real_distribution<float> u(0, 1);
  const Vec3f lo = t.bounds.lo - t.bounds.extent() * 0.05f, ext = t.bounds.extent() * 1.1f;
  std::normal_distribution<float> g(0, std::max(1e-6f, 0.01f * length(t.bounds.extent())));
  std::vector<Vec3f> near;
  for (const GeometryView& v : t.views)
    if (!v.shape && !v.positions.empty())
      for (int i = 0; i < 64; ++i)
        near.push_back(v.positions[size_t(u(rng) * float(v.positions.size() - 1))]);
  std::vector<Vec3f> q;
  for (int i = 0; i < count; ++i)
    if (i % 2 || near.empty())
      q.push_back(lo + Vec3f{u(rng) * ext.x, u(rng) * ext.y, u(rng) * ext.z});
    else
      q.push_back(near[size_t(i / 2) % near.size()] + Vec3f{g(rng), g(rng), g(rng)});
  return q;
}

bool same(const std::vector<PrimitiveMatch>& a, const std::vector<PrimitiveMatch>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].geom_id != b[i].geom_id || a[i].prim_id != b[i].prim_id || a[i].distance != b[i].distance)
      return false;
  return true;
}

// The answers of query `i` of `kind` into `out`.
using Answer = std::function<void(const Accelerator&, size_t i, std::vector<PrimitiveMatch>& out)>;

Answer answer_of(const std::string& kind, const QueryScene& scene, const std::vector<Vec3f>& q, int k,
                 float radius, Vec3f half) {
  if (kind == "nearest" || kind == "knn") {
    const int n = kind == "knn" ? k : 1;
    return [&scene, &q, n](const Accelerator& a, size_t i, std::vector<PrimitiveMatch>& out) {
      out.resize(size_t(n));
      out.resize(nearest(a, scene, q[i], n, kInfinity, out));
    };
  }
  if (kind == "within")
    return [&scene, &q, radius](const Accelerator& a, size_t i, std::vector<PrimitiveMatch>& out) {
      within(a, scene, q[i], radius, out);
    };
  return [&scene, &q, half](const Accelerator& a, size_t i, std::vector<PrimitiveMatch>& out) {
    overlap(a, scene, {q[i] - half, q[i] + half}, out);
  };
}

// Every query of `answer` on `threads` workers.
void run_all(const Accelerator& a, const Answer& answer, size_t count, int threads) {
  tbb::task_arena arena(thread_count(threads));
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 64), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<PrimitiveMatch> out;
      out.reserve(64);
      for (size_t i = r.begin(); i < r.end(); ++i) answer(a, i, out);
    });
  });
}

#ifdef PENUMBRA_HAVE_NANOFLANN
// nanoflann's kD-tree (leaves of at most 10 points, its default) on the same points and queries:
// build, memory (the tree plus the 12 bytes per point it indexes), throughput, and its answers
// against brute force's (the same distances within 1e-5, each returned point at its distance).
QueryRow nanoflann_row(const std::string& scene_name, const Target& t, const std::vector<Vec3f>& q,
                       const QueryBenchConfig& o, const std::vector<std::vector<PrimitiveMatch>>& truth) {
  QueryRow row{scene_name, "knn", "nanoflann", t.primitives};
  PointAdaptor adaptor{t.points};
  std::vector<double> builds;
  std::unique_ptr<PointTree> tree;
  for (int b = 0; b < o.builds; ++b) {
    tree.reset();
    const auto t0 = Clock::now();
    tree = std::make_unique<PointTree>(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));  // builds
    builds.push_back(seconds_since(t0));
  }
  row.build_ms = median(builds) * 1e3;
  row.bytes = double(tree->usedMemory(*tree)) + 12.0 * double(t.points.size());
  const size_t k = size_t(o.k);
  const auto search = [&](size_t i, uint32_t* ids, float* d2) {
    return tree->knnSearch(&q[i].x, k, ids, d2);
  };
  const double s = median_seconds(o.repeats, [&] {
    tbb::task_arena arena(thread_count(o.threads));
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, q.size(), 64),
                        [&](const tbb::blocked_range<size_t>& r) {
                          std::vector<uint32_t> ids(k);
                          std::vector<float> d2(k);
                          for (size_t i = r.begin(); i < r.end(); ++i) search(i, ids.data(), d2.data());
                        });
    });
  });
  row.queries_per_second = double(q.size()) / s;
  std::vector<uint32_t> ids(k);
  std::vector<float> d2(k);
  for (size_t i = 0; i < truth.size(); ++i) {
    const size_t n = search(i, ids.data(), d2.data());
    // Right when the distances are brute force's and each point lies at its distance: points
    // at the same distance are equally near, whichever of them a structure returns.
    bool ok = n == truth[i].size();
    for (size_t j = 0; ok && j < n; ++j) {
      const float want = truth[i][j].distance, tol = 1e-5f * want + 1e-7f;
      ok = std::fabs(std::sqrt(d2[j]) - want) <= tol && ids[j] < t.points.size() &&
           std::fabs(length(t.points[ids[j]] - q[i]) - want) <= tol;
    }
    row.wrong += !ok;
    ++row.verified;
  }
  return row;
}
#endif

void write_csv(const std::string& path, const std::vector<QueryRow>& rows, int threads) {
  std::ostringstream out;
  out << "scene,query,structure,primitives,build_ms,bytes,bytes_per_primitive,queries_per_second,threads,"
         "verified,wrong\n";
  for (const auto& r : rows)
    out << r.scene << ',' << r.kind << ',' << r.structure << ',' << r.primitives << ',' << r.build_ms << ','
        << r.bytes << ',' << (r.primitives ? r.bytes / double(r.primitives) : 0.0) << ','
        << r.queries_per_second << ',' << threads << ',' << r.verified << ',' << r.wrong << '\n';
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp);
    f << out.str();
    if (!f) throw std::runtime_error(path + ": cannot write");
  });
}

// A panel per query kind and a row per scene: the queries per second of every structure.
void write_svg(const QueryBenchConfig& o, const std::vector<QueryRow>& rows, int threads) {
  BarChart chart;
  chart.title = "Spatial queries: throughput per structure";
  for (const QueryRow& r : rows)
    if (std::find(chart.series.begin(), chart.series.end(), r.structure) == chart.series.end())
      chart.series.push_back(r.structure);
  for (const QueryRow& r : rows) {
    if (std::find(chart.row_labels.begin(), chart.row_labels.end(), r.scene) != chart.row_labels.end())
      continue;
    chart.row_labels.push_back(r.scene);
    std::vector<BarPanel> panels;
    for (const std::string& kind : o.kinds) {
      BarPanel p;
      p.title = kind == "knn" ? "k = " + std::to_string(o.k) + " nearest points" : kind;
      p.x_label = "query";
      p.quantity = "throughput";
      p.unit = "queries/s";
      p.groups = {kind};
      p.values.assign(1, std::vector<std::optional<Spread>>(chart.series.size()));
      bool any = false;
      for (const QueryRow& q : rows)
        if (q.scene == r.scene && q.kind == kind) {
          const size_t s =
              size_t(std::find(chart.series.begin(), chart.series.end(), q.structure) - chart.series.begin());
          p.values[0][s] = Spread{q.queries_per_second, q.queries_per_second, q.queries_per_second};
          any = true;
        }
      if (any) panels.push_back(std::move(p));
    }
    chart.rows.push_back(std::move(panels));
  }
  chart.caption = {std::to_string(o.count) +
                       " queries per kind (half near the geometry, half uniform over its bounds), " +
                       std::to_string(threads) + " thread" + (threads == 1 ? "" : "s") + ", the median of " +
                       std::to_string(o.repeats) + " passes after a warm-up; the first " +
                       std::to_string(o.verified) + " answers of every bar equal brute force's.",
                   o.caption};
  write_atomically(o.svg, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp);
    f << bar_chart_svg(chart);
    if (!f) throw std::runtime_error(o.svg + ": cannot write");
  });
}

}  // namespace

const std::vector<std::string>& query_kinds() {
  static const std::vector<std::string> kinds{"nearest", "knn", "within", "overlap"};
  return kinds;
}

int run_queries(const std::vector<std::pair<std::string, Scene>>& scenes, const AccelConfig& config,
                const QueryBenchConfig& o) {
  for (const auto& kind : o.kinds)
    if (std::find(query_kinds().begin(), query_kinds().end(), kind) == query_kinds().end())
      throw std::invalid_argument("--queries: unknown query '" + kind +
                                  "' (known: nearest, knn, within, overlap)");
  for (const std::string* out : {&o.csv, &o.svg}) {
    const std::filesystem::path dir =
        std::filesystem::path(*out).has_parent_path() ? std::filesystem::path(*out).parent_path() : ".";
    if (!out->empty() && !std::filesystem::is_directory(dir))
      throw std::invalid_argument(*out + ": directory '" + dir.string() + "' does not exist");
  }
  const int threads = o.threads > 0 ? o.threads : thread_count(0);
  std::printf(
      "queries: %d per kind, k = %d (knn), %d thread%s, median of %d builds and %d passes; within: radius "
      "1%% of the diagonal; overlap: boxes 2%% of it; the first %d answers of each compared with brute "
      "force\n",
      o.count, o.k, threads, threads == 1 ? "" : "s", o.builds, o.repeats, o.verified);
  std::printf("%-22s %-8s %-8s %10s %10s %9s %7s %12s %10s\n", "scene", "query", "struct", "primitives",
              "build ms", "MiB", "B/prim", "queries/s", "wrong");
  std::vector<QueryRow> rows;
  uint64_t wrong = 0;
  for (const auto& [name, scene] : scenes) {
    const Target surface = surface_target(scene), points = point_target(scene);
    for (const std::string& kind : o.kinds) {
      const Target& t = kind == "knn" ? points : surface;
      if (t.primitives == 0) continue;
      const QueryScene qs = t.query();
      const std::vector<Vec3f> q = query_points(t, o.count, o.seed);
      const float diag = length(t.bounds.extent());
      const Answer answer = answer_of(kind, qs, q, o.k, 0.01f * diag, Vec3f{1, 1, 1} * (0.01f * diag));
      // The reference answers of the verified queries.
      const auto build = [&](const std::string& which) {
        return t.instances.empty() ? make_accelerator(which, t.views, config)
                                   : make_accelerator(which, t.views, t.instances, config);
      };
      const auto brute = build("brute");
      const size_t verified = std::min<size_t>(size_t(o.verified), q.size());
      std::vector<std::vector<PrimitiveMatch>> truth(verified);
      tbb::parallel_for(size_t(0), verified, [&](size_t i) { answer(*brute, i, truth[i]); });
      for (const std::string& accel_name : o.accels) {
        if (accel_name == "brute") continue;
        QueryRow row{name, kind, accel_name, t.primitives};
        std::vector<double> builds;
        std::unique_ptr<Accelerator> accel;
        for (int b = 0; b < o.builds; ++b) {
          accel.reset();
          const auto t0 = Clock::now();
          accel = build(accel_name);
          builds.push_back(seconds_since(t0));
        }
        row.build_ms = median(builds) * 1e3;
        row.bytes = double(accel->stats().bytes);
        row.queries_per_second = double(q.size()) / median_seconds(o.repeats, [&] {
                                   run_all(*accel, answer, q.size(), o.threads);
                                 });
        std::vector<PrimitiveMatch> got;
        for (size_t i = 0; i < verified; ++i) {
          answer(*accel, i, got);
          row.wrong += !same(got, truth[i]);
        }
        row.verified = verified;
        wrong += row.wrong;
        print_row(row);
        rows.push_back(row);
      }
#ifdef PENUMBRA_HAVE_NANOFLANN
      if (kind == "knn") {
        const QueryRow row = nanoflann_row(name, t, q, o, truth);
        wrong += row.wrong;
        print_row(row);
        rows.push_back(row);
      }
#else
      if (kind == "knn") std::printf("(nanoflann is not installed: no nanoflann row)\n");
#endif
    }
  }
  if (!o.csv.empty()) write_csv(o.csv, rows, threads);
  if (!o.svg.empty()) write_svg(o, rows, threads);
  if (wrong > 0) {
    std::fprintf(stderr,
                 "penumbra-bench: %llu query answers differ from brute force: these results do not count\n",
                 static_cast<unsigned long long>(wrong));
    return 1;
  }
  return 0;
}

}  // namespace penumbra::bench
