// penumbra-bench --collision.
#include "benchmarks/collision.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include "benchmarks/timing.h"
#include "io/files/atomic_file.h"
#include "renderer/accel/embree.h"
#include "renderer/collision/gjk.h"
#include "renderer/collision/mesh_contact.h"
#include "renderer/collision/scene_proxies.h"
#include "renderer/core/quaternion.h"

#ifdef PENUMBRA_HAVE_FCL
#include <fcl/fcl.h>
#endif

namespace penumbra::bench {

namespace {

// Every placed mesh of the scene as one body.
NodeGeometry whole_body(const Scene& scene) {
  NodeGeometry body;
  body.enclosed_volume = NAN;
  for (const NodeGeometry& g : node_geometry(scene, {}, -1)) {
    const uint32_t base = uint32_t(body.points.size());
    body.points.insert(body.points.end(), g.points.begin(), g.points.end());
    body.positions.insert(body.positions.end(), g.positions.begin(), g.positions.end());
    for (uint32_t i : g.triangles) body.triangles.push_back(base + i);
    for (uint32_t i : g.measured) body.measured.push_back(base + i);
  }
  return body;
}

uint64_t proxy_bytes(const Proxy& p) {
  uint64_t bytes = sizeof(Proxy);
  for (const ConvexPolyhedron& c : p.parts)
    bytes += c.vertices.size() * sizeof(DVec3) + c.planes.size() * sizeof(DPlane) +
             (c.triangles.size() + c.face_of.size()) * sizeof(uint32_t);
  return bytes;
}

// The proxy moved rigidly: turned by r about the origin, then moved by t.
Proxy moved(const Proxy& p, const Transform& r, DVec3 t) {
  auto at = [&](DVec3 v) {
    return DVec3{r.m[0][0] * v.x + r.m[0][1] * v.y + r.m[0][2] * v.z + t.x,
                 r.m[1][0] * v.x + r.m[1][1] * v.y + r.m[1][2] * v.z + t.y,
                 r.m[2][0] * v.x + r.m[2][1] * v.y + r.m[2][2] * v.z + t.z};
  };
  auto turn = [&](DVec3 v) { return at(v) - t; };
  Proxy q = p;
  q.sphere.center = at(p.sphere.center);
  q.box.center = at(p.box.center);
  for (DVec3& a : q.box.axis) a = turn(a);
  q.capsule.a = at(p.capsule.a);
  q.capsule.b = at(p.capsule.b);
  for (ConvexPolyhedron& c : q.parts) {
    for (DVec3& v : c.vertices) v = at(v);
    for (DPlane& pl : c.planes) {
      pl.n = turn(pl.n);
      pl.d += dot(pl.n, t);
    }
  }
  return q;
}

struct Placement {
  Transform turn;
  DVec3 offset;
};

// Random placements of a copy around the body: turned at random, moved up to 1.2 x its size.
std::vector<Placement> placements(int count, double size, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Placement> out;
  for (int i = 0; i < count; ++i)
    out.push_back({rotate(quat_axis_angle(u(rng), u(rng), u(rng), 3.14159 * u(rng))),
                   DVec3{u(rng), u(rng), u(rng)} * (1.2 * size)});
  return out;
}

// Distance tests per second between `a` and each placement of `b`.
double tests_per_second(const Proxy& a, const std::vector<Proxy>& bs, int repeats) {
  double sink = 0;
  const double s = median_seconds(repeats, [&] {
    for (const Proxy& b : bs) sink += proxy_distance(a, b).distance;
  });
  if (sink == -1) std::printf(" ");  // keep the calls
  return double(bs.size()) / std::max(s, 1e-12);
}

struct Row {
  std::string scene, table, method, kind;
  double value_a = 0, value_b = 0, value_c = 0, value_d = 0;
};

void proxy_tables(const std::string& name, const NodeGeometry& body, double size,
                  const CollisionBenchConfig& c, std::vector<Row>& rows) {
  const std::vector<Placement> where = placements(c.tests, size, c.seed);
  const double hull_volume = convex_hull(body.points).volume;
  std::printf(
      "\n%s: proxies of %zu vertices, %zu triangles (median of %d fits; %d distance tests against a "
      "turned copy; Hausdorff over %d samples, / diagonal)\n",
      name.c_str(), body.points.size(), body.triangles.size() / 3, c.builds, c.tests, c.samples);
  std::printf("%-10s %12s %12s %14s %12s %12s\n", "kind", "fit ms", "bytes", "tests/s", "vol/hull",
              "hausdorff");
  std::vector<Proxy> fitted;
  for (int k = 0; k < kProxyKindCount; ++k) {
    const ProxyKind kind = ProxyKind(k);
    Proxy p;
    std::vector<double> fits;
    for (int b = 0; b < c.builds; ++b) {
      const auto t0 = Clock::now();
      p = fit_proxy(kind, body.points, body.triangles);
      fits.push_back(seconds_since(t0));
    }
    std::vector<Proxy> copies;
    for (const Placement& w : where) copies.push_back(moved(p, w.turn, w.offset));
    const double rate = tests_per_second(p, copies, c.repeats);
    const ProxyTightness t = proxy_tightness(p, body, size_t(c.samples), 0, hull_volume);
    std::printf("%-10s %12.3f %12llu %14.0f %12.4f %12.5f\n", proxy_kind_name(kind), median(fits) * 1e3,
                (unsigned long long)proxy_bytes(p), rate, t.hull_ratio, t.hausdorff / size);
    rows.push_back({name, "proxy", proxy_kind_name(kind), "", median(fits) * 1e3, double(proxy_bytes(p)),
                    rate, t.hausdorff / size});
    fitted.push_back(std::move(p));
  }
  std::printf("\n%s: distance tests per second, row kind against column kind (turned copies)\n",
              name.c_str());
  std::printf("%-10s", "");
  for (int k = 0; k < kProxyKindCount; ++k) std::printf(" %10s", proxy_kind_name(ProxyKind(k)));
  std::printf("\n");
  for (int i = 0; i < kProxyKindCount; ++i) {
    std::printf("%-10s", proxy_kind_name(ProxyKind(i)));
    for (int j = 0; j < kProxyKindCount; ++j) {
      std::vector<Proxy> copies;
      for (const Placement& w : where) copies.push_back(moved(fitted[size_t(j)], w.turn, w.offset));
      const double rate = tests_per_second(fitted[size_t(i)], copies, c.repeats);
      std::printf(" %10.0f", rate);
      rows.push_back({name, "pair", proxy_kind_name(ProxyKind(i)), proxy_kind_name(ProxyKind(j)), rate});
    }
    std::printf("\n");
  }
}

std::vector<Bounds3f> triangle_boxes(const std::vector<DVec3>& p, const std::vector<uint32_t>& t) {
  std::vector<Bounds3f> out;
  for (size_t i = 0; i < t.size(); i += 3) {
    Bounds3f b;
    for (int k = 0; k < 3; ++k) {
      const DVec3 v = p[t[i + size_t(k)]];
      b = merge(b, Vec3f{std::nextafter(float(v.x), -INFINITY), std::nextafter(float(v.y), -INFINITY),
                         std::nextafter(float(v.z), -INFINITY)});
      b = merge(b, Vec3f{std::nextafter(float(v.x), INFINITY), std::nextafter(float(v.y), INFINITY),
                         std::nextafter(float(v.z), INFINITY)});
    }
    out.push_back(b);
  }
  return out;
}

bool meet(const std::vector<DVec3>& pa, const std::vector<uint32_t>& ta, uint32_t s,
          const std::vector<DVec3>& pb, const std::vector<uint32_t>& tb, uint32_t t) {
  return triangles_meet(pa[ta[3 * s]], pa[ta[3 * s + 1]], pa[ta[3 * s + 2]], pb[tb[3 * t]], pb[tb[3 * t + 1]],
                        pb[tb[3 * t + 2]]);
}

#ifdef PENUMBRA_HAVE_FCL
// FCL's OBBRSS tree over the triangles.
std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> fcl_model(const std::vector<DVec3>& points,
                                                       const std::vector<uint32_t>& triangles) {
  auto m = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  std::vector<fcl::Vector3d> v;
  for (const DVec3& q : points) v.emplace_back(q.x, q.y, q.z);
  std::vector<fcl::Triangle> t;
  for (size_t i = 0; i < triangles.size(); i += 3)
    t.emplace_back(triangles[i], triangles[i + 1], triangles[i + 2]);
  m->beginModel();
  m->addSubModel(v, t);
  m->endModel();
  return m;
}
#endif

// The model against a turned copy moved along x so that their x extents overlap by `overlap`.
int mesh_table(const std::string& name, const NodeGeometry& body, const CollisionBenchConfig& c,
               std::vector<Row>& rows) {
  DVec3 lo = body.points[0], hi = body.points[0];
  for (const DVec3& p : body.points)
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)},
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  const DVec3 centre = (lo + hi) * 0.5;
  const Transform turn = rotate(quat_axis_angle(0.3, 1, 0.2, 0.5));
  std::printf(
      "\n%s: against a copy turned 0.5 rad, its centre moved along x by (1 - overlap) x the x extent "
      "(ms, median of %d; pairs: meeting triangle pairs)\n",
      name.c_str(), c.repeats);
  std::printf("%8s %10s %12s %12s %12s %12s %12s %10s\n", "overlap", "pairs", "own build", "own query",
              "embree b+q", "fcl build", "fcl query", "agree");
  int wrong = 0;
  const ContactMesh ma{body.points, body.triangles};
  std::vector<double> own_builds;
  ContactTree ta;
  for (int b = 0; b < c.builds; ++b) {
    const auto t0 = Clock::now();
    ta = build_contact_tree(ma);
    own_builds.push_back(seconds_since(t0));
  }
  const std::vector<Bounds3f> boxes_a = triangle_boxes(body.points, body.triangles);
  double fcl_build = NAN;
#ifdef PENUMBRA_HAVE_FCL
  std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> fa;
  std::vector<double> fcl_builds;
  for (int b = 0; b < c.builds; ++b) {
    const auto t0 = Clock::now();
    fa = fcl_model(body.points, body.triangles);
    fcl_builds.push_back(seconds_since(t0));
  }
  fcl_build = median(fcl_builds);
#endif
  for (double overlap : c.overlaps) {
    std::vector<DVec3> pb;
    const DVec3 shift{(1 - overlap) * (hi.x - lo.x), 0, 0};
    for (const DVec3& p : body.points) {
      const DVec3 q = p - centre;
      pb.push_back(centre + shift +
                   DVec3{turn.m[0][0] * q.x + turn.m[0][1] * q.y + turn.m[0][2] * q.z,
                         turn.m[1][0] * q.x + turn.m[1][1] * q.y + turn.m[1][2] * q.z,
                         turn.m[2][0] * q.x + turn.m[2][1] * q.y + turn.m[2][2] * q.z});
    }
    const ContactMesh mb{pb, body.triangles};
    const ContactTree tb = build_contact_tree(mb);
    uint64_t own_pairs = 0;
    const double own_query =
        median_seconds(c.repeats, [&] { own_pairs = mesh_contacts(ma, ta, mb, tb, 0).meeting; });
    uint64_t embree_pairs = 0;
    const double embree = median_seconds(c.repeats, [&] {
      embree_pairs = 0;
      for (const auto& [s, t] : embree_collide(boxes_a, triangle_boxes(pb, body.triangles)))
        embree_pairs += meet(body.points, body.triangles, s, pb, body.triangles, t);
    });
    double fcl_query = NAN;
    uint64_t fcl_pairs = own_pairs;  // without FCL: nothing to compare
#ifdef PENUMBRA_HAVE_FCL
    {
      const auto fb = fcl_model(pb, body.triangles);
      fcl::CollisionObjectd oa(fa), ob(fb);  // their boxes are computed here, outside the timing
      fcl_query = median_seconds(c.repeats, [&] {
        fcl::CollisionRequestd request(1u << 30, false);
        fcl::CollisionResultd result;
        fcl::collide(&oa, &ob, request, result);
        fcl_pairs = result.numContacts();
      });
    }
#endif
    const bool agree = own_pairs == embree_pairs && own_pairs == fcl_pairs;
    wrong += !agree;
    std::printf("%8.2f %10llu %12.2f %12.2f %12.2f %12.2f %12.2f %10s\n", overlap,
                (unsigned long long)own_pairs, median(own_builds) * 1e3, own_query * 1e3, embree * 1e3,
                fcl_build * 1e3, fcl_query * 1e3, agree ? "yes" : "NO");
    rows.push_back({name, "mesh", "own", std::to_string(overlap), median(own_builds) * 1e3, own_query * 1e3,
                    double(own_pairs)});
    rows.push_back({name, "mesh", "embree", std::to_string(overlap), 0, embree * 1e3, double(embree_pairs)});
#ifdef PENUMBRA_HAVE_FCL
    rows.push_back(
        {name, "mesh", "fcl", std::to_string(overlap), fcl_build * 1e3, fcl_query * 1e3, double(fcl_pairs)});
#endif
  }
#ifndef PENUMBRA_HAVE_FCL
  std::printf("(FCL is not installed: no FCL columns)\n");
#endif
  return wrong;
}

