// The rasteriser: triangle setup (vertex stage, clipping, viewport), binning, tile rasterisation
// into a per-sample z-buffer, Blend layers, and the visibility buffer handed to the shader.
#include "renderer/raster/rasterize.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "renderer/core/dvec3.h"
#include "renderer/materials/material.h"
#include "renderer/raster/clip.h"
#include "renderer/raster/edge.h"

namespace penumbra {

namespace {

/// How a triangle's fragments are tested.
enum class Kind : uint8_t { Opaque, Mask, Blend };

/// A triangle after clipping and the viewport map, in screen space (104 bytes).
struct SetupTriangle {
  int32_t x[3], y[3];  ///< fixed-point raster vertices, ordered so that the area is positive
  float iw[3];         ///< 1 / w of each vertex (perspective-correct interpolation)
  float dw[3];         ///< view depth / w of each vertex
  float bu[3], bv[3];  ///< each vertex's barycentrics (u, v) in the source triangle
  uint32_t instance, prim;
  int32_t px0, py0, px1, py1;  ///< pixels [px0, px1) x [py0, py1) whose samples it may cover
  Kind kind;
  bool disc = false;  ///< a point's or a segment end's square: (bu, bv) are its local coordinates,
                      ///< and only samples with bu^2 + bv^2 <= 1 are covered
};

/// A shape instance, ray-cast over its projected bounds.
struct SetupShape {
  uint32_t instance;
  int32_t px0, py0, px1, py1;
  Kind kind;
  bool cull_back;  ///< single-sided material: back-facing hits are skipped
};

/// The vertex stage's output: every mesh instance's vertices in clip space with their view
/// depth, instance i's at [first[i], first[i] + its mesh's vertex count).
struct Vertices {
  std::vector<uint64_t> first;
  std::vector<Vec4f> clip;
  std::vector<float> depth;
};

/// The fixed parts of a pass: view, planes and window.
struct Pipeline {
  const Scene& scene;
  const RasterView& view;
  const RasterPass& pass;
  ClipPlanes planes;
  PixelWindow win;
};

Kind material_kind(const Material& m, const RasterPass& pass) {
  if (m.alpha_mode == AlphaMode::Mask) return Kind::Mask;
  if (m.alpha_mode == AlphaMode::Blend)
    return pass.blend == RasterBlend::Layers && !pass.depth_only ? Kind::Blend : Kind::Mask;
  return Kind::Opaque;
}

// p in view space (double) from world space.
void to_view(const Transform& v, Vec3f p, double out[3]) {
  for (int r = 0; r < 3; ++r)
    out[r] = v.m[size_t(r)][0] * p.x + v.m[size_t(r)][1] * p.y + v.m[size_t(r)][2] * p.z + v.m[size_t(r)][3];
}

Vec4f to_clip(const Transform& p, const double v[3]) {
  double c[4];
  for (int r = 0; r < 4; ++r)
    c[r] = p.m[size_t(r)][0] * v[0] + p.m[size_t(r)][1] * v[1] + p.m[size_t(r)][2] * v[2] + p.m[size_t(r)][3];
  return {float(c[0]), float(c[1]), float(c[2]), float(c[3])};
}

/// Where the samples of pixel x lie along an axis: in [x + lo, x + hi].
struct SampleSpan {
  double lo = 0, hi = 1;
};

SampleSpan sample_span(const RasterPass& pass) {
  if (!pass.position) return {0.5, 0.5};
  return {-double(pass.margin), 1.0 + double(pass.margin)};
}

// floor(v) for |v| < 2^31, without a library call.
int64_t floor_int(double v) {
  const int64_t i = int64_t(v);
  return i - int64_t(double(i) > v);
}

// The pixels whose samples may reach raster interval [lo, hi] (pixels, widened by the
// snapping's half unit), clamped to [w0, w1).
void pixel_range(double lo, double hi, SampleSpan span, int w0, int w1, int32_t& a, int32_t& b) {
  constexpr double eps = 1.0 / kSubpixelScale;
  lo = std::clamp(lo, -kMaxRasterCoordinate, kMaxRasterCoordinate);  // also NaN-free below
  hi = std::clamp(hi, -kMaxRasterCoordinate, kMaxRasterCoordinate);
  const int64_t l = -floor_int(-(lo - span.hi - eps)), h = floor_int(hi - span.lo + eps) + 1;
  a = int32_t(std::clamp<int64_t>(l, w0, w1));
  b = int32_t(std::clamp<int64_t>(h, w0, w1));
}

/// Screen-space sub-triangle (a, b, c) of a clipped source triangle: viewport map, snapping,
/// culling and bounds. Returns false when it covers no sample.
bool setup_triangle(const Pipeline& pl, const ClipVertex* const v[3], uint32_t instance, uint32_t prim,
                    Kind kind, bool cull, bool mirrored, SetupTriangle& t) {
  const double w = pl.view.width, h = pl.view.height;
  FixedPoint f[3];
  double rx[3], ry[3];
  for (int k = 0; k < 3; ++k) {
    const Vec4f& p = v[k]->p;
    if (!(p.w > 0)) return false;
    const double iw = 1.0 / double(p.w);
    rx[k] = (double(p.x) * iw + 1.0) * 0.5 * w;
    ry[k] = (1.0 - double(p.y) * iw) * 0.5 * h;
    if (!(std::fabs(rx[k]) <= kMaxRasterCoordinate && std::fabs(ry[k]) <= kMaxRasterCoordinate)) return false;
    f[k] = to_fixed(rx[k], ry[k]);
  }
  const int64_t area2 = edge_function(f[0], f[1], f[2]);
  if (area2 == 0) return false;
  // Counter-clockwise in world space seen from the viewer is clockwise in raster (y down) space.
  const bool front = (area2 < 0) != mirrored;
  if (cull && !front) return false;
  int order[3] = {0, 1, 2};
  if (area2 < 0) std::swap(order[1], order[2]);
  for (int k = 0; k < 3; ++k) {
    const ClipVertex& c = *v[order[k]];
    t.x[k] = int32_t(f[order[k]].x);
    t.y[k] = int32_t(f[order[k]].y);
    t.iw[k] = 1.0f / c.p.w;
    t.dw[k] = c.depth / c.p.w;
    t.bu[k] = c.b[1];
    t.bv[k] = c.b[2];
  }
  t.instance = instance;
  t.prim = prim;
  t.kind = kind;
  const PixelWindow& win = pl.win;
  pixel_range(std::min({rx[0], rx[1], rx[2]}), std::max({rx[0], rx[1], rx[2]}), sample_span(pl.pass), win.x0,
              win.x1, t.px0, t.px1);
  pixel_range(std::min({ry[0], ry[1], ry[2]}), std::max({ry[0], ry[1], ry[2]}), sample_span(pl.pass), win.y0,
              win.y1, t.py0, t.py1);
  return t.px0 < t.px1 && t.py0 < t.py1;
}

/// The fan of screen-space triangles of a source triangle that needs clipping (kept apart from
/// the common path, whose stack then holds no clipped polygon).
void setup_clipped(const Pipeline& pl, const ClipVertex cv[3], uint32_t instance, uint32_t prim, Kind kind,
                   bool cull, bool mirrored, std::vector<SetupTriangle>& out) {
  ClipVertex poly[kMaxClipVertices];
  const int n = clip_triangle(cv, pl.planes, poly);
  for (int i = 1; i + 1 < n; ++i) {
    const ClipVertex* tri[3] = {&poly[0], &poly[i], &poly[i + 1]};
    SetupTriangle t;
    if (setup_triangle(pl, tri, instance, prim, kind, cull, mirrored, t)) out.push_back(t);
  }
}

/// Triangles each element of a rendered point or line set is drawn with: a point's square (its
/// disc cut out per sample); a segment's quad and a square at each end; 1 for a triangle
/// mesh's triangles.
uint32_t pieces_per_element(const Mesh& mesh) {
  if (!renders_as_curves(mesh)) return 1;
  return mesh.points ? 2 : 6;
}

/// `a` normalised, or `fallback` when it has (almost) no length.
DVec3 unit_or(DVec3 a, DVec3 fallback) {
  const double n = length(a);
  return n > 1e-12 ? a * (1 / n) : fallback;
}

/// Triangle `piece` (0 or 1) of the quad with corners q[0..3] (counter-clockwise), with each
/// corner's local coordinates `local` (the disc test's; zero for a segment's body).
void quad_piece(const DVec3 q[4], const float local[4][2], uint32_t piece, DVec3 out[3],
                float out_local[3][2]) {
  const int k[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (int v = 0; v < 3; ++v) {
    out[v] = q[k[piece][v]];
    out_local[v][0] = local[k[piece][v]][0];
    out_local[v][1] = local[k[piece][v]][1];
  }
}

/// Triangle `piece` of element `prim` of a rendered point or line set, as clip-space vertices,
/// drawn facing the viewer along the silhouette of the sphere or capsule (so that raster and ray
/// tracing cover the same samples): a point as the square about its silhouette's disc,
/// with the square's local coordinates (corners at (+-1, +-1)) in the vertices' barycentrics so
/// that the fragment stage keeps the samples inside the disc (returns true); a segment as a quad
/// as wide as its capsule between its ends (false) and such a disc at each end (true): the
/// capsule's round caps and joints.
bool curve_piece(const Pipeline& pl, const Instance& inst, const Mesh& mesh, uint32_t prim, uint32_t piece,
                 ClipVertex cv[3]) {
  const uint32_t ia = mesh.indices[3 * size_t(prim)], ib = mesh.indices[3 * size_t(prim) + 1];
  const Transform mv = pl.view.view * to_transform(inst.to_world);
  const double scale =
      inst.identity ? 1.0 : std::cbrt(std::fabs(determinant3x3(to_transform(inst.to_world))));
  auto view_point = [&](Vec3f p) {
    const auto& m = mv.m;
    return DVec3{m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
                 m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
                 m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
  };
  const DVec3 a = view_point(mesh.positions[ia]), b = view_point(mesh.positions[mesh.points ? ia : ib]);
  const double r = (mesh.points ? mesh.radii[ia] : 0.5 * (double(mesh.radii[ia]) + mesh.radii[ib])) * scale;
  const bool ortho = pl.view.projection.m[3][3] != 0;
  DVec3 corner[3];
  float local[3][2];
  const bool disc = mesh.points || piece >= 2;
  if (disc) {
    // The sphere's silhouette: the circle where the cone from the eye touches it, r^2 / d in
    // front of the centre with radius r sqrt(1 - r^2 / d^2) (the centre's plane and r seen
    // orthographically).
    const DVec3 c = !mesh.points && piece >= 4 ? b : a;
    const double d = ortho ? kInfinity : length(c);
    const DVec3 e = ortho ? DVec3{0, 0, 1} : unit_or(c * -1, DVec3{0, 0, 1});
    const double k = ortho || !(d > r) ? 0.0 : r / d;
    const DVec3 s = unit_or(cross(e, DVec3{0, 1, 0}), unit_or(cross(e, DVec3{1, 0, 0}), DVec3{1, 0, 0})) *
                    (r * std::sqrt(1 - k * k));
    const DVec3 t = cross(e, s), f = c + e * (r * k);
    const DVec3 q[4] = {f - s - t, f + s - t, f + s + t, f - s + t};
    const float lq[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    quad_piece(q, lq, piece % 2, corner, local);
  } else {
    // The cylinder's silhouette seen from the eye at distance d from the axis: the plane through
    // the axis facing the eye, r d / sqrt(d^2 - r^2) to each side.
    const DVec3 axis = unit_or(b - a, DVec3{0, 1, 0}), m = (a + b) * 0.5;
    DVec3 to_eye = ortho ? DVec3{0, 0, 1} : m * -1;
    if (!ortho) {  // the part of m -> eye across the axis
      const double along = to_eye.x * axis.x + to_eye.y * axis.y + to_eye.z * axis.z;
      to_eye = to_eye - axis * along;
    }
    const double d = ortho ? kInfinity : length(to_eye);
    DVec3 side = cross(axis, unit_or(to_eye, DVec3{0, 0, 1}));
    if (!(length(side) > 1e-9)) side = cross(DVec3{0, 0, 1}, DVec3{0, 1, 0});  // the axis along the view
    const double half = ortho || !(d > r) ? r : r * d / std::sqrt(d * d - r * r);
    side = unit_or(side, DVec3{1, 0, 0}) * half;
    const DVec3 q[4] = {a - side, b - side, b + side, a + side};
    const float lq[4][2] = {};
    quad_piece(q, lq, piece, corner, local);
  }
  for (int v = 0; v < 3; ++v) {
    const double p[3] = {corner[v].x, corner[v].y, corner[v].z};
    cv[v] = ClipVertex{};
    cv[v].p = to_clip(pl.view.projection, p);
    cv[v].depth = float(-corner[v].z);
    cv[v].b[1] = local[v][0];
    cv[v].b[2] = local[v][1];
  }
  return disc;
}

/// Clipping and setup of triangle `prim` of mesh instance `instance`, whose vertices the vertex
/// stage transformed (or of piece `prim` % pieces of element `prim` / pieces of a point or
/// line set); appends its screen-space triangles to `out`.
void setup_source_triangle(const Pipeline& pl, const Vertices& vs, uint32_t instance, uint32_t prim,
                           Kind kind, bool cull, std::vector<SetupTriangle>& out, RasterStats& st) {
  const Instance& inst = pl.scene.instances[instance];
  const Mesh& mesh = pl.scene.meshes[size_t(inst.mesh)];
  if (renders_as_curves(mesh)) {
    const uint32_t pieces = pieces_per_element(mesh), element = prim / pieces;
    ClipVertex cv[3];
    const bool disc = curve_piece(pl, inst, mesh, element, prim % pieces, cv);
    const size_t before = out.size();
    setup_clipped(pl, cv, instance, element, kind, false, false, out);
    for (size_t i = before; i < out.size(); ++i) out[i].disc = disc;
    if (out.size() == before) ++st.culled;
    ++st.triangles_in;
    st.triangles_setup += out.size() - before;
    return;
  }
  const uint32_t* index = &pl.scene.meshes[size_t(inst.mesh)].indices[size_t(prim) * 3];
  const uint64_t base = vs.first[instance];
  ClipVertex cv[3];
  unsigned all = ~0u, any = 0;
  for (int k = 0; k < 3; ++k) {
    cv[k].p = vs.clip[base + index[k]];
    cv[k].depth = vs.depth[base + index[k]];
    cv[k].b[k] = 1;
    const unsigned code = clip_outcode(cv[k].p, pl.planes);
    all &= code;
    any |= code;
  }
  ++st.triangles_in;
  if (all) {
    ++st.culled;
    return;
  }
  const size_t before = out.size();
  if (!any) {
    const ClipVertex* tri[3] = {&cv[0], &cv[1], &cv[2]};
    SetupTriangle t;
    if (setup_triangle(pl, tri, instance, prim, kind, cull, inst.mirrored, t)) out.push_back(t);
  } else {
    ++st.clipped;
    setup_clipped(pl, cv, instance, prim, kind, cull, inst.mirrored, out);
  }
  if (out.size() == before) ++st.culled;
  st.triangles_setup += out.size() - before;
}

/// The vertex stage: each mesh instance's vertices by its model-view-projection matrix (made in
/// double, applied in float) and their view depth, in parallel.
Vertices transform_vertices(const Pipeline& pl, tbb::task_arena& arena) {
  const Scene& scene = pl.scene;
  Vertices vs;
  vs.first.assign(scene.instances.size() + 1, 0);
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    vs.first[i + 1] = vs.first[i] + (inst.shape >= 0 ? 0 : scene.meshes[size_t(inst.mesh)].positions.size());
  }
  vs.clip.resize(vs.first.back());
  vs.depth.resize(vs.first.back());
  constexpr size_t kChunk = 16384;
  arena.execute([&] {
    tbb::parallel_for(size_t(0), scene.instances.size(), [&](size_t i) {
      const Instance& inst = scene.instances[i];
      if (inst.shape >= 0) return;
      const Transform model_view = pl.view.view * to_transform(inst.to_world);
      const Transform mvp = pl.view.projection * model_view;
      float m[4][4], d[4];
      for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) m[r][c] = float(mvp.m[size_t(r)][size_t(c)]);
        d[r] = float(-model_view.m[2][size_t(r)]);
      }
      const std::vector<Vec3f>& pos = scene.meshes[size_t(inst.mesh)].positions;
      tbb::parallel_for(size_t(0), pos.size(), kChunk, [&](size_t c0) {
        const size_t c1 = std::min(pos.size(), c0 + kChunk);
        for (size_t k = c0; k < c1; ++k) {
          const Vec3f p = pos[k];
          Vec4f& o = vs.clip[vs.first[i] + k];
          o.x = m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3];
          o.y = m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3];
          o.z = m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3];
          o.w = m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3];
          vs.depth[vs.first[i] + k] = d[0] * p.x + d[1] * p.y + d[2] * p.z + d[3];
        }
      });
    });
  });
  return vs;
}

