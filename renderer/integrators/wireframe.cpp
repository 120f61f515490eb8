// The wireframe overlay; see wireframe.h.
#include "renderer/integrators/wireframe.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>

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
  /// Raster position of `p`, whose depth is > 0 (perspective).
  Vec2f project(Vec3f p) const {
    const Vec3f q = p - cam.eye;
    float sx, sy;
    if (ortho) {
      sx = dot(q, cam.u) / half_w;
      sy = dot(q, cam.v) / half_h;
    } else {
      const float z = dot(q, -cam.w);
      sx = dot(q, cam.u) / (z * raster.tan_x);
      sy = dot(q, cam.v) / (z * raster.tan_y);
    }
    return {(sx + 1) * 0.5f * raster.width, (1 - sy) * 0.5f * raster.height};
  }
  float footprint(float depth) const {
    return ortho ? 2 * half_h / raster.height : 2 * std::max(depth, 0.0f) * raster.tan_y / raster.height;
  }
};

CentreHits trace_centres(const Scene& scene, const Accelerator& accel, const Projector& pr, PixelWindow win) {
  (void)scene;
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
        if (accel.intersect(ray, hit)) {
          out.hits[i] = hit;
          out.depth[i] = pr.depth(ray.org + ray.dir * hit.t);
        }
      }
  });
  return out;
}

/// Raises the float at `slot` to `value` (coverage is non-negative, so its bits order as it does).
void atomic_max(float& slot, float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, 4);
  std::atomic_ref<uint32_t> ref(*reinterpret_cast<uint32_t*>(&slot));
  uint32_t old = ref.load(std::memory_order_relaxed);
  while (old < bits && !ref.compare_exchange_weak(old, bits, std::memory_order_relaxed)) {
  }
}

/// Whether the triangle `prim` of mesh `mesh` has both vertices a and b.
bool has_edge(const Mesh& mesh, uint32_t prim, uint32_t a, uint32_t b) {
  const uint32_t* t = &mesh.indices[3 * size_t(prim)];
  const bool ha = t[0] == a || t[1] == a || t[2] == a, hb = t[0] == b || t[1] == b || t[2] == b;
  return ha && hb;
}

/// One edge a-b (vertex indices of `mesh`, world points pa, pb) of instance `instance`.
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
  const Vec2f sa = pr.project(pa), sb = pr.project(pb);
  if (!std::isfinite(sa.x + sa.y + sb.x + sb.y)) return;
  const float half = 0.5f * wire.width;
  const PixelWindow& win = centres.win;
  const float reach = half + 1;
  const int x0 = std::max(win.x0, int(std::floor(std::min(sa.x, sb.x) - reach)));
  const int x1 = std::min(win.x1, int(std::ceil(std::max(sa.x, sb.x) + reach)));
  const int y0 = std::max(win.y0, int(std::floor(std::min(sa.y, sb.y) - reach)));
  const int y1 = std::min(win.y1, int(std::ceil(std::max(sa.y, sb.y) + reach)));
  if (x0 >= x1 || y0 >= y1) return;
  const Vec2f d{sb.x - sa.x, sb.y - sa.y};
  const float dd = d.x * d.x + d.y * d.y, len = std::sqrt(dd);
  const Mesh& mesh = scene.meshes[size_t(scene.instances[instance].mesh)];
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const Vec2f c{float(x) + 0.5f, float(y) + 0.5f};
      float s = dd > 0 ? ((c.x - sa.x) * d.x + (c.y - sa.y) * d.y) / dd : 0.0f;
      s = std::clamp(s, 0.0f, 1.0f);
      const float ex = sa.x + d.x * s - c.x, ey = sa.y + d.y * s - c.y;
      float cover = std::clamp(half + 0.5f - std::sqrt(ex * ex + ey * ey), 0.0f, 1.0f);
      if (cover <= 0) continue;
      // The edge's depth at s: 1 / depth is linear on screen (perspective).
      const float z = pr.ortho ? za + (zb - za) * s : 1.0f / ((1 - s) / za + s / zb);
      const size_t i = size_t(y - win.y0) * size_t(win.width()) + size_t(x - win.x0);
      const Hit& h = centres.hits[i];
      const bool visible = !h.valid() ||
                           (h.geom_id == instance && scene.instances[instance].shape < 0 &&
                            !renders_as_curves(mesh) && has_edge(mesh, h.prim_id, a, b)) ||
                           z <= centres.depth[i] + 1e-3f * z + 2 * pr.footprint(z) * (half + 1);
      if (!visible) {
        if (wire.hidden == WireframeHidden::Off) continue;
        if (wire.hidden == WireframeHidden::Dim) cover *= 0.25f;
        if (wire.hidden == WireframeHidden::Dashed && std::fmod(s * len, 8.0f) >= 4.0f) continue;
      }
      atomic_max(alpha[i], cover);
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
  const CentreHits centres = trace_centres(scene, accel, pr, win);
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
  for (uint32_t instance : chosen) {
    const Instance& inst = scene.instances[instance];
    const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
    const size_t triangles = mesh.indices.size() / 3;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, triangles, 256),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t t = r.begin(); t < r.end(); ++t) {
                          const WorldTriangle tri = world_triangle(scene, inst, uint32_t(t));
                          for (int k = 0; k < 3; ++k) {
                            // Each edge from its lower vertex index: the triangles sharing it dash it alike.
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