void write_csv(const std::string& path, const std::vector<Row>& rows) {
  std::ostringstream out;
  out << "scene,table,method,kind,a,b,c,d\n";
  for (const Row& r : rows)
    out << r.scene << ',' << r.table << ',' << r.method << ',' << r.kind << ',' << r.value_a << ','
        << r.value_b << ',' << r.value_c << ',' << r.value_d << '\n';
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp);
    f << out.str();
    if (!f) throw std::runtime_error(path + ": cannot write");
  });
}

}  // namespace

int run_collision(const std::vector<std::pair<std::string, Scene>>& scenes,
                  const CollisionBenchConfig& config) {
  std::vector<Row> rows;
  int wrong = 0;
  for (const auto& [name, scene] : scenes) {
    const NodeGeometry body = whole_body(scene);
    if (body.triangles.empty()) throw std::invalid_argument(name + ": no triangles to collide");
    DVec3 lo = body.points[0], hi = body.points[0];
    for (const DVec3& p : body.points)
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)},
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    const double size = length(hi - lo);
    proxy_tables(name, body, size, config, rows);
    wrong += mesh_table(name, body, config, rows);
  }
  if (!config.csv.empty()) write_csv(config.csv, rows);
  if (wrong) std::fprintf(stderr, "penumbra-bench: %d overlaps where the mesh methods disagree\n", wrong);
  return wrong ? 1 : 0;
}

}  // namespace penumbra::bench