/// The setup triangles of a pass in batches of consecutive source triangles, each triangle
/// named by a 32-bit id: its batch in the high bits, its place in the batch in the low `shift`
/// bits. Ids grow with submission order (instance, then triangle), the z-buffer's tie order;
/// shapes take the ids from end_id() on.
struct SetupTriangles {
  std::vector<std::vector<SetupTriangle>> batches;
  int shift = 16;
  const SetupTriangle& operator[](uint32_t id) const {
    return batches[id >> shift][id & ((uint32_t(1) << shift) - 1)];
  }
  uint32_t end_id() const { return uint32_t(batches.size()) << shift; }
  bool is_triangle(uint32_t id) const { return id < end_id(); }
};

/// Every mesh instance's triangles set up in parallel batches, in submission order.
SetupTriangles setup_triangles(const Pipeline& pl, tbb::task_arena& arena, RasterStats& st) {
  const Scene& scene = pl.scene;
  const Vertices vs = transform_vertices(pl, arena);
  // Global triangle numbering over the mesh instances, cut into batches of `batch`.
  std::vector<uint32_t> mesh_instances;
  std::vector<uint64_t> first;  // first global triangle of each mesh instance
  uint64_t total = 0;
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.shape >= 0) continue;
    const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
    if ((mesh.points || mesh.lines) && !renders_as_curves(mesh)) continue;  // for spatial queries only
    mesh_instances.push_back(uint32_t(i));
    first.push_back(total);
    total += mesh.indices.size() / 3 * pieces_per_element(mesh);
  }
  // A batch of n source triangles makes at most 7 n setup triangles (a clipped polygon has at
  // most 9 vertices); the ids of every batch and of the shapes fit 32 bits.
  SetupTriangles out;
  uint64_t batch = 8192;
  out.shift = 16;
  while ((((total + batch - 1) / batch + 1) << out.shift) > (uint64_t(1) << 32) - scene.instances.size()) {
    batch *= 2;
    ++out.shift;
  }
  const size_t batches = size_t((total + batch - 1) / batch);
  out.batches.resize(batches);
  std::vector<RasterStats> part_stats(batches);
  arena.execute([&] {
    tbb::parallel_for(size_t(0), batches, [&](size_t b) {
      const uint64_t g0 = b * batch, g1 = std::min(total, g0 + batch);
      size_t k = size_t(std::upper_bound(first.begin(), first.end(), g0) - first.begin()) - 1;
      std::vector<SetupTriangle>& part = out.batches[b];
      part.reserve(size_t(g1 - g0));
      for (uint64_t g = g0; g < g1;) {
        while (k + 1 < first.size() && first[k + 1] <= g) ++k;
        const uint32_t instance = mesh_instances[k];
        const Instance& inst = scene.instances[instance];
        const Material& m = material_of(scene, scene.meshes[size_t(inst.mesh)].material);
        const Kind kind = material_kind(m, pl.pass);
        const bool cull = pl.pass.cull_back_faces && !m.double_sided;
        const uint64_t end = std::min(g1, k + 1 < first.size() ? first[k + 1] : total);
        for (; g < end; ++g)
          setup_source_triangle(pl, vs, instance, uint32_t(g - first[k]), kind, cull, part, part_stats[b]);
      }
    });
  });
  for (const RasterStats& p : part_stats) {
    st.triangles_in += p.triangles_in;
    st.triangles_setup += p.triangles_setup;
    st.clipped += p.clipped;
    st.culled += p.culled;
  }
  return out;
}

