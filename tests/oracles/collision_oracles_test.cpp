// Independent libraries as oracles for the collision queries (test-only dependencies, Debian
// libfcl-dev and libcgal-dev):
//  - FCL (the Flexible Collision Library, Pan, Chitta & Manocha, ICRA 2012): its mesh-mesh
//    collision over OBBRSS trees lists every pair of triangles that meet; mesh_contacts must
//    list the same pairs on closed meshes (icospheres, star polyhedra, rings) in random
//    placements, and agree on whether two meshes meet at all;
//  - CGAL's corefinement (Polygon Mesh Processing, corefine_and_compute_intersection, then
//    volume): the exact solid intersection of two closed meshes, which must lie within the
//    bound mesh_intersection_volume states.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Surface_mesh.h>
#include <fcl/fcl.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <random>
#include <set>

#include "renderer/collision/mesh_contact.h"
#include "renderer/collision/shared_volume.h"
#include "renderer/core/quaternion.h"
#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

// A mesh turned by q and moved by t, in double precision.
struct Placed {
  std::vector<DVec3> points;
  std::vector<uint32_t> triangles;
  std::vector<Vec3f> positions;  // the same points in single precision
};

Placed place(const TriMesh& m, const Quat& q, DVec3 t, double scale = 1) {
  Placed p;
  const Transform r = rotate(q);
  for (const Vec3f& v : m.positions) {
    const DVec3 s = to_dvec(v) * scale;
    const DVec3 w{r.m[0][0] * s.x + r.m[0][1] * s.y + r.m[0][2] * s.z + t.x,
                  r.m[1][0] * s.x + r.m[1][1] * s.y + r.m[1][2] * s.z + t.y,
                  r.m[2][0] * s.x + r.m[2][1] * s.y + r.m[2][2] * s.z + t.z};
    // Round to float first, so that every library sees the same points.
    p.positions.push_back({float(w.x), float(w.y), float(w.z)});
    p.points.push_back(to_dvec(p.positions.back()));
  }
  p.triangles = m.indices;
  return p;
}

std::set<std::pair<uint32_t, uint32_t>> fcl_pairs(const Placed& a, const Placed& b) {
  auto model = [](const Placed& p) {
    auto m = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
    std::vector<fcl::Vector3d> v;
    for (const DVec3& q : p.points) v.emplace_back(q.x, q.y, q.z);
    std::vector<fcl::Triangle> t;
    for (size_t i = 0; i < p.triangles.size(); i += 3)
      t.emplace_back(p.triangles[i], p.triangles[i + 1], p.triangles[i + 2]);
    m->beginModel();
    m->addSubModel(v, t);
    m->endModel();
    return m;
  };
  fcl::CollisionObjectd oa(model(a)), ob(model(b));
  fcl::CollisionRequestd request(1u << 30, false);
  fcl::CollisionResultd result;
  fcl::collide(&oa, &ob, request, result);
  std::set<std::pair<uint32_t, uint32_t>> out;
  for (size_t i = 0; i < result.numContacts(); ++i) {
    const fcl::Contactd& c = result.getContact(i);
    out.insert({uint32_t(c.b1), uint32_t(c.b2)});
  }
  return out;
}

std::set<std::pair<uint32_t, uint32_t>> own_pairs(const Placed& a, const Placed& b) {
  const ContactMesh ma{a.points, a.triangles}, mb{b.points, b.triangles};
  const ContactTree ta = build_contact_tree(ma), tb = build_contact_tree(mb);
  const MeshContacts c = mesh_contacts(ma, ta, mb, tb, size_t(1) << 30);
  return {c.pairs.begin(), c.pairs.end()};
}

double cgal_volume(const Placed& a, const Placed& b) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
  auto mesh = [](const Placed& p) {
    Mesh m;
    std::vector<Mesh::Vertex_index> v;
    for (const DVec3& q : p.points) v.push_back(m.add_vertex(Kernel::Point_3(q.x, q.y, q.z)));
    for (size_t i = 0; i < p.triangles.size(); i += 3)
      m.add_face(v[p.triangles[i]], v[p.triangles[i + 1]], v[p.triangles[i + 2]]);
    return m;
  };
  Mesh ma = mesh(a), mb = mesh(b), out;
  REQUIRE(CGAL::Polygon_mesh_processing::corefine_and_compute_intersection(ma, mb, out));
  return CGAL::to_double(CGAL::Polygon_mesh_processing::volume(out));
}

}  // namespace

TEST_CASE("FCL lists the same meeting triangle pairs as mesh_contacts", "[oracle][fcl]") {
  const TriMesh sphere = icosphere_mesh(3), star = icosphere_mesh(2, 1.7f),
                ring = ring_mesh(1.0f, 0.3f, 32, 12);
  const TriMesh* meshes[] = {&sphere, &star, &ring};
  std::mt19937_64 rng(45);
  std::uniform_real_distribution<double> u(-1, 1);
  int meeting = 0, apart = 0;
  for (int trial = 0; trial < 36; ++trial) {
    const TriMesh& ma = *meshes[trial % 3];
    const TriMesh& mb = *meshes[(trial / 3) % 3];
    const Placed a = place(ma, quat_axis_angle(u(rng), u(rng), 1, 3 * u(rng)), {0, 0, 0});
    const Placed b = place(mb, quat_axis_angle(1, u(rng), u(rng), 3 * u(rng)),
                           {1.2 * u(rng), 1.2 * u(rng), 1.6 * u(rng)}, 0.6 + 0.3 * u(rng));
    const auto mine = own_pairs(a, b), theirs = fcl_pairs(a, b);
    INFO("trial " << trial << ": " << mine.size() << " pairs here, " << theirs.size() << " by FCL");
    CHECK(mine == theirs);
    (mine.empty() ? apart : meeting) += 1;
  }
  CHECK(meeting > 20);
  CHECK(apart >= 1);
}

TEST_CASE("CGAL's exact intersection volume lies within mesh_intersection_volume's bound", "[oracle][cgal]") {
  const TriMesh sphere = icosphere_mesh(3), star = icosphere_mesh(2, 1.7f),
                ring = ring_mesh(1.0f, 0.3f, 32, 12);
  struct Case {
    const TriMesh* a;
    const TriMesh* b;
    DVec3 offset;
    double scale;
  };
  const Case cases[] = {{&sphere, &sphere, {0.7, 0.2, 0.1}, 1.0},
                        {&star, &sphere, {0.9, 0.3, 0}, 0.8},
                        {&ring, &sphere, {1.0, 0.1, 0}, 0.5},
                        {&star, &ring, {0.2, 0.5, 0.1}, 1.0}};
  for (const Case& c : cases) {
    const Placed a = place(*c.a, Quat{}, {0, 0, 0});
    const Placed b = place(*c.b, quat_axis_angle(1, 1, 0, 0.4), c.offset, c.scale);
    const double want = cgal_volume(a, b);
    const SolidMesh sa = build_solid_mesh(a.positions, a.triangles),
                    sb = build_solid_mesh(b.positions, b.triangles);
    const VolumeEstimate got = mesh_intersection_volume({&sa, 1}, {&sb, 1});
    INFO("CGAL " << want << ", here " << got.volume << " +- " << got.error);
    CHECK(want > 0.01);
    CHECK(std::abs(got.volume - want) <= got.error + 1e-9 * want);
    CHECK(got.error <= 0.02 * std::min(sa.bsp.volume, sb.bsp.volume));
  }
}
