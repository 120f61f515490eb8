// NFOR (Bitterli et al. 2016) and a cross-bilateral baseline; see denoise.h.
#include "renderer/film/denoise.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>

#include "renderer/core/math.h"
#include "renderer/core/parallel.h"

namespace penumbra {

namespace {

// A row-major image of `c` floats per pixel.
struct Plane {
  int w = 0, h = 0, c = 0;
  std::vector<float> v;
  Plane() = default;
  Plane(int width, int height, int channels)
      : w(width), h(height), c(channels), v(size_t(width) * size_t(height) * size_t(channels), 0.0f) {}
  float* at(int x, int y) { return &v[(size_t(y) * size_t(w) + size_t(x)) * size_t(c)]; }
  const float* at(int x, int y) const { return &v[(size_t(y) * size_t(w) + size_t(x)) * size_t(c)]; }
  const float* clamped(int x, int y) const { return at(std::clamp(x, 0, w - 1), std::clamp(y, 0, h - 1)); }
};

// The input buffer as a plane, non-finite values read as 0.
Plane finite_plane(const std::vector<float>& src, int w, int h, int c) {
  Plane p(w, h, c);
  for (size_t i = 0; i < p.v.size(); ++i) p.v[i] = std::isfinite(src[i]) ? src[i] : 0.0f;
  return p;
}

// Features with every miss's depth (+inf, or any non-finite value) set to the largest finite
// depth of either half, so that background pixels form one depth layer behind the scene.
void fill_missing_depth(const DenoiseInput& in, Plane out[2]) {
  float far = 0;
  for (int h = 0; h < 2; ++h)
    for (size_t i = kDenoiseFeatures - 1; i < in.features[h].size(); i += kDenoiseFeatures)
      if (std::isfinite(in.features[h][i])) far = std::max(far, in.features[h][i]);
  for (int h = 0; h < 2; ++h) {
    out[h] = finite_plane(in.features[h], in.width, in.height, kDenoiseFeatures);
    for (size_t i = kDenoiseFeatures - 1; i < out[h].v.size(); i += kDenoiseFeatures)
      if (!std::isfinite(in.features[h][i])) out[h].v[i] = far;
  }
}

float luminance(const float* c) {
  return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
}

// Per pixel, `scale` times the (rank+1)-th largest luminance of `src` over the (2 radius + 1)^2
// pixels around it (clamped at the border; without the pixel itself if `skip_centre`), plus
// 1e-3.
Plane luminance_bound(const Plane& src, int radius, bool skip_centre, int rank, float scale) {
  Plane bound(src.w, src.h, 1);
  std::array<float, 25> n{};
  for (int y = 0; y < src.h; ++y)
    for (int x = 0; x < src.w; ++x) {
      size_t k = 0;
      for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx)
          if (!skip_centre || dx != 0 || dy != 0) n[k++] = luminance(src.clamped(x + dx, y + dy));
      std::nth_element(n.begin(), n.begin() + rank, n.begin() + std::ptrdiff_t(k), std::greater<float>());
      bound.at(x, y)[0] = scale * n[size_t(rank)] + 1e-3f;
    }
  return bound;
}

// Firefly removal: a pixel of one half whose luminance exceeds twice the brightest pixel of the
// other half's 5 x 5 neighbourhood is scaled down to that bound. A sample that rarely finds a
// bright path (a caustic through a mirror) lands in one half only; left in, the regression
// spreads it over whole windows with overshoot, since the weights come from the other half,
// which never saw it. Detail present in both halves (a highlight) stays. This is biased (the
// rare paths' energy is dropped, as a clamp drops it); spreading the energy instead measured
// far worse in relative error, since one 16-spp draw of such paths is far from their mean.
void remove_spikes(Plane color[2]) {
  const Plane bound[2] = {luminance_bound(color[1], 2, false, 0, 2.0f),
                          luminance_bound(color[0], 2, false, 0, 2.0f)};
  for (int s = 0; s < 2; ++s)
    for (int y = 0; y < color[s].h; ++y)
      for (int x = 0; x < color[s].w; ++x) {
        float* c = color[s].at(x, y);
        const float l = luminance(c), b = bound[s].at(x, y)[0];
        if (l > b)
          for (int k = 0; k < 3; ++k) c[k] *= b / l;
      }
}

// Isolated highlights: a pixel whose luminance, in both halves, exceeds 4 times the third
// brightest of its 8 neighbours in that half (a glint of a point light, one pixel or a
// one-pixel line, in focus) is scaled down to that bound before the regression, and the excess
// (the halves' mean) returned, to be added back to the filtered image. Left in, the regression
// spreads it over its neighbours (each window's fit sees it); taken out, it stays sharp and
// its energy stays in its pixel. Noise rarely passes the test in both independent halves.
Plane split_highlights(Plane color[2]) {
  const int w = color[0].w, h = color[0].h;
  const Plane bound[2] = {luminance_bound(color[0], 1, true, 2, 4.0f),
                          luminance_bound(color[1], 1, true, 2, 4.0f)};
  Plane residual(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float l0 = luminance(color[0].at(x, y)), l1 = luminance(color[1].at(x, y));
      const float b0 = bound[0].at(x, y)[0], b1 = bound[1].at(x, y)[0];
      if (!(l0 > b0 && l1 > b1)) continue;
      for (int s = 0; s < 2; ++s) {
        float* c = color[s].at(x, y);
        const float f = (s == 0 ? b0 / l0 : b1 / l1);
        for (int i = 0; i < 3; ++i) {
          residual.at(x, y)[i] += 0.5f * c[i] * (1 - f);
          c[i] *= f;
        }
      }
    }
  return residual;
}

// Adds `residual` to the 3-channel image `out`.
void add_residual(std::vector<float>& out, const Plane& residual) {
  for (size_t i = 0; i < out.size(); ++i) out[i] += residual.v[i];
}

// Runs fn(tile) over the image's tiles on `threads` workers.
template <class Fn>
void for_each_tile(int w, int h, int tile_size, int threads, Fn&& fn) {
  TileScheduler(PixelWindow{0, 0, w, h}, tile_size, threads).for_each_tile(fn);
}

// Per-channel variance of one half from the two halves: (a - b)^2 / 2 averaged over 3 x 3
// pixels (clamped at the border). `scale` multiplies it (1/2: the variance of the halves' mean).
Plane half_variance(const Plane& a, const Plane& b, float scale, int tile_size, int threads) {
  Plane d(a.w, a.h, a.c), out(a.w, a.h, a.c);
  for (size_t i = 0; i < d.v.size(); ++i) d.v[i] = (a.v[i] - b.v[i]) * (a.v[i] - b.v[i]) * 0.5f * scale;
  for_each_tile(a.w, a.h, tile_size, threads, [&](const PixelWindow& t) {
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        float* o = out.at(x, y);
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const float* s = d.clamped(x + dx, y + dy);
            for (int ch = 0; ch < a.c; ++ch) o[ch] += s[ch] * (1.0f / 9);
          }
      }
  });
  return out;
}