/// Each shape instance with the pixels its world bounds project to (the whole window when
/// the bounds reach behind the near plane).
std::vector<SetupShape> setup_shapes(const Pipeline& pl, RasterStats& st) {
  std::vector<SetupShape> out;
  const Scene& scene = pl.scene;
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.shape < 0) continue;
    const SceneShape& ss = scene.shapes[size_t(inst.shape)];
    Bounds3f b = shape_bounds(ss.shape);
    if (b.empty()) continue;
    if (!inst.identity) b = transform_bounds(inst.to_world, b);
    const Material& m = material_of(scene, ss.material);
    SetupShape s;
    s.instance = uint32_t(i);
    s.kind = material_kind(m, pl.pass);
    s.cull_back = pl.pass.cull_back_faces && !m.double_sided;
    // A Mask (or thresholded Blend) shape is covered everywhere or nowhere.
    if (s.kind == Kind::Mask) {
      const float a = eval_alpha(scene, uint32_t(i), 0, 0, 0);
      if (!(a >= (m.alpha_mode == AlphaMode::Mask ? 1.0f : 0.5f))) continue;
      s.kind = Kind::Opaque;
    }
    double lo[2] = {kInfinity, kInfinity}, hi[2] = {-kInfinity, -kInfinity};
    bool behind = false;
    for (int c = 0; c < 8; ++c) {
      const Vec3f p{(c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z};
      double v[3];
      to_view(pl.view.view, p, v);
      const Vec4f q = to_clip(pl.view.projection, v);
      if (!(q.w > 0) || (clip_outcode(q, pl.planes) & 1u)) {
        behind = true;
        break;
      }
      const double rx = (double(q.x) / q.w + 1.0) * 0.5 * pl.view.width;
      const double ry = (1.0 - double(q.y) / q.w) * 0.5 * pl.view.height;
      lo[0] = std::min(lo[0], rx), hi[0] = std::max(hi[0], rx);
      lo[1] = std::min(lo[1], ry), hi[1] = std::max(hi[1], ry);
    }
    if (behind) {
      s.px0 = pl.win.x0, s.px1 = pl.win.x1, s.py0 = pl.win.y0, s.py1 = pl.win.y1;
    } else {
      pixel_range(lo[0], hi[0], sample_span(pl.pass), pl.win.x0, pl.win.x1, s.px0, s.px1);
      pixel_range(lo[1], hi[1], sample_span(pl.pass), pl.win.y0, pl.win.y1, s.py0, s.py1);
    }
    if (s.px0 < s.px1 && s.py0 < s.py1) out.push_back(s);
  }
  st.shapes = out.size();
  return out;
}

