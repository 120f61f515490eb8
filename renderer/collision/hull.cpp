// Convex hulls through Qhull's reentrant C library, and k-DOP style polyhedra by clipping.
#include "renderer/collision/hull.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <unordered_map>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace penumbra {

namespace {

// Volume and area of the triangles, and every triangle's winding made outward for its plane.
void finish_polyhedron(ConvexPolyhedron& poly) {
  poly.volume = poly.area = 0;
  if (poly.vertices.empty()) return;
  const DVec3 o = poly.vertices[0];
  for (size_t t = 0; t + 2 < poly.triangles.size(); t += 3) {
    const DVec3 a = poly.vertices[poly.triangles[t]] - o, b = poly.vertices[poly.triangles[t + 1]] - o,
                c = poly.vertices[poly.triangles[t + 2]] - o;
    const DVec3 n = cross(b - a, c - a);
    poly.area += 0.5 * length(n);
    poly.volume += dot(a, cross(b, c)) / 6;
  }
}

// Qhull's messages go to a memory stream so that a failure can be reported, not printed.
struct MessageStream {
  char* buffer = nullptr;
  size_t size = 0;
  FILE* file = open_memstream(&buffer, &size);
  ~MessageStream() {
    if (file) std::fclose(file);
    std::free(buffer);
  }
  std::string text() {
    if (!file) return {};
    std::fflush(file);
    std::string s(buffer ? buffer : "", size);
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    return s;
  }
};

// Joins edge-adjacent triangles that lie in one plane (the larger one's plane holds the other's
// corners within 1e-9 of `scale`: slivers have no reliable normal of their own) into faces, and gives each
// face its plane: the area- weighted normal, offset to its farthest vertex or `near` point (input points
// Qhull found on or just inside a facet, which joggling may have left out of the hull), so that every input
// point lies inside every plane.
void merge_coplanar(ConvexPolyhedron& poly, double scale,
                    const std::vector<std::pair<uint32_t, DVec3>>& near) {
  const size_t nt = poly.triangles.size() / 3;
  std::vector<DVec3> n(nt);
  std::vector<double> d(nt), area(nt);
  for (size_t t = 0; t < nt; ++t) {
    const DVec3 a = poly.vertices[poly.triangles[3 * t]];
    const DVec3 c =
        cross(poly.vertices[poly.triangles[3 * t + 1]] - a, poly.vertices[poly.triangles[3 * t + 2]] - a);
    area[t] = 0.5 * length(c);
    n[t] = area[t] > 0 ? c * (0.5 / area[t]) : DVec3{0, 0, 0};
    d[t] = dot(n[t], a);
  }
  std::vector<uint32_t> parent(nt);
  for (uint32_t t = 0; t < nt; ++t) parent[t] = t;
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::unordered_map<uint64_t, uint32_t> edge_owner;
  for (uint32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = poly.triangles[3 * t + size_t(k)], b = poly.triangles[3 * t + size_t((k + 1) % 3)];
      if (a > b) std::swap(a, b);
      auto [it, added] = edge_owner.try_emplace((uint64_t(a) << 32) | b, t);
      if (added) continue;
      // One plane: the better-conditioned (larger) triangle's plane holds the other's corners.
      const uint32_t u = it->second, big = area[u] >= area[t] ? u : t, small = big == u ? t : u;
      bool coplanar = dot(n[big], n[small]) > 0;
      for (int c = 0; c < 3 && coplanar; ++c)
        coplanar = std::abs(dot(n[big], poly.vertices[poly.triangles[3 * small + size_t(c)]]) - d[big]) <=
                   1e-9 * scale;
      if (coplanar) {
        const uint32_t ru = find(u), rt = find(t);
        if (ru != rt) parent[std::max(ru, rt)] = std::min(ru, rt);
      }
    }
  std::unordered_map<uint32_t, uint32_t> face_of_root;
  std::vector<DVec3> sum;
  poly.face_of.assign(nt, 0);
  for (uint32_t t = 0; t < nt; ++t) {
    auto [it, added] = face_of_root.try_emplace(find(t), uint32_t(sum.size()));
    if (added) sum.push_back({0, 0, 0});
    poly.face_of[t] = it->second;
    sum[it->second] = sum[it->second] + n[t] * area[t];
  }
  poly.planes.assign(sum.size(), {});
  std::vector<double> best(sum.size(), -INFINITY);
  for (size_t f = 0; f < sum.size(); ++f) {
    const double l = length(sum[f]);
    poly.planes[f].n = l > 0 ? sum[f] * (1 / l) : DVec3{0, 0, 1};
  }
  for (size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t f = poly.face_of[t];
      best[f] = std::max(best[f], dot(poly.planes[f].n, poly.vertices[poly.triangles[3 * t + size_t(k)]]));
    }
  // Joggling leaves the triangulation over the original points convex only to the joggle's
  // size: a face may cut a neighbouring vertex off. Each face is offset to hold the vertices
  // adjacent to its own.
  {
    std::vector<std::vector<uint32_t>> neighbours(poly.vertices.size());
    for (size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k)
        neighbours[poly.triangles[3 * t + size_t(k)]].push_back(poly.triangles[3 * t + size_t((k + 1) % 3)]);
    std::vector<std::vector<uint32_t>> face_triangles(sum.size());
    for (uint32_t t = 0; t < nt; ++t) face_triangles[poly.face_of[t]].push_back(t);
    std::vector<uint32_t> stamp(poly.vertices.size(), UINT32_MAX);
    for (uint32_t f = 0; f < sum.size(); ++f)
      for (uint32_t t : face_triangles[f])
        for (int k = 0; k < 3; ++k)
          for (uint32_t w : neighbours[poly.triangles[3 * t + size_t(k)]]) {
            if (stamp[w] == f) continue;
            stamp[w] = f;
            best[f] = std::max(best[f], dot(poly.planes[f].n, poly.vertices[w]));
          }
  }
  // A near point may lie outside any face (a rim point is nearest to the cap it lies in but
  // outside the side face across it): each is checked against every face.
  for (const auto& near_point : near) {
    const DVec3 p = near_point.second;
    for (size_t f = 0; f < sum.size(); ++f) best[f] = std::max(best[f], dot(poly.planes[f].n, p));
  }
  for (size_t f = 0; f < sum.size(); ++f) poly.planes[f].d = best[f];
}

// One Qhull run over coords (3 per point) with joggled input ('QJ': every facet a triangle, no
// merging, which stays fast on many coplanar or cospherical points), its triangles taken over
// the original coordinates. Returns Qhull's exit code; on success fills `out`.
int run_qhull(const std::vector<double>& coords, ConvexPolyhedron& out,
              std::vector<std::pair<uint32_t, DVec3>>& near, std::string& message) {
  MessageStream errors;
  std::vector<double> work = coords;  // Qhull joggles its own copy; this one it reads
  qhT qh_qh;
  qhT* qh = &qh_qh;
  qh_zero(qh, errors.file);
  char flags[] = "qhull QJ Qc Qi";  // joggle; keep coplanar and near-inside points with their facet
  const int code = qh_new_qhull(qh, 3, int(work.size() / 3), work.data(), False, flags, nullptr,
                                errors.file ? errors.file : stderr);
  if (code == 0) {
    qh_getarea(qh, qh->facet_list);
    out.qhull_volume = qh->totvol;
    std::unordered_map<int, uint32_t> index;  // Qhull point id -> our vertex
    facetT* facet;
    FORALLfacets {
      uint32_t tri[3];
      int k = 0;
      vertexT *vertex, **vertexp;
      FOREACHvertex_(facet->vertices) {
        const int id = qh_pointid(qh, vertex->point);
        auto [it, added] = index.try_emplace(id, uint32_t(out.vertices.size()));
        if (added)
          out.vertices.push_back(
              {coords[3 * size_t(id)], coords[3 * size_t(id) + 1], coords[3 * size_t(id) + 2]});
        if (k < 3) tri[k++] = it->second;
      }
      if (k < 3) continue;
      const DVec3 n{facet->normal[0], facet->normal[1], facet->normal[2]};
      const DVec3 tn =
          cross(out.vertices[tri[1]] - out.vertices[tri[0]], out.vertices[tri[2]] - out.vertices[tri[0]]);
      if (dot(tn, n) < 0) std::swap(tri[1], tri[2]);
      const uint32_t t = uint32_t(out.triangles.size() / 3);
      out.triangles.insert(out.triangles.end(), {tri[0], tri[1], tri[2]});
      if (facet->coplanarset) {
        pointT *point, **pointp;
        FOREACHpoint_(facet->coplanarset) {
          const size_t id = size_t(qh_pointid(qh, point));
          near.push_back({t, {coords[3 * id], coords[3 * id + 1], coords[3 * id + 2]}});
        }
      }
    }
  } else {
    message = errors.text();
  }
  qh_freeqhull(qh, !qh_ALL);
  int still_long = 0, total_long = 0;
  qh_memfreeshort(qh, &still_long, &total_long);
  return code;
}

}  // namespace