// Non-local-means weights (Rousselle et al. 2012's distance) of every window offset for every
// pixel of a tile. weights[o * n + i]: offset o = (dy + R) (2R + 1) + dx + R, pixel i of the
// tile (row-major), n = tile pixels; 0 where the neighbour lies outside the image.
class NlmWeights {
 public:
  /// Keeps planar copies of guide and variance padded by R + F pixels (the border replicated),
  /// so the distance loops read contiguous rows.
  NlmWeights(const Plane& guide, const Plane& var, int radius, int patch, float k)
      : m_w(guide.w),
        m_h(guide.h),
        m_c(guide.c),
        m_r(radius),
        m_f(patch),
        m_pad(radius + patch),
        m_k2(k * k) {
    m_pw = m_w + 2 * m_pad;
    m_ph = m_h + 2 * m_pad;
    const size_t plane = size_t(m_pw) * size_t(m_ph);
    m_guide.resize(plane * size_t(m_c));
    m_var.resize(plane * size_t(m_c));
    for (int ch = 0; ch < m_c; ++ch)
      for (int y = 0; y < m_ph; ++y)
        for (int x = 0; x < m_pw; ++x) {
          const size_t o = size_t(ch) * plane + size_t(y) * size_t(m_pw) + size_t(x);
          m_guide[o] = guide.clamped(x - m_pad, y - m_pad)[ch];
          m_var[o] = var.clamped(x - m_pad, y - m_pad)[ch];
        }
  }
  int offsets() const { return (2 * m_r + 1) * (2 * m_r + 1); }
  int radius() const { return m_r; }