/// Triangle indices per tile (compressed rows: tile t holds refs[begin[t] .. begin[t + 1])).
struct Bins {
  int tiles_x = 0, tiles_y = 0;
  std::vector<uint64_t> begin;
  std::vector<uint32_t> refs;
};

Bins bin_triangles(const SetupTriangles& tris, const PixelWindow& win, int ts) {
  Bins bins;
  bins.tiles_x = (win.width() + ts - 1) / ts;
  bins.tiles_y = (win.height() + ts - 1) / ts;
  const size_t ntiles = size_t(bins.tiles_x) * size_t(bins.tiles_y);
  bins.begin.assign(ntiles + 1, 0);
  auto for_tiles = [&](const SetupTriangle& t, auto&& fn) {
    const int tx0 = (t.px0 - win.x0) / ts, tx1 = (t.px1 - 1 - win.x0) / ts;
    const int ty0 = (t.py0 - win.y0) / ts, ty1 = (t.py1 - 1 - win.y0) / ts;
    for (int ty = ty0; ty <= ty1; ++ty)
      for (int tx = tx0; tx <= tx1; ++tx) fn(size_t(ty) * size_t(bins.tiles_x) + size_t(tx));
  };
  for (const auto& part : tris.batches)
    for (const SetupTriangle& t : part) for_tiles(t, [&](size_t k) { ++bins.begin[k + 1]; });
  for (size_t k = 0; k < ntiles; ++k) bins.begin[k + 1] += bins.begin[k];
  bins.refs.resize(bins.begin[ntiles]);
  std::vector<uint64_t> fill(bins.begin.begin(), bins.begin.end() - 1);
  for (size_t b = 0; b < tris.batches.size(); ++b)
    for (size_t i = 0; i < tris.batches[b].size(); ++i) {
      const uint32_t id = uint32_t(b << tris.shift | i);
      for_tiles(tris.batches[b][i], [&](size_t k) { bins.refs[fill[k]++] = id; });
    }
  return bins;
}

