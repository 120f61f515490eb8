// EWA splatting of Gaussian splats; see splat_raster.h.
#include "renderer/raster/splat_raster.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>

namespace penumbra {

namespace {
using M3 = std::array<std::array<double, 3>, 3>;

M3 mul(const M3& a, const M3& b) {
  M3 c{};
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j)
      for (size_t k = 0; k < 3; ++k) c[i][j] += a[i][k] * b[k][j];
  return c;
}
}  // namespace

bool project_splat(const Scene& scene, const Camera& camera, int width, int height, uint32_t inst, uint32_t i,
                   ProjectedSplat& out, Sym2* covariance) {
  const SplatInstance& si = scene.splat_instances[inst];
  const SplatCloud& cloud = scene.splat_clouds[size_t(si.cloud)];
  const Shape shape = splat_shape(cloud, i, i);
  if (!(shape.opacity > 0)) return false;
  // The splat's axes R S (the inverse of its whitening S^-1 R^T: rows over their squared norms).
  M3 axes{};
  for (size_t k = 0; k < 3; ++k) {
    const Vec3f w = shape.whiten[k];
    const double n2 = double(dot(w, w));
    for (size_t a = 0; a < 3; ++a) axes[a][k] = double(w[int(a)]) / n2;
  }
  // Camera rows (u, v, -w) times the instance's linear part.
  const Vec3f rows[3] = {camera.u, camera.v, -camera.w};
  M3 cam_lin{};
  for (size_t r = 0; r < 3; ++r)
    for (size_t c = 0; c < 3; ++c) {
      double sum = 0;
      for (size_t k = 0; k < 3; ++k) sum += double(rows[r][int(k)]) * si.to_world.m[k][c];
      cam_lin[r][c] = sum;
    }
  const M3 m = mul(cam_lin, axes);  // camera-space axes
  const Vec3f world = apply_point(si.to_world, cloud.positions[i]);
  const Vec3f rel = world - camera.eye;
  const double x = dot(rel, camera.u), y = dot(rel, camera.v), z = dot(rel, -camera.w);
  const bool ortho = camera.projection == Projection::Orthographic;
  if (!(z > std::max(double(camera.znear), 1e-6)) || !(z < double(camera.zfar))) return false;
  const CameraRaster raster = camera_raster(camera, width, height);
  double j[2][3] = {};
  double px = 0, py = 0;
  if (ortho) {
    const double fx = width / (2.0 * camera.ymag * raster.aspect), fy = height / (2.0 * camera.ymag);
    j[0][0] = fx, j[1][1] = -fy;
    px = 0.5 * width + fx * x, py = 0.5 * height - fy * y;
  } else {
    const double fx = width / (2.0 * raster.tan_x), fy = height / (2.0 * raster.tan_y);
    j[0][0] = fx / z, j[0][2] = -fx * x / (z * z);
    j[1][1] = -fy / z, j[1][2] = fy * y / (z * z);
    px = 0.5 * width + fx * x / z, py = 0.5 * height - fy * y / z;
  }
  // Sigma' = (J M)(J M)^T.
  double jm[2][3] = {};
  for (size_t r = 0; r < 2; ++r)
    for (size_t c = 0; c < 3; ++c)
      for (size_t k = 0; k < 3; ++k) jm[r][c] += j[r][k] * m[k][c];
  Sym2 cov;
  for (size_t k = 0; k < 3; ++k) {
    cov.xx += jm[0][k] * jm[0][k];
    cov.xy += jm[0][k] * jm[1][k];
    cov.yy += jm[1][k] * jm[1][k];
  }
  if (covariance) *covariance = cov;
  const double det = cov.xx * cov.yy - cov.xy * cov.xy;
  if (!(det > 0) || !std::isfinite(det)) return false;
  out.centre = {float(px), float(py)};
  out.conic[0] = float(cov.yy / det), out.conic[1] = float(-cov.xy / det), out.conic[2] = float(cov.xx / det);
  const double rx = kSplatSigmas * std::sqrt(cov.xx), ry = kSplatSigmas * std::sqrt(cov.yy);
  out.lo = {float(px - rx), float(py - ry)};
  out.hi = {float(px + rx), float(py + ry)};
  out.depth = float(z);
  out.opacity = shape.opacity;
  // Colour along the direction from the eye (orthographic: the view axis) in the cloud's space.
  Affine3f inv;
  Vec3f dir = ortho ? -camera.w : rel;
  if (inverse(si.to_world, inv)) dir = apply_vector(inv, dir);
  out.color = splat_linear_color(cloud.color_space, splat_sh_color(cloud, i, normalize(dir)));
  out.instance = inst;
  out.splat = i;
  return std::isfinite(out.centre.x) && std::isfinite(out.centre.y) && is_finite(out.color);
}