  void compute(const PixelWindow& t, std::vector<float>& weights, std::vector<float>& scratch) const {
    const int tw = t.width(), th = t.height(), pw = tw + 2 * m_f, ph = th + 2 * m_f;
    const size_t n = size_t(tw) * size_t(th), plane = size_t(m_pw) * size_t(m_ph);
    weights.assign(size_t(offsets()) * n, 0.0f);
    scratch.assign(size_t(pw) * size_t(ph) + size_t(tw) * size_t(ph), 0.0f);
    float* dist = scratch.data();                  // per-pixel distance over the padded tile
    float* rows = dist + size_t(pw) * size_t(ph);  // horizontal box sums
    const float inv_patch = 1.0f / float((2 * m_f + 1) * (2 * m_f + 1)), inv_c = 1.0f / float(m_c);
    for (int dy = -m_r; dy <= m_r; ++dy)
      for (int dx = -m_r; dx <= m_r; ++dx) {
        std::fill(dist, dist + size_t(pw) * size_t(ph), 0.0f);
        for (int ch = 0; ch < m_c; ++ch)
          for (int y = 0; y < ph; ++y) {
            // Padded-plane row of the tile's row y - F, and of its neighbours at (dx, dy).
            const size_t r0 = size_t(ch) * plane + size_t(t.y0 + y - m_f + m_pad) * size_t(m_pw) +
                              size_t(t.x0 - m_f + m_pad);
            const size_t r1 = r0 + size_t(ptrdiff_t(dy) * m_pw + dx);
            const float *g0 = &m_guide[r0], *g1 = &m_guide[r1], *v0 = &m_var[r0], *v1 = &m_var[r1];
            float* d = dist + size_t(y) * size_t(pw);
            for (int x = 0; x < pw; ++x) {
              const float diff = g0[x] - g1[x];
              const float num = diff * diff - (v0[x] + std::min(v0[x], v1[x]));
              d[x] += num / (1e-10f + m_k2 * (v0[x] + v1[x]));
            }
          }
        for (int y = 0; y < ph; ++y)
          for (int x = 0; x < tw; ++x) {
            float s = 0;
            for (int i = 0; i <= 2 * m_f; ++i) s += dist[size_t(y) * size_t(pw) + size_t(x + i)];
            rows[size_t(y) * size_t(tw) + size_t(x)] = s;
          }
        float* w = &weights[size_t((dy + m_r) * (2 * m_r + 1) + dx + m_r) * n];
        for (int y = 0; y < th; ++y)
          for (int x = 0; x < tw; ++x) {
            const int qx = t.x0 + x + dx, qy = t.y0 + y + dy;
            if (qx < 0 || qy < 0 || qx >= m_w || qy >= m_h) continue;
            float s = 0;
            for (int i = 0; i <= 2 * m_f; ++i) s += rows[size_t(y + i) * size_t(tw) + size_t(x)];
            w[size_t(y) * size_t(tw) + size_t(x)] = std::exp(-std::max(0.0f, s * inv_c * inv_patch));
          }
      }
  }

 private:
  int m_w, m_h, m_c, m_r, m_f, m_pad, m_pw = 0, m_ph = 0;
  float m_k2;
  std::vector<float> m_guide, m_var;  // planar, padded
};

// Non-local means: each pixel the weighted mean of `image` over its window, weighted by
// `weights` (a gather: each tile writes only its own pixels).
Plane nl_means(const Plane& image, const NlmWeights& weights, int tile_size, int threads) {
  Plane out(image.w, image.h, image.c);
  for_each_tile(image.w, image.h, tile_size, threads, [&](const PixelWindow& t) {
    std::vector<float> w, scratch;
    weights.compute(t, w, scratch);
    const int r = weights.radius(), tw = t.width();
    const size_t n = size_t(tw) * size_t(t.height());
    std::vector<double> acc(size_t(image.c));
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        const size_t i = size_t(y - t.y0) * size_t(tw) + size_t(x - t.x0);
        std::fill(acc.begin(), acc.end(), 0.0);
        double wsum = 0;
        for (int dy = -r; dy <= r; ++dy)
          for (int dx = -r; dx <= r; ++dx) {
            const float wj = w[size_t((dy + r) * (2 * r + 1) + dx + r) * n + i];
            if (wj <= 0) continue;
            const float* s = image.at(x + dx, y + dy);
            for (int ch = 0; ch < image.c; ++ch) acc[size_t(ch)] += double(wj) * s[ch];
            wsum += wj;
          }
        float* o = out.at(x, y);
        for (int ch = 0; ch < image.c; ++ch)
          o[ch] = wsum > 0 ? float(acc[size_t(ch)] / wsum) : image.at(x, y)[ch];
      }
  });
  return out;
}