/// A covered sample before resolution: its z-buffer key and the sub-triangle's linear
/// barycentrics of vertices 1 and 2 (shapes: the ray parameter in l1).
struct Candidate {
  uint32_t sample;
  float depth;
  uint32_t id;  ///< submission index: a setup triangle, or triangles + shape index
  float l1, l2;
};

bool closer(float da, uint32_t ia, float db, uint32_t ib) {
  return da < db || (da == db && ia < ib);
}

/// One thread's tile buffers, reused from tile to tile.
struct TileBuffers {
  std::vector<Vec2f> positions;
  std::vector<FixedPoint> fixed;
  std::vector<float> depth;
  std::vector<uint32_t> id;
  std::vector<float> l1, l2;
  std::vector<Candidate> blend;
  std::vector<RasterFragment> opaque, layers;
  std::vector<uint32_t> layer_begin;
  std::vector<float> block_max;  ///< per kBlock x kBlock pixels: a bound on its samples' depths
};

constexpr uint32_t kNone = 0xffffffffu;
/// Pixels on a side of the blocks of hierarchical z and edge rejection.
constexpr int kBlock = 8;

/// Perspective-correct source barycentrics (u, v) of triangle t at linear barycentrics
/// (1 - l1 - l2, l1, l2).
Vec2f source_uv(const SetupTriangle& t, double l1, double l2) {
  const double l0 = 1.0 - l1 - l2;
  const double s = l0 * t.iw[0] + l1 * t.iw[1] + l2 * t.iw[2];
  const double u = (l0 * t.iw[0] * t.bu[0] + l1 * t.iw[1] * t.bu[1] + l2 * t.iw[2] * t.bu[2]) / s;
  const double v = (l0 * t.iw[0] * t.bv[0] + l1 * t.iw[1] * t.bv[1] + l2 * t.iw[2] * t.bv[2]) / s;
  return {float(u), float(v)};
}

/// The screen gradients (per pixel in x and y) of a setup triangle's linear barycentrics.
struct Gradients {
  double dl[3][2];
};

Gradients gradients(const SetupTriangle& t) {
  const EdgeTriangle e = make_edge_triangle({t.x[0], t.y[0]}, {t.x[1], t.y[1]}, {t.x[2], t.y[2]});
  const double inv_area = kSubpixelScale / double(e.area2);
  Gradients g;
  for (int k = 0; k < 3; ++k)
    g.dl[k][0] = double(e.edge[k].a) * inv_area, g.dl[k][1] = double(e.edge[k].b) * inv_area;
  return g;
}

/// The fragment of setup triangle t at linear barycentrics (l1, l2): source barycentrics and
/// their derivatives per pixel (the quotient rule on the perspective-correct ratio, with the
/// linear barycentrics' constant screen gradients g).
RasterFragment triangle_fragment(const SetupTriangle& t, const Gradients& g, float depth, double l1,
                                 double l2) {
  RasterFragment f;
  f.depth = depth;
  f.hit.geom_id = t.instance;
  f.hit.prim_id = t.prim;
  const double l[3] = {1.0 - l1 - l2, l1, l2};
  double s = 0, nu = 0, nv = 0, ds[2] = {0, 0}, dnu[2] = {0, 0}, dnv[2] = {0, 0};
  for (int k = 0; k < 3; ++k) {
    const double iw = t.iw[k], iu = iw * t.bu[k], iv = iw * t.bv[k];
    s += l[k] * iw;
    nu += l[k] * iu;
    nv += l[k] * iv;
    for (int a = 0; a < 2; ++a) {
      ds[a] += g.dl[k][a] * iw;
      dnu[a] += g.dl[k][a] * iu;
      dnv[a] += g.dl[k][a] * iv;
    }
  }
  const double inv_s = 1.0 / s, inv_s2 = inv_s * inv_s;
  f.hit.u = float(nu * inv_s);
  f.hit.v = float(nv * inv_s);
  f.duv_dx = {float((dnu[0] * s - nu * ds[0]) * inv_s2), float((dnv[0] * s - nv * ds[0]) * inv_s2)};
  f.duv_dy = {float((dnu[1] * s - nu * ds[1]) * inv_s2), float((dnv[1] * s - nv * ds[1]) * inv_s2)};
  return f;
}