ConvexPolyhedron convex_hull(std::span<const DVec3> points, const ConvexHullConfig& config) {
  if (points.empty()) throw std::invalid_argument("convex hull of no points");
  DVec3 lo = points[0], hi = points[0];
  for (const DVec3& p : points) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw std::invalid_argument("convex hull of a non-finite point");
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  std::vector<double> coords;
  coords.reserve(points.size() * 3);
  for (const DVec3& p : points) coords.insert(coords.end(), {p.x, p.y, p.z});
  double diagonal = length(hi - lo);
  if (!(diagonal > 0)) diagonal = 1;
  const double e = config.thickness * diagonal;
  ConvexPolyhedron hull;
  std::vector<std::pair<uint32_t, DVec3>> near;
  std::string message;
  if (points.size() >= 4 && run_qhull(coords, hull, near, message) == 0 && hull.triangles.size() >= 12) {
    merge_coplanar(hull, diagonal, near);
    finish_polyhedron(hull);
    // A slab of width w has volume / area = w / 2: thinner than the thickening is flat (joggling
    // gives flat input a hull of rounding width).
    if (hull.volume >= e * hull.area) return hull;
  }
  // No volume (or Qhull refused the input): hull the points with copies moved along each axis.
  const DVec3 offsets[6] = {{e, 0, 0}, {-e, 0, 0}, {0, e, 0}, {0, -e, 0}, {0, 0, e}, {0, 0, -e}};
  coords.clear();
  coords.reserve(points.size() * 18);
  for (const DVec3& p : points)
    for (const DVec3& o : offsets) coords.insert(coords.end(), {p.x + o.x, p.y + o.y, p.z + o.z});
  hull = {};
  near.clear();
  std::string second;
  if (run_qhull(coords, hull, near, second) != 0)
    throw std::runtime_error("Qhull failed: " + (second.empty() ? message : second));
  hull.thickened = true;
  merge_coplanar(hull, diagonal + 2 * e, near);
  finish_polyhedron(hull);
  return hull;
}