constexpr int kDims = kDenoiseFeatures + 1;  // intercept + features

// Solves (A + ridge) x = b for the symmetric kDims x kDims matrix A (lower triangle used) and
// three right-hand sides, by Cholesky; false if A is not positive definite.
bool solve_spd(double a[kDims][kDims], double b[kDims][3]) {
  for (int j = 0; j < kDims; ++j) {
    double d = a[j][j];
    for (int k = 0; k < j; ++k) d -= a[j][k] * a[j][k];
    if (!(d > 0)) return false;
    a[j][j] = std::sqrt(d);
    for (int i = j + 1; i < kDims; ++i) {
      double s = a[i][j];
      for (int k = 0; k < j; ++k) s -= a[i][k] * a[j][k];
      a[i][j] = s / a[j][j];
    }
  }
  for (int c = 0; c < 3; ++c) {
    for (int i = 0; i < kDims; ++i) {
      double s = b[i][c];
      for (int k = 0; k < i; ++k) s -= a[i][k] * b[k][c];
      b[i][c] = s / a[i][i];
    }
    for (int i = kDims - 1; i >= 0; --i) {
      double s = b[i][c];
      for (int k = i + 1; k < kDims; ++k) s -= a[k][i] * b[k][c];
      b[i][c] = s / a[i][i];
    }
  }
  return true;
}

// The first-order fit at centre pixel (x, y): coefficients beta[k][c] of colour c on
// [1, f - f(x, y)], from the window's weighted samples. Columns are scaled to unit weighted
// mean square before a small ridge (1e-3 of the weight sum), so constant features drop out.
// False when nothing in the window has weight (then the pixel keeps its own colour).
bool fit_pixel(const Plane& color, const Plane& feat, const float* w, size_t n, size_t i, int x, int y, int r,
               double beta[kDims][3]) {
  // Sums in float (the rows are differences from the centre, of order one), solved in double.
  float af[kDims][kDims] = {}, bf[kDims][3] = {};
  const float* fc = feat.at(x, y);
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const float wj = w[size_t((dy + r) * (2 * r + 1) + dx + r) * n + i];
      if (wj <= 0) continue;
      float row[kDims];
      row[0] = 1;
      const float* fj = feat.at(x + dx, y + dy);
      for (int k = 0; k < kDenoiseFeatures; ++k) row[k + 1] = fj[k] - fc[k];
      const float* cj = color.at(x + dx, y + dy);
      for (int p = 0; p < kDims; ++p) {
        const float wr = wj * row[p];
        for (int q = 0; q <= p; ++q) af[p][q] += wr * row[q];  // the lower triangle: A is symmetric
        for (int c = 0; c < 3; ++c) bf[p][c] += wr * cj[c];
      }
    }
  double a[kDims][kDims], b[kDims][3];
  for (int p = 0; p < kDims; ++p) {
    for (int q = 0; q < kDims; ++q) a[p][q] = af[p][q];
    for (int c = 0; c < 3; ++c) b[p][c] = bf[p][c];
  }
  if (!(a[0][0] > 0)) return false;
  double s[kDims];
  s[0] = 1;
  for (int k = 1; k < kDims; ++k) s[k] = a[k][k] > 1e-12 * a[0][0] ? std::sqrt(a[0][0] / a[k][k]) : 0.0;
  for (int p = 0; p < kDims; ++p) {
    for (int q = 0; q <= p; ++q) a[p][q] *= s[p] * s[q];
    for (int c = 0; c < 3; ++c) b[p][c] *= s[p];
  }
  for (int k = 1; k < kDims; ++k) a[k][k] += 1e-3 * a[0][0];
  if (!solve_spd(a, b)) return false;
  for (int p = 0; p < kDims; ++p)
    for (int c = 0; c < 3; ++c) beta[p][c] = b[p][c] * s[p];
  return true;
}