/// The nearest hit of `shape` along object-space ray `ray`; with `cull_back`, the nearest seen
/// from outside (n . d <= 0: the sign is the same in object and world space, as normals map by
/// the inverse transpose), stepping past back-facing hits a bounded number of times.
bool front_hit(const Shape& shape, const Ray& ray, bool cull_back, ShapeHit& hit) {
  Ray r = ray;
  for (int i = 0; i < 64; ++i) {
    if (!intersect_shape(shape, r, hit)) return false;
    if (!cull_back || dot(shape_surface(shape, r.org + r.dir * hit.t, 1e-4f).n, r.dir) <= 0) return true;
    r.tnear = std::nextafter(std::max(hit.t, r.tnear), kInfinity);
  }
  return false;
}

/// Rasterises one tile: z-buffer of opaque and alpha-tested fragments, Blend candidates, then
/// the resolved visibility buffer.
class TileRasterizer {
 public:
  TileRasterizer(const Pipeline& pl, const SetupTriangles& tris, const std::vector<SetupShape>& shapes,
                 const Bins& bins)
      : m_pl(pl), m_tris(tris), m_shapes(shapes), m_bins(bins) {}

  void run(const PixelWindow& tile, TileBuffers& b,
           const std::function<void(const RasterTile&)>& shade) const {
    const int spp = m_pl.pass.spp;
    const size_t n = size_t(tile.width()) * size_t(tile.height()) * size_t(spp);
    init_samples(tile, b, n);
    const int ts = m_pl.pass.tile_size;
    const size_t k =
        size_t((tile.y0 - m_pl.win.y0) / ts) * size_t(m_bins.tiles_x) + size_t((tile.x0 - m_pl.win.x0) / ts);
    for (uint64_t r = m_bins.begin[k]; r < m_bins.begin[k + 1]; ++r) raster_triangle(tile, m_bins.refs[r], b);
    for (size_t s = 0; s < m_shapes.size(); ++s) raster_shape(tile, s, b);
    resolve(tile, b, n);
    RasterTile out;
    out.pixels = tile;
    out.spp = spp;
    out.positions = b.positions.data();
    out.opaque = b.opaque.data();
    out.blend_begin = b.layer_begin.data();
    out.blend = b.layers.data();
    shade(out);
  }