std::vector<uint32_t> convex_hull_2d(std::span<const DVec3> points) {
  if (points.size() < 3) return {};
  std::vector<double> coords;
  coords.reserve(points.size() * 2);
  for (const DVec3& p : points) coords.insert(coords.end(), {p.x, p.y});
  MessageStream errors;
  qhT qh_qh;
  qhT* qh = &qh_qh;
  qh_zero(qh, errors.file);
  char flags[] = "qhull QJ";
  std::vector<uint32_t> corners;
  if (qh_new_qhull(qh, 2, int(points.size()), coords.data(), False, flags, nullptr,
                   errors.file ? errors.file : stderr) == 0) {
    vertexT* vertex;
    FORALLvertices corners.push_back(uint32_t(qh_pointid(qh, vertex->point)));
  }
  qh_freeqhull(qh, !qh_ALL);
  int still_long = 0, total_long = 0;
  qh_memfreeshort(qh, &still_long, &total_long);
  if (corners.size() < 3) return {};
  // A convex polygon's corners in counter-clockwise order: by angle around their centroid.
  double cx = 0, cy = 0;
  for (uint32_t i : corners) cx += points[i].x, cy += points[i].y;
  cx /= double(corners.size());
  cy /= double(corners.size());
  std::vector<std::pair<double, uint32_t>> by_angle;
  for (uint32_t i : corners) by_angle.push_back({std::atan2(points[i].y - cy, points[i].x - cx), i});
  std::sort(by_angle.begin(), by_angle.end());
  for (size_t k = 0; k < by_angle.size(); ++k) corners[k] = by_angle[k].second;
  return corners;
}

ConvexPolyhedron polyhedron_from_planes(std::span<const DPlane> planes, const Bounds3f& box) {
  Polytope poly(box);
  for (const DPlane& p : planes) {
    if (poly.empty()) break;
    poly = poly.clip(p.n, p.d, false);
  }
  ConvexPolyhedron out;
  if (poly.empty()) return out;
  std::vector<uint32_t> tris;
  poly.triangles(tris);
  std::vector<uint32_t> remap(poly.vertices().size(), UINT32_MAX);
  for (uint32_t& v : tris) {
    if (remap[v] == UINT32_MAX) {
      remap[v] = uint32_t(out.vertices.size());
      out.vertices.push_back(poly.vertices()[v]);
    }
    v = remap[v];
  }
  out.triangles = std::move(tris);
  out.planes.assign(planes.begin(), planes.end());
  // Each triangle's face: the plane its normal is closest to.
  for (size_t t = 0; t + 2 < out.triangles.size(); t += 3) {
    const DVec3 a = out.vertices[out.triangles[t]];
    DVec3 n = cross(out.vertices[out.triangles[t + 1]] - a, out.vertices[out.triangles[t + 2]] - a);
    const double len = length(n);
    if (len > 0) n = n * (1 / len);
    uint32_t best = 0;
    double best_dot = -2;
    for (size_t i = 0; i < planes.size(); ++i)
      if (dot(n, planes[i].n) > best_dot) best_dot = dot(n, planes[i].n), best = uint32_t(i);
    out.face_of.push_back(best);
  }
  finish_polyhedron(out);
  return out;
}

void polyhedron_extent(const ConvexPolyhedron& poly, DVec3 n, double& lo, double& hi) {
  lo = INFINITY;
  hi = -INFINITY;
  for (const DVec3& v : poly.vertices) {
    const double s = dot(n, v);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
}

bool polyhedron_contains(const ConvexPolyhedron& poly, DVec3 p, double tolerance) {
  for (const DPlane& pl : poly.planes)
    if (dot(pl.n, p) - pl.d > tolerance) return false;
  return !poly.planes.empty();
}

}  // namespace penumbra