// Each channel's minimum and maximum over the 3 x 3 pixels around every pixel (clamped at the
// border).
struct LocalRange {
  Plane lo, hi;
};

LocalRange local_range(const Plane& color) {
  LocalRange r{Plane(color.w, color.h, 3), Plane(color.w, color.h, 3)};
  for (int y = 0; y < color.h; ++y)
    for (int x = 0; x < color.w; ++x)
      for (int c = 0; c < 3; ++c) {
        float lo = kInfinity, hi = -kInfinity;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const float v = color.clamped(x + dx, y + dy)[c];
            lo = std::min(lo, v);
            hi = std::max(hi, v);
          }
        r.lo.at(x, y)[c] = lo;
        r.hi.at(x, y)[c] = hi;
      }
  return r;
}

// Collaborative first-order regression (NFOR section 5.2) of `color` on `feat` with `weights`:
// every pixel's fit evaluated at each neighbour of its window, and each pixel the weighted
// mean of the estimates it receives. Each estimate is clamped to the range of the colour
// around the pixel it is for (3 x 3): a fit extrapolated along the features from a small
// bright spot the features do not explain (a light's highlight on a mirror) would otherwise
// draw a streak across the window, or overshoot below zero. Tiles of one row of tiles run in parallel into
// private padded buffers, which are then added in tile order (deterministic for any thread count).
Plane regression(const Plane& color, const Plane& feat, const NlmWeights& weights, int tile_size,
                 int threads) {
  const int w = color.w, h = color.h, r = weights.radius();
  std::vector<double> acc(size_t(w) * size_t(h) * 4, 0.0);  // RGB sums and weight sum
  const LocalRange range = local_range(color);
  const int tiles_x = (w + tile_size - 1) / tile_size;
  std::vector<std::vector<float>> bufs(static_cast<size_t>(tiles_x));
  for (int ty = 0; ty < h; ty += tile_size) {
    const PixelWindow row{0, ty, w, std::min(h, ty + tile_size)};
    TileScheduler(row, tile_size, threads).for_each_tile([&](const PixelWindow& t) {
      const int bw = t.width() + 2 * r, bh = t.height() + 2 * r;
      std::vector<float>& buf = bufs[size_t(t.x0 / tile_size)];
      buf.assign(size_t(bw) * size_t(bh) * 4, 0.0f);
      std::vector<float> wts, scratch;
      weights.compute(t, wts, scratch);
      const size_t n = size_t(t.width()) * size_t(t.height());
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) {
          const size_t i = size_t(y - t.y0) * size_t(t.width()) + size_t(x - t.x0);
          double beta_d[kDims][3];
          if (!fit_pixel(color, feat, wts.data(), n, i, x, y, r, beta_d)) continue;
          float beta[kDims][3];
          for (int p = 0; p < kDims; ++p)
            for (int c = 0; c < 3; ++c) beta[p][c] = float(beta_d[p][c]);
          const float* fc = feat.at(x, y);
          for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
              const float wj = wts[size_t((dy + r) * (2 * r + 1) + dx + r) * n + i];
              if (wj <= 0) continue;
              const float* fj = feat.at(x + dx, y + dy);
              float* o = &buf[(size_t(y - t.y0 + r + dy) * size_t(bw) + size_t(x - t.x0 + r + dx)) * 4];
              const float* lo = range.lo.at(x + dx, y + dy);
              const float* hi = range.hi.at(x + dx, y + dy);
              float d[kDenoiseFeatures];
              for (int k = 0; k < kDenoiseFeatures; ++k) d[k] = fj[k] - fc[k];
              for (int c = 0; c < 3; ++c) {
                float e = beta[0][c];
                for (int k = 0; k < kDenoiseFeatures; ++k) e += beta[k + 1][c] * d[k];
                o[c] += wj * std::clamp(e, lo[c], hi[c]);
              }
              o[3] += wj;
            }
        }
    });
    for (int tx = 0; tx < tiles_x; ++tx) {  // in tile order
      const int x0 = tx * tile_size, x1 = std::min(w, x0 + tile_size), y1 = std::min(h, ty + tile_size);
      const int bw = x1 - x0 + 2 * r;
      const std::vector<float>& buf = bufs[size_t(tx)];
      for (int by = 0; by < y1 - ty + 2 * r; ++by) {
        const int y = ty - r + by;
        if (y < 0 || y >= h) continue;
        for (int bx = 0; bx < bw; ++bx) {
          const int x = x0 - r + bx;
          if (x < 0 || x >= w) continue;
          const float* s = &buf[(size_t(by) * size_t(bw) + size_t(bx)) * 4];
          double* a = &acc[(size_t(y) * size_t(w) + size_t(x)) * 4];
          for (int c = 0; c < 4; ++c) a[c] += s[c];
        }
      }
    }
  }
  Plane out(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double* a = &acc[(size_t(y) * size_t(w) + size_t(x)) * 4];
      for (int c = 0; c < 3; ++c) out.at(x, y)[c] = a[3] > 0 ? float(a[c] / a[3]) : color.at(x, y)[c];
    }
  return out;
}