 private:
  void init_samples(const PixelWindow& tile, TileBuffers& b, size_t n) const {
    const RasterPass& pass = m_pl.pass;
    b.positions.resize(n);
    b.fixed.resize(n);
    b.depth.assign(n, kInfinity);
    b.id.assign(n, kNone);
    b.l1.resize(n);
    b.l2.resize(n);
    b.blend.clear();
    b.block_max.assign(
        size_t((tile.width() + kBlock - 1) / kBlock) * size_t((tile.height() + kBlock - 1) / kBlock),
        kInfinity);
    size_t i = 0;
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x)
        for (uint32_t s = 0; s < uint32_t(pass.spp); ++s, ++i) {
          const Vec2f p = pass.position ? pass.position(pass.position_context, x, y, s)
                                        : Vec2f{float(x) + 0.5f, float(y) + 0.5f};
          b.positions[i] = p;
          b.fixed[i] = to_fixed(std::clamp(double(p.x), -kMaxRasterCoordinate, kMaxRasterCoordinate),
                                std::clamp(double(p.y), -kMaxRasterCoordinate, kMaxRasterCoordinate));
        }
  }

  // The depth test and the fragment stage for one covered sample; true if it was written to
  // the z-buffer (a Blend fragment is kept aside instead).
  bool fragment(size_t i, float depth, uint32_t id, float l1, float l2, Kind kind, TileBuffers& b) const {
    if (!closer(depth, id, b.depth[i], b.id[i])) return false;
    if (kind == Kind::Blend) {
      b.blend.push_back({uint32_t(i), depth, id, l1, l2});
      return false;
    }
    b.depth[i] = depth;
    b.id[i] = id;
    b.l1[i] = l1;
    b.l2[i] = l2;
    return true;
  }

  // One triangle over the tile, block by block: a block is skipped when the triangle lies
  // behind every sample in it (hierarchical z: the block's bound on its samples' depth) or
  // wholly outside one of its edges; a triangle that writes every sample of a block lowers its
  // bound (Greene, Kass and Miller, "Hierarchical Z-Buffer Visibility", SIGGRAPH 1993). Both
  // tests are conservative: the buffer is the one a plain loop gives.
  void raster_triangle(const PixelWindow& tile, uint32_t index, TileBuffers& b) const {
    const SetupTriangle& t = m_tris[index];
    const EdgeTriangle e = make_edge_triangle({t.x[0], t.y[0]}, {t.x[1], t.y[1]}, {t.x[2], t.y[2]});
    const int x0 = std::max(t.px0, tile.x0), x1 = std::min(t.px1, tile.x1);
    const int y0 = std::max(t.py0, tile.y0), y1 = std::min(t.py1, tile.y1);
    float zmin = kInfinity, zmax = 0;
    for (int k = 0; k < 3; ++k) {
      const float z = t.dw[k] / t.iw[k];
      zmin = std::min(zmin, z);
      zmax = std::max(zmax, z);
    }
    zmin *= 1 - 1e-5f;  // the fragments' depths carry rounding
    zmax *= 1 + 1e-5f;
    const int bw = (tile.width() + kBlock - 1) / kBlock;
    for (int by = (y0 - tile.y0) / kBlock; by * kBlock + tile.y0 < y1; ++by)
      for (int bx = (x0 - tile.x0) / kBlock; bx * kBlock + tile.x0 < x1; ++bx) {
        float& bound = b.block_max[size_t(by) * size_t(bw) + size_t(bx)];
        if (zmin > bound) continue;
        PixelWindow blk{tile.x0 + bx * kBlock, tile.y0 + by * kBlock, 0, 0};
        blk.x1 = std::min(blk.x0 + kBlock, tile.x1);
        blk.y1 = std::min(blk.y0 + kBlock, tile.y1);
        const PixelWindow r{std::max(blk.x0, x0), std::max(blk.y0, y0), std::min(blk.x1, x1),
                            std::min(blk.y1, y1)};
        if (outside_an_edge(e, r)) continue;
        const int written = raster_block(t, e, index, tile, r, b);
        if (t.kind == Kind::Opaque && written == blk.width() * blk.height() * m_pl.pass.spp)
          bound = std::min(bound, zmax);
      }
  }

  // Whether every sample the pixels of r may hold lies outside one of e's edges.
  bool outside_an_edge(const EdgeTriangle& e, const PixelWindow& r) const {
    const SampleSpan span = sample_span(m_pl.pass);
    const int64_t xs[2] = {int64_t(std::floor((r.x0 + span.lo) * kSubpixelScale)),
                           int64_t(std::ceil((r.x1 - 1 + span.hi) * kSubpixelScale))};
    const int64_t ys[2] = {int64_t(std::floor((r.y0 + span.lo) * kSubpixelScale)),
                           int64_t(std::ceil((r.y1 - 1 + span.hi) * kSubpixelScale))};
    for (const EdgeEquation& q : e.edge)
      if (q.c + q.a * xs[q.a > 0] + q.b * ys[q.b > 0] < q.threshold) return true;
    return false;
  }

  // The samples of the pixels of r that t covers through the depth test and the fragment
  // stage; returns how many were written to the z-buffer.
  int raster_block(const SetupTriangle& t, const EdgeTriangle& e, uint32_t index, const PixelWindow& tile,
                   const PixelWindow& r, TileBuffers& b) const {
    const double inv_area = 1.0 / double(e.area2);
    const int spp = m_pl.pass.spp;
    const float mask_cut = m_pl.pass.blend == RasterBlend::Threshold || m_pl.pass.depth_only ? 0.5f : 1.0f;
    int written = 0;
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) {
        const size_t base = (size_t(y - tile.y0) * size_t(tile.width()) + size_t(x - tile.x0)) * size_t(spp);
        for (int s = 0; s < spp; ++s) {
          const size_t i = base + size_t(s);
          int64_t ev[3];
          if (!edge_inside(e, b.fixed[i], ev)) continue;
          const double l1 = double(ev[1]) * inv_area, l2 = double(ev[2]) * inv_area, l0 = 1.0 - l1 - l2;
          const double sw = l0 * t.iw[0] + l1 * t.iw[1] + l2 * t.iw[2];
          const float depth = float((l0 * t.dw[0] + l1 * t.dw[1] + l2 * t.dw[2]) / sw);
          if (!closer(depth, index, b.depth[i], b.id[i])) continue;
          if (t.disc) {  // the disc in its square, in the square's plane (perspective-correct)
            const double u = (l0 * t.iw[0] * t.bu[0] + l1 * t.iw[1] * t.bu[1] + l2 * t.iw[2] * t.bu[2]) / sw;
            const double v = (l0 * t.iw[0] * t.bv[0] + l1 * t.iw[1] * t.bv[1] + l2 * t.iw[2] * t.bv[2]) / sw;
            if (u * u + v * v > 1) continue;
          }
          if (t.kind == Kind::Mask) {
            const Vec2f uv = t.disc ? source_uv(t, 0, 0) : source_uv(t, l1, l2);
            const Material& m =
                material_of(m_pl.scene, instance_material(m_pl.scene, m_pl.scene.instances[t.instance]));
            const float cut = m.alpha_mode == AlphaMode::Mask ? 1.0f : mask_cut;
            if (!(eval_alpha(m_pl.scene, t.instance, t.prim, uv.x, uv.y) >= cut)) continue;
          }
          written += t.disc ? fragment(i, depth, index, 0, 0, t.kind, b)
                            : fragment(i, depth, index, float(l1), float(l2), t.kind, b);
        }
      }
    return written;
  }

  void raster_shape(const PixelWindow& tile, size_t index, TileBuffers& b) const {
    const SetupShape& sh = m_shapes[index];
    const int x0 = std::max(sh.px0, tile.x0), x1 = std::min(sh.px1, tile.x1);
    const int y0 = std::max(sh.py0, tile.y0), y1 = std::min(sh.py1, tile.y1);
    if (x0 >= x1 || y0 >= y1) return;
    const Scene& scene = m_pl.scene;
    const Instance& inst = scene.instances[sh.instance];
    const Shape& shape = scene.shapes[size_t(inst.shape)].shape;
    const uint32_t id = m_tris.end_id() + uint32_t(index);
    const int spp = m_pl.pass.spp;
    const auto& vrow = m_pl.view.view.m[2];
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const size_t base = (size_t(y - tile.y0) * size_t(tile.width()) + size_t(x - tile.x0)) * size_t(spp);
        for (int s = 0; s < spp; ++s) {
          const size_t i = base + size_t(s);
          const Vec2f p = b.positions[i];
          const Ray world = m_pl.view.ray(m_pl.view.ray_context, p.x, p.y);
          Ray obj = world;
          if (!inst.identity) {
            obj.org = apply_point(inst.to_object, world.org);
            obj.dir = apply_vector(inst.to_object, world.dir);
          }
          ShapeHit hit;
          if (!front_hit(shape, obj, sh.cull_back, hit)) continue;
          const Vec3f q = world.org + world.dir * hit.t;
          const float depth = float(-(vrow[0] * q.x + vrow[1] * q.y + vrow[2] * q.z + vrow[3]));
          fragment(i, depth, id, hit.t, 0, sh.kind, b);
        }
      }
  }

  // The fragment of submission `id`; `cache` holds the gradients of the last triangle resolved.
  RasterFragment make_fragment(uint32_t id, float depth, float l1, float l2,
                               std::pair<uint32_t, Gradients>& cache) const {
    if (m_tris.is_triangle(id)) {
      if (cache.first != id) cache = {id, gradients(m_tris[id])};
      return triangle_fragment(m_tris[id], cache.second, depth, l1, l2);
    }
    RasterFragment f;
    f.depth = depth;
    f.hit.geom_id = m_shapes[id - m_tris.end_id()].instance;
    f.hit.prim_id = 0;
    f.hit.t = l1;
    return f;
  }

  void resolve(const PixelWindow& tile, TileBuffers& b, size_t n) const {
    (void)tile;
    b.opaque.resize(n);
    std::pair<uint32_t, Gradients> cache{kNone, {}};
    if (m_pl.pass.depth_only) {
      for (size_t i = 0; i < n; ++i) {
        b.opaque[i] = RasterFragment{};
        if (b.id[i] == kNone) continue;
        b.opaque[i].depth = b.depth[i];
        b.opaque[i].hit.geom_id = m_tris.is_triangle(b.id[i]) ? m_tris[b.id[i]].instance
                                                              : m_shapes[b.id[i] - m_tris.end_id()].instance;
      }
      b.layer_begin.assign(n + 1, 0);
      return;
    }
    for (size_t i = 0; i < n; ++i)
      b.opaque[i] =
          b.id[i] == kNone ? RasterFragment{} : make_fragment(b.id[i], b.depth[i], b.l1[i], b.l2[i], cache);
    // Blend layers in front of each sample's opaque fragment, front to back; past the layer
    // limit the next one stands for the opaque surface.
    auto& c = b.blend;
    c.erase(std::remove_if(c.begin(), c.end(),
                           [&](const Candidate& k) {
                             return !closer(k.depth, k.id, b.depth[k.sample], b.id[k.sample]);
                           }),
            c.end());
    std::sort(c.begin(), c.end(), [](const Candidate& a, const Candidate& z) {
      return a.sample != z.sample ? a.sample < z.sample : closer(a.depth, a.id, z.depth, z.id);
    });
    b.layers.clear();
    b.layer_begin.assign(n + 1, 0);
    const size_t limit = size_t(std::max(0, m_pl.pass.max_blend_layers));
    for (size_t k = 0; k < c.size();) {
      const uint32_t s = c[k].sample;
      size_t e = k, kept = 0;
      while (e < c.size() && c[e].sample == s) ++e;
      for (size_t j = k; j < e; ++j) {
        if (kept == limit) {
          b.opaque[s] = make_fragment(c[j].id, c[j].depth, c[j].l1, c[j].l2, cache);
          break;
        }
        b.layers.push_back(make_fragment(c[j].id, c[j].depth, c[j].l1, c[j].l2, cache));
        ++kept;
      }
      b.layer_begin[s + 1] = uint32_t(kept);
      k = e;
    }
    for (size_t i = 0; i < n; ++i) b.layer_begin[i + 1] += b.layer_begin[i];
  }

  const Pipeline& m_pl;
  const SetupTriangles& m_tris;
  const std::vector<SetupShape>& m_shapes;
  const Bins& m_bins;
};

