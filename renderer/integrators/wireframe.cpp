// The wireframe overlay; see wireframe.h.
#include "renderer/integrators/wireframe.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>

#include "renderer/integrators/visibility.h"

namespace penumbra {

namespace {

/// What the centre ray of each pixel of the window sees.
struct CentreHits {
  PixelWindow win;
  std::vector<Hit> hits;
  std::vector<float> depth;  ///< along the view axis; infinity for a miss
};

/// The camera's projection to raster space and back.
struct Projector {
  Camera cam;
  CameraRaster raster;
  float half_w = 1, half_h = 1;  ///< orthographic half extents
  bool ortho = false;

  float depth(Vec3f p) const { return dot(p - cam.eye, -cam.w); }
  /// Raster position of `p`, whose depth is > 0 (perspective), in double.
  void project(Vec3f p, double out[2]) const {
    const Vec3f q = p - cam.eye;
    double sx, sy;
    if (ortho) {
      sx = double(dot(q, cam.u)) / half_w;
      sy = double(dot(q, cam.v)) / half_h;
    } else {
      const double z = dot(q, -cam.w);
      sx = double(dot(q, cam.u)) / (z * raster.tan_x);
      sy = double(dot(q, cam.v)) / (z * raster.tan_y);
    }
    out[0] = (sx + 1) * 0.5 * raster.width;
    out[1] = (1 - sy) * 0.5 * raster.height;
  }
  float footprint(float depth) const {
    return ortho ? 2 * half_h / raster.height : 2 * std::max(depth, 0.0f) * raster.tan_y / raster.height;
  }
};

CentreHits trace_centres(const Scene& scene, const Accelerator& accel, const Projector& pr, PixelWindow win) {
  const bool filter = scene_needs_hit_filter(scene);  // alpha-masked holes and culled back faces
  CentreHits out;
  out.win = win;
  const size_t n = size_t(win.width()) * size_t(win.height());
  out.hits.resize(n);
  out.depth.assign(n, kInfinity);
  tbb::parallel_for(tbb::blocked_range<int>(win.y0, win.y1), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y)
      for (int x = win.x0; x < win.x1; ++x) {
        Ray ray = raster_ray(pr.cam, pr.raster, float(x) + 0.5f, float(y) + 0.5f);
        ray.time = 0.5f;
        const size_t i = size_t(y - win.y0) * size_t(win.width()) + size_t(x - win.x0);
        Hit hit;
        if (intersect_visible(scene, accel, ray, hit, filter)) {
          out.hits[i] = hit;
          out.depth[i] = pr.depth(ray.org + ray.dir * hit.t);
        }
      }
  });
  return out;
}

/// Raises the float at `slot` to `value` (the largest wins whatever the order: deterministic).
void atomic_max(float& slot, float value) {
  std::atomic_ref<float> ref(slot);
  float old = ref.load(std::memory_order_relaxed);
  while (old < value && !ref.compare_exchange_weak(old, value, std::memory_order_relaxed)) {
  }
}

/// Whether the triangle `prim` of mesh `mesh` has both vertices a and b.
bool has_edge(const Mesh& mesh, uint32_t prim, uint32_t a, uint32_t b) {
  const uint32_t* t = &mesh.indices[3 * size_t(prim)];
  const bool ha = t[0] == a || t[1] == a || t[2] == a, hb = t[0] == b || t[1] == b || t[2] == b;
  return ha && hb;
}