Plane mean_of(const Plane& a, const Plane& b) {
  Plane m(a.w, a.h, a.c);
  for (size_t i = 0; i < m.v.size(); ++i) m.v[i] = 0.5f * (a.v[i] + b.v[i]);
  return m;
}

// (a - b)^2 / 4 per value: the variance of the mean of two estimates that differ by a - b.
Plane mean_variance(const Plane& a, const Plane& b) {
  Plane m(a.w, a.h, a.c);
  for (size_t i = 0; i < m.v.size(); ++i) m.v[i] = 0.25f * (a.v[i] - b.v[i]) * (a.v[i] - b.v[i]);
  return m;
}

// The channels [first, first + count) of a plane.
Plane channels(const Plane& p, int first, int count) {
  Plane out(p.w, p.h, count);
  for (size_t i = 0; i < size_t(p.w) * size_t(p.h); ++i)
    for (int c = 0; c < count; ++c)
      out.v[i * size_t(count) + size_t(c)] = p.v[i * size_t(p.c) + size_t(first + c)];
  return out;
}

// Non-local means of the features one group at a time (albedo, normal, depth), each group
// weighted by its own guide channels and variance (NFOR section 5.1), so that a feature
// without noise (variance 0) does not stop the filtering of a noisy one.
Plane filter_features(const Plane& image, const Plane& guide, const Plane& var, int radius, int patch,
                      float k, int tile_size, int threads) {
  constexpr int kGroups[3][2] = {{0, 3}, {3, 3}, {6, 1}};  // first channel, count
  Plane out(image.w, image.h, image.c);
  for (const auto& [first, count] : kGroups) {
    const Plane g = channels(guide, first, count), v = channels(var, first, count);
    const Plane f =
        nl_means(channels(image, first, count), NlmWeights(g, v, radius, patch, k), tile_size, threads);
    for (size_t i = 0; i < size_t(image.w) * size_t(image.h); ++i)
      for (int c = 0; c < count; ++c)
        out.v[i * size_t(image.c) + size_t(first + c)] = f.v[i * size_t(count) + size_t(c)];
  }
  return out;
}