/// Guard band (in viewport half-extents) that holds every sample, with a pixel to spare.
float guard_band(const RasterView& view, const RasterPass& pass) {
  const float dim = float(std::max(1, std::min(view.width, view.height)));
  return std::max(2.0f, 1.0f + 2.0f * (pass.margin + 2.0f) / dim);
}

}  // namespace

uint64_t raster_memory_bytes(const Scene& scene, const RasterPass& pass) {
  uint64_t tris = count_triangles(scene);
  for (const Instance& inst : scene.instances)
    if (inst.shape < 0 && renders_as_curves(scene.meshes[size_t(inst.mesh)]))
      tris += scene.meshes[size_t(inst.mesh)].indices.size() / 3 *
              pieces_per_element(scene.meshes[size_t(inst.mesh)]);
  const uint64_t samples =
      uint64_t(pass.tile_size) * uint64_t(pass.tile_size) * uint64_t(std::max(1, pass.spp));
  const uint64_t per_sample = sizeof(Vec2f) + sizeof(FixedPoint) + 16 + sizeof(RasterFragment) + 4;
  // Setup triangles (clipping adds a few), their references (a handful of tiles each) and
  // the batches being concatenated.
  return tris * (2 * sizeof(SetupTriangle) + 4 * sizeof(uint32_t) + sizeof(Vec4f) + sizeof(float)) +
         uint64_t(thread_count(pass.threads)) * samples * per_sample;
}

void rasterize(const Scene& scene, const RasterView& view, const RasterPass& pass,
               const std::function<void(const RasterTile& tile)>& shade, RasterStats* stats) {
  Pipeline pl{scene, view, pass, ClipPlanes{view.far_plane, guard_band(view, pass)}, pass.window};
  RasterStats st;
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  auto t0 = Clock::now();
  tbb::task_arena arena(thread_count(pass.threads));
  const SetupTriangles tris = setup_triangles(pl, arena, st);
  const std::vector<SetupShape> shapes = setup_shapes(pl, st);
  st.setup_seconds = since(t0);
  t0 = Clock::now();
  const Bins bins = bin_triangles(tris, pl.win, pass.tile_size);
  st.bin_references = bins.refs.size();
  st.bin_seconds = since(t0);
  t0 = Clock::now();
  const TileRasterizer raster(pl, tris, shapes, bins);
  tbb::enumerable_thread_specific<TileBuffers> buffers;
  TileScheduler scheduler(pl.win, pass.tile_size, pass.threads);
  scheduler.for_each_tile([&](const PixelWindow& tile) { raster.run(tile, buffers.local(), shade); });
  st.tile_seconds = since(t0);
  if (stats) *stats = st;
}

}  // namespace penumbra