std::vector<ProjectedSplat> project_splats(const Scene& scene, const Camera& camera, int width, int height,
                                           const PixelWindow& window, float margin, int threads) {
  std::vector<std::pair<uint32_t, uint32_t>> items;
  for (uint32_t k = 0; k < scene.splat_instances.size(); ++k) {
    const size_t n = scene.splat_clouds[size_t(scene.splat_instances[k].cloud)].positions.size();
    for (uint32_t i = 0; i < n; ++i) items.push_back({k, i});
  }
  std::vector<ProjectedSplat> all(items.size());
  std::vector<uint8_t> keep(items.size(), 0);
  tbb::task_arena arena(thread_count(threads));
  arena.execute([&] {
    tbb::parallel_for(size_t(0), items.size(), [&](size_t k) {
      ProjectedSplat& s = all[k];
      keep[k] = project_splat(scene, camera, width, height, items[k].first, items[k].second, s) &&
                s.hi.x >= float(window.x0) - margin && s.lo.x <= float(window.x1) + margin &&
                s.hi.y >= float(window.y0) - margin && s.lo.y <= float(window.y1) + margin;
    });
  });
  size_t n = 0;
  for (size_t k = 0; k < all.size(); ++k)
    if (keep[k]) all[n++] = all[k];
  all.resize(n);
  arena.execute([&] {
    tbb::parallel_sort(all.begin(), all.end(), [](const ProjectedSplat& a, const ProjectedSplat& b) {
      if (a.depth != b.depth) return a.depth < b.depth;
      if (a.instance != b.instance) return a.instance < b.instance;
      return a.splat < b.splat;
    });
  });
  return all;
}

namespace {
// floor(v), clamped to [0, n - 1] before it becomes an int (a splat's box may reach far beyond
// any int, or be NaN: then 0).
int cell_index(float v, int n) {
  const float f = std::floor(v);
  return f >= 0 ? (f < float(n - 1) ? int(f) : n - 1) : 0;
}
}  // namespace

size_t SplatBins::cell_of(Vec2f p) const {
  const int cx = cell_index((p.x - float(window.x0)) / float(cell), columns);
  const int cy = cell_index((p.y - float(window.y0)) / float(cell), rows);
  return size_t(cy) * size_t(columns) + size_t(cx);
}

SplatBins bin_splats(std::span<const ProjectedSplat> splats, const PixelWindow& window, float margin,
                     int cell) {
  SplatBins b;
  b.window = window;
  b.cell = std::max(1, cell);
  b.columns = std::max(1, (window.width() + b.cell - 1) / b.cell);
  b.rows = std::max(1, (window.height() + b.cell - 1) / b.cell);
  const size_t cells = size_t(b.columns) * size_t(b.rows);
  // Each splat goes to the cells its box meets, widened by how far a sample may lie outside its
  // pixel (and a pixel more).
  const float pad = margin + 1;
  auto range = [&](const ProjectedSplat& s, int& x0, int& x1, int& y0, int& y1) {
    x0 = cell_index((s.lo.x - pad - float(window.x0)) / float(b.cell), b.columns);
    x1 = cell_index((s.hi.x + pad - float(window.x0)) / float(b.cell), b.columns);
    y0 = cell_index((s.lo.y - pad - float(window.y0)) / float(b.cell), b.rows);
    y1 = cell_index((s.hi.y + pad - float(window.y0)) / float(b.cell), b.rows);
  };
  std::vector<uint32_t> count(cells + 1, 0);
  for (const ProjectedSplat& s : splats) {
    int x0, x1, y0, y1;
    range(s, x0, x1, y0, y1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) ++count[size_t(y) * size_t(b.columns) + size_t(x)];
  }
  b.begin.assign(cells + 1, 0);
  for (size_t c = 0; c < cells; ++c) b.begin[c + 1] = b.begin[c] + count[c];
  b.refs.resize(b.begin[cells]);
  std::vector<uint32_t> at(b.begin.begin(), b.begin.end() - 1);
  for (uint32_t k = 0; k < splats.size(); ++k) {
    int x0, x1, y0, y1;
    range(splats[k], x0, x1, y0, y1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) b.refs[at[size_t(y) * size_t(b.columns) + size_t(x)]++] = k;
  }
  return b;
}

uint64_t splat_raster_bytes(const Scene& scene) {
  uint64_t n = 0;
  for (const SplatInstance& s : scene.splat_instances)
    n += scene.splat_clouds[size_t(s.cloud)].positions.size();
  return n * (sizeof(ProjectedSplat) + 8 + 16 * 4);
}

float splat_alpha_at(const ProjectedSplat& s, Vec2f p) {
  const float dx = p.x - s.centre.x, dy = p.y - s.centre.y;
  const float q = s.conic[0] * dx * dx + 2 * s.conic[1] * dx * dy + s.conic[2] * dy * dy;
  if (!(q <= kSplatSigmas * kSplatSigmas)) return 0;
  const float a = s.opacity * std::exp(-0.5f * q);
  return a >= kSplatMinAlpha ? a : 0.0f;
}

SplatCursor splat_cursor(std::span<const ProjectedSplat> splats, const SplatBins& bins, Vec2f p) {
  SplatCursor c;
  c.splats = splats;
  c.p = p;
  if (bins.refs.empty()) return c;
  const size_t cell = bins.cell_of(p);
  c.next = bins.refs.data() + bins.begin[cell];
  c.end = bins.refs.data() + bins.begin[cell + 1];
  return c;
}

void SplatCursor::advance(float zmax, Vec3f& sum, float& remaining) {
  for (; next != end && remaining > 0; ++next) {
    const ProjectedSplat& s = splats[*next];
    if (!(s.depth < zmax)) return;
    const float a = std::min(splat_alpha_at(s, p), 1.0f);
    if (!(a > 0)) continue;
    sum += s.color * (remaining * a);
    const float before = remaining;
    remaining *= 1 - a;
    if (before >= 0.5f && remaining < 0.5f) median = &s;
    if (remaining < kSplatMinTransmittance) remaining = 0;
  }
}

}  // namespace penumbra