// NFOR sections 5.2-5.3: each colour half regressed on the other half's features, guided by
// the other half, at both bandwidths; each candidate's error estimated against the other half
// and smoothed; per pixel, the halves at the bandwidth of lower error (a smoothed selection).
std::array<Plane, 2> selected_halves(const Plane color[2], const Plane feat[2], const DenoiseConfig& cfg) {
  const int w = color[0].w, h = color[0].h, ts = cfg.tile_size, th = cfg.threads;
  const Plane var_half = half_variance(color[0], color[1], 1.0f, ts, th);
  const Plane mean = mean_of(color[0], color[1]);
  Plane mean_var = var_half;
  for (float& v : mean_var.v) v *= 0.5f;
  Plane cand[2][2], mse[2];
  for (int b = 0; b < 2; ++b) {
    for (int s = 0; s < 2; ++s)
      cand[b][s] = regression(
          color[s], feat[1 - s],
          NlmWeights(color[1 - s], var_half, cfg.window_radius, cfg.patch_radius, cfg.bandwidths[b]), ts, th);
    Plane noisy(w, h, 3);
    for (size_t i = 0; i < noisy.v.size(); ++i) {
      const float ea = (color[1].v[i] - cand[b][0].v[i]) * (color[1].v[i] - cand[b][0].v[i]) - var_half.v[i];
      const float eb = (color[0].v[i] - cand[b][1].v[i]) * (color[0].v[i] - cand[b][1].v[i]) - var_half.v[i];
      const float residual =
          0.25f * (cand[b][1].v[i] - cand[b][0].v[i]) * (cand[b][1].v[i] - cand[b][0].v[i]);
      noisy.v[i] = 0.5f * (ea + eb) - residual;
    }
    mse[b] = nl_means(noisy, NlmWeights(mean, mean_var, cfg.window_radius, 1, 1.0f), ts, th);
  }
  Plane select(w, h, 3);
  for (size_t i = 0; i < select.v.size(); ++i) select.v[i] = mse[0].v[i] < mse[1].v[i] ? 0.0f : 1.0f;
  select = nl_means(select, NlmWeights(mean, mean_var, cfg.window_radius, 1, 1.0f), ts, th);
  std::array<Plane, 2> result = {Plane(w, h, 3), Plane(w, h, 3)};
  for (int s = 0; s < 2; ++s)
    for (size_t i = 0; i < select.v.size(); ++i)
      result[size_t(s)].v[i] = cand[0][s].v[i] + select.v[i] * (cand[1][s].v[i] - cand[0][s].v[i]);
  return result;
}

}  // namespace

const char* validate(const DenoiseConfig& c) {
  if (c.window_radius < 1 || c.window_radius > 20) return "window radius must be in 1..20";
  if (c.patch_radius < 0 || c.patch_radius > 10) return "patch radius must be in 0..10";
  if (c.feature_window_radius < 0 || c.feature_window_radius > 20)
    return "feature window radius must be in 0..20";
  for (float k : c.bandwidths)
    if (!(k > 0) || !std::isfinite(k)) return "bandwidths must be positive and finite";
  if (!(c.feature_bandwidth > 0) || !std::isfinite(c.feature_bandwidth))
    return "feature bandwidth must be positive";
  if (c.tile_size < 8 || c.tile_size > 256) return "tile size must be in 8..256";
  return "";
}

const char* validate(const DenoiseInput& in) {
  if (in.width < 1 || in.height < 1) return "image is empty";
  const size_t n = size_t(in.width) * size_t(in.height);
  for (int h = 0; h < 2; ++h) {
    if (in.color[h].size() != n * 3) return "a colour half does not have 3 channels per pixel";
    if (in.features[h].size() != n * kDenoiseFeatures)
      return "a feature half does not have 7 channels per pixel";
  }
  return "";
}

size_t denoise_bytes(int width, int height, const DenoiseConfig& c) {
  // The peak, in floats per pixel, is in the regressions of steps 2-3: the inputs as planes
  // (20), the highlights' excess (3), the colour variance, the halves' mean and its variance (9), the four
  // candidate colours (12), an error map being filtered and the two filtered ones (9), a regression's output
  // (3), the 3 x 3 colour range its estimates are clamped to (6) and double accumulators (8); step 4 holds
  // less (the inputs, the two selected halves and about 40 more). Weights keep padded copies of at most 3
  // guide and 3 variance channels, and every thread a tile of weights.
  const size_t pixels = size_t(width) * size_t(height);
  const size_t r = size_t(std::max(c.window_radius, c.feature_window_radius)), t = size_t(c.tile_size),
               f = size_t(c.patch_radius), pad = r + f;
  const size_t padded = 6 * (size_t(width) + 2 * pad) * (size_t(height) + 2 * pad);
  const size_t tiles_x = (size_t(width) + t - 1) / t;
  const size_t tile_weights = (2 * r + 1) * (2 * r + 1) * t * t + 2 * (t + 2 * f) * (t + 2 * f);
  const size_t row_buffers = tiles_x * (t + 2 * r) * (t + 2 * r) * 4;
  return (pixels * 70 + padded + size_t(thread_count(c.threads)) * tile_weights + row_buffers) *
         sizeof(float);
}