/// Clips the screen segment p0 + s (p1 - p0), s in [s0, s1], to the box [lo, hi] (Liang and
/// Barsky 1984); false when nothing is left.
bool clip_segment(const double p0[2], const double p1[2], const double lo[2], const double hi[2], double& s0,
                  double& s1) {
  for (int k = 0; k < 2; ++k) {
    const double d = p1[k] - p0[k];
    if (d == 0) {
      if (p0[k] < lo[k] || p0[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - p0[k]) / d, tb = (hi[k] - p0[k]) / d;
    if (ta > tb) std::swap(ta, tb);
    s0 = std::max(s0, ta);
    s1 = std::min(s1, tb);
    if (s0 > s1) return false;
  }
  return true;
}

/// One edge a-b (vertex indices of its instance's mesh, world points pa, pb) of `instance`:
/// near-clipped, projected in double, clipped to the window widened by the band, and walked row
/// by row (column by column for steep edges) over the band only.
void draw_edge(const Scene& scene, const Projector& pr, const CentreHits& centres,
               const WireframeConfig& wire, uint32_t instance, uint32_t a, uint32_t b, Vec3f pa, Vec3f pb,
               std::vector<float>& alpha) {
  // Near clipping (perspective): the part in front of a plane just before the eye.
  float za = pr.depth(pa), zb = pr.depth(pb);
  if (!pr.ortho) {
    const float znear = std::max(pr.cam.znear, 1e-6f * std::max({1.0f, std::fabs(za), std::fabs(zb)}));
    if (za < znear && zb < znear) return;
    if (za < znear) pa = pa + (pb - pa) * ((znear - za) / (zb - za)), za = znear;
    if (zb < znear) pb = pb + (pa - pb) * ((znear - zb) / (za - zb)), zb = znear;
  }
  double sa[2], sb[2];
  pr.project(pa, sa);
  pr.project(pb, sb);
  if (!std::isfinite(sa[0] + sa[1] + sb[0] + sb[1])) return;
  const double half = 0.5 * wire.width, reach = half + 1;
  const PixelWindow& win = centres.win;
  const double lo[2] = {win.x0 - reach, win.y0 - reach}, hi[2] = {win.x1 + reach, win.y1 + reach};
  double s0 = 0, s1 = 1;
  if (!clip_segment(sa, sb, lo, hi, s0, s1)) return;
  const double d[2] = {sb[0] - sa[0], sb[1] - sa[1]};
  const double dd = d[0] * d[0] + d[1] * d[1], len = std::sqrt(dd);
  // Walk the major axis k over the clipped part; across it, the band reaches `across` each side.
  const int k = std::fabs(d[0]) >= std::fabs(d[1]) ? 0 : 1, j = 1 - k;
  const double c0[2] = {sa[0] + d[0] * s0, sa[1] + d[1] * s0}, c1[2] = {sa[0] + d[0] * s1, sa[1] + d[1] * s1};
  const double across = std::fabs(d[k]) > 0 ? reach * len / std::fabs(d[k]) : reach;
  const int w0[2] = {win.x0, win.y0}, w1[2] = {win.x1, win.y1};
  const int m0 = std::max(w0[k], int(std::floor(std::min(c0[k], c1[k]) - reach)));
  const int m1 = std::min(w1[k], int(std::ceil(std::max(c0[k], c1[k]) + reach)));
  const double minor_lo = std::min(c0[j], c1[j]) - reach, minor_hi = std::max(c0[j], c1[j]) + reach;
  const Mesh& mesh = scene.meshes[size_t(scene.instances[instance].mesh)];
  for (int m = m0; m < m1; ++m) {
    const double centre = m + 0.5;
    const double at = std::fabs(d[k]) > 0 ? sa[j] + d[j] * (centre - sa[k]) / d[k] : sa[j];
    const int n0 = std::max(w0[j], int(std::floor(std::max(minor_lo, at - across))));
    const int n1 = std::min(w1[j], int(std::ceil(std::min(minor_hi, at + across))));
    for (int n = n0; n < n1; ++n) {
      const int x = k == 0 ? m : n, y = k == 0 ? n : m;
      const double cx = x + 0.5, cy = y + 0.5;
      const double s = dd > 0 ? std::clamp(((cx - sa[0]) * d[0] + (cy - sa[1]) * d[1]) / dd, 0.0, 1.0) : 0.0;
      const double ex = sa[0] + d[0] * s - cx, ey = sa[1] + d[1] * s - cy;
      float cover = float(std::clamp(half + 0.5 - std::sqrt(ex * ex + ey * ey), 0.0, 1.0));
      if (cover <= 0) continue;
      // The edge's depth at s: 1 / depth is linear on screen (perspective).
      const float sf = float(s);
      const float z = pr.ortho ? za + (zb - za) * sf : 1.0f / ((1 - sf) / za + sf / zb);
      const size_t i = size_t(y - win.y0) * size_t(win.width()) + size_t(x - win.x0);
      const Hit& h = centres.hits[i];
      const bool visible = !h.valid() || (h.geom_id == instance && has_edge(mesh, h.prim_id, a, b)) ||
                           z <= centres.depth[i] + 1e-3f * z + 2 * pr.footprint(z) * float(half + 1);
      if (!visible) {
        if (wire.hidden == WireframeHidden::Off) continue;
        if (wire.hidden == WireframeHidden::Dim) cover *= 0.25f;
        if (wire.hidden == WireframeHidden::Dashed && std::fmod(s * len, 8.0) >= 4.0) continue;
      }
      atomic_max(alpha[i], cover);
    }
  }
}

}  // namespace

std::vector<float> render_wireframe(const Scene& scene, const Accelerator& accel, const Camera& camera,
                                    const RenderConfig& config, const WireframeConfig& wire) {
  const PixelWindow win = render_window(config);
  Projector pr;
  pr.cam = camera;
  pr.raster = camera_raster(camera, config.width, config.height);
  pr.ortho = camera.projection == Projection::Orthographic;
  pr.half_h = camera.ymag;
  pr.half_w = camera.ymag * pr.raster.aspect;
  tbb::task_arena arena(thread_count(config.threads));
  CentreHits centres;
  arena.execute([&] { centres = trace_centres(scene, accel, pr, win); });
  std::vector<float> alpha(size_t(win.width()) * size_t(win.height()), 0.0f);
  std::vector<uint32_t> chosen;
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.shape >= 0) continue;
    const Mesh& m = scene.meshes[size_t(inst.mesh)];
    if (m.points || m.lines) continue;
    if (!wire.nodes.empty() && std::find(wire.nodes.begin(), wire.nodes.end(), inst.node) == wire.nodes.end())
      continue;
    chosen.push_back(uint32_t(i));
  }
  arena.execute([&] {
    for (uint32_t instance : chosen) {
      const Instance& inst = scene.instances[instance];
      const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
      const size_t triangles = mesh.indices.size() / 3;
      tbb::parallel_for(tbb::blocked_range<size_t>(0, triangles, 256),
                        [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t t = r.begin(); t < r.end(); ++t) {
                            const WorldTriangle tri = world_triangle(scene, inst, uint32_t(t));
                            for (int k = 0; k < 3; ++k) {
                              // Each edge from its lower vertex index: the triangles sharing it dash it
                              // alike.
                              const int k1 = (k + 1) % 3;
                              const bool up = tri.index[k] < tri.index[k1];
                              const int i0 = up ? k : k1, i1 = up ? k1 : k;
                              if (tri.index[i0] == tri.index[i1]) continue;
                              draw_edge(scene, pr, centres, wire, instance, tri.index[i0], tri.index[i1],
                                        tri.p[i0], tri.p[i1], alpha);
                            }
                          }
                        });
    }
  });
  return alpha;
}

void overlay_wireframe(Film& film, const std::vector<float>& alpha, Vec3f colour) {
  const size_t n = std::min(alpha.size(), film.rgba.size() / 4);
  for (size_t i = 0; i < n; ++i) {
    const float a = alpha[i];
    if (!(a > 0)) continue;
    float* p = &film.rgba[4 * i];
    p[0] = colour.x * a + p[0] * (1 - a);
    p[1] = colour.y * a + p[1] * (1 - a);
    p[2] = colour.z * a + p[2] * (1 - a);
    p[3] = a + p[3] * (1 - a);
  }
}

}  // namespace penumbra