std::vector<float> denoise_nfor(const DenoiseInput& in, const DenoiseConfig& cfg,
                                const std::function<void(int, int)>& progress) {
  const int w = in.width, h = in.height, ts = cfg.tile_size, th = cfg.threads;
  const int steps = cfg.second_pass ? 3 : 2;
  const auto step_done = [&](int done) {
    if (progress) progress(done, steps);
  };
  Plane color[2] = {finite_plane(in.color[0], w, h, 3), finite_plane(in.color[1], w, h, 3)};
  remove_spikes(color);
  const Plane highlights = split_highlights(color);
  Plane feat[2];
  fill_missing_depth(in, feat);

  // 1. Feature prefiltering: each half with weights from the other.
  if (cfg.feature_window_radius > 0) {
    const Plane fvar = half_variance(feat[0], feat[1], 1.0f, ts, th);
    Plane filtered[2];
    for (int s = 0; s < 2; ++s)
      filtered[s] = filter_features(feat[s], feat[1 - s], fvar, cfg.feature_window_radius, cfg.patch_radius,
                                    cfg.feature_bandwidth, ts, th);
    feat[0] = std::move(filtered[0]);
    feat[1] = std::move(filtered[1]);
  }
  step_done(1);

  // 2.-3. The two halves, each regressed at the bandwidth selected per pixel.
  const std::array<Plane, 2> result = selected_halves(color, feat, cfg);
  step_done(2);

  // 4. The second pass: the selected halves' mean regressed on the halves' mean features.
  Plane combined = mean_of(result[0], result[1]);
  if (!cfg.second_pass) {
    add_residual(combined.v, highlights);
    return std::move(combined.v);
  }
  const Plane combined_var = mean_variance(result[0], result[1]);
  const Plane feat_mean = mean_of(feat[0], feat[1]), feat_var = mean_variance(feat[0], feat[1]);
  const Plane final_feat = filter_features(feat_mean, feat_mean, feat_var, 2, cfg.patch_radius, 0.5f, ts, th);
  std::vector<float> out =
      regression(combined, final_feat,
                 NlmWeights(combined, combined_var, cfg.window_radius, cfg.patch_radius, 1.0f), ts, th)
          .v;
  add_residual(out, highlights);
  step_done(3);
  return out;
}

std::vector<float> denoise_cross_bilateral(const DenoiseInput& in, int window_radius, int threads) {
  const int w = in.width, h = in.height, r = std::max(1, window_radius);
  const Plane color = mean_of(finite_plane(in.color[0], w, h, 3), finite_plane(in.color[1], w, h, 3));
  Plane feat[2];
  fill_missing_depth(in, feat);
  const Plane f = mean_of(feat[0], feat[1]);
  Plane out(w, h, 3);
  const float sigma_p = std::max(1.0f, float(r) / 2);
  for_each_tile(w, h, 32, threads, [&](const PixelWindow& t) {
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        const float* fc = f.at(x, y);
        const float sigma_z = std::max(1e-6f, 0.02f * std::fabs(fc[6]));
        double acc[3] = {0, 0, 0}, wsum = 0;
        for (int dy = -r; dy <= r; ++dy)
          for (int dx = -r; dx <= r; ++dx) {
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
            const float* fq = f.at(qx, qy);
            float e = float(dx * dx + dy * dy) / (2 * sigma_p * sigma_p);
            for (int k = 0; k < 3; ++k) e += (fq[k] - fc[k]) * (fq[k] - fc[k]) / (2 * 0.1f * 0.1f);
            for (int k = 3; k < 6; ++k) e += (fq[k] - fc[k]) * (fq[k] - fc[k]) / (2 * 0.2f * 0.2f);
            e += (fq[6] - fc[6]) * (fq[6] - fc[6]) / (2 * sigma_z * sigma_z);
            const double wq = std::exp(-double(e));
            const float* c = color.at(qx, qy);
            for (int k = 0; k < 3; ++k) acc[k] += wq * c[k];
            wsum += wq;
          }
        for (int k = 0; k < 3; ++k) out.at(x, y)[k] = float(acc[k] / wsum);
      }
  });
  return out.v;
}

}  // namespace penumbra
