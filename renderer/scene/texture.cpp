// Texture storage and filtering (isotropic MIP mapping after Williams, "Pyramidal
// Parametrics", SIGGRAPH 1983; level selection as in pbrt-v4's MIPMap::Filter).
#include "renderer/scene/texture.h"

#include <cmath>

namespace penumbra {

namespace {

uint16_t to_unorm16(float v) {
  if (!(v > 0)) return 0;  // also NaN
  if (v >= 1) return 65535;
  return uint16_t(std::lround(v * 65535.0f));
}

// Wraps integer texel coordinate i into [0, n).
int wrap_index(int64_t i, int n, TextureWrap mode) {
  if (i >= 0 && i < n) return int(i);  // inside the texture: every mode leaves it
  switch (mode) {
    case TextureWrap::ClampToEdge:
      return int(std::clamp<int64_t>(i, 0, n - 1));
    case TextureWrap::MirroredRepeat: {
      const int64_t period = 2 * int64_t(n);
      int64_t m = i % period;
      if (m < 0) m += period;
      return int(m < n ? m : period - 1 - m);
    }
    case TextureWrap::Repeat:
    default: {
      int64_t m = i % n;
      if (m < 0) m += n;
      return int(m);
    }
  }
}

// Float texel coordinate to a safe integer (huge or NaN coordinates stay in int64 range).
int64_t floor_index(float x) {
  if (!(x == x)) return 0;
  return int64_t(std::floor(std::clamp(x, -1e9f, 1e9f)));
}

Vec4f fetch(const MipLevel& l, int x, int y) {
  const uint16_t* t = &l.texels[(size_t(y) * size_t(l.width) + size_t(x)) * 4];
  constexpr float s = 1.0f / 65535.0f;
  return {t[0] * s, t[1] * s, t[2] * s, t[3] * s};
}

Vec4f lerp4(Vec4f a, Vec4f b, float t) {
  return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z + (b.z - a.z) * t, a.w + (b.w - a.w) * t};
}

Vec4f sample_level(const MipLevel& l, const TextureSampler& s, Vec2f uv, TextureFilter filter) {
  const float x = uv.x * float(l.width), y = uv.y * float(l.height);
  if (filter == TextureFilter::Nearest)
    return fetch(l, wrap_index(floor_index(x), l.width, s.wrap_s),
                 wrap_index(floor_index(y), l.height, s.wrap_t));
  const float xs = x - 0.5f, ys = y - 0.5f;
  const int64_t x0 = floor_index(xs), y0 = floor_index(ys);
  float fx = xs - float(x0), fy = ys - float(y0);
  if (!(fx >= 0 && fx <= 1)) fx = 0;  // NaN or coordinates beyond float precision
  if (!(fy >= 0 && fy <= 1)) fy = 0;
  const int xa = wrap_index(x0, l.width, s.wrap_s), xb = wrap_index(x0 + 1, l.width, s.wrap_s);
  const int ya = wrap_index(y0, l.height, s.wrap_t), yb = wrap_index(y0 + 1, l.height, s.wrap_t);
  return lerp4(lerp4(fetch(l, xa, ya), fetch(l, xb, ya), fx), lerp4(fetch(l, xa, yb), fetch(l, xb, yb), fx),
               fy);
}

}  // namespace

float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

uint64_t texture_bytes_for(int width, int height) {
  uint64_t bytes = 0;
  uint64_t w = uint64_t(std::max(width, 1)), h = uint64_t(std::max(height, 1));
  for (;;) {
    bytes += w * h * 8;
    if (w == 1 && h == 1) break;
    w = std::max<uint64_t>(1, (w + 1) / 2);
    h = std::max<uint64_t>(1, (h + 1) / 2);
  }
  return bytes;
}

uint64_t texture_bytes(const Texture& tex) {
  uint64_t bytes = 0;
  for (const auto& l : tex.levels) bytes += l.texels.size() * sizeof(uint16_t);
  return bytes;
}

Texture make_texture(std::string name, int width, int height, const std::vector<float>& rgba,
                     const TextureSampler& sampler) {
  Texture tex;
  tex.name = std::move(name);
  tex.sampler = sampler;
  std::vector<float> cur(rgba.size());
  for (size_t i = 0; i < rgba.size(); ++i)
    cur[i] = std::isfinite(rgba[i]) ? std::clamp(rgba[i], 0.0f, 1.0f) : 0.0f;
  int w = width, h = height;
  for (;;) {
    MipLevel level;
    level.width = w;
    level.height = h;
    level.texels.resize(cur.size());
    for (size_t i = 0; i < cur.size(); ++i) level.texels[i] = to_unorm16(cur[i]);
    tex.levels.push_back(std::move(level));
    if ((w == 1 && h == 1) || !sampler.mipmaps) break;
    // Next level: 2x2 box filter in linear space; an odd last row/column is reused.
    const int nw = std::max(1, (w + 1) / 2), nh = std::max(1, (h + 1) / 2);
    std::vector<float> next(size_t(nw) * size_t(nh) * 4);
    for (int y = 0; y < nh; ++y)
      for (int x = 0; x < nw; ++x) {
        const int xs[2] = {std::min(2 * x, w - 1), std::min(2 * x + 1, w - 1)};
        const int ys[2] = {std::min(2 * y, h - 1), std::min(2 * y + 1, h - 1)};
        for (int c = 0; c < 4; ++c) {
          float sum = 0;
          for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i)
              sum += cur[(size_t(ys[j]) * size_t(w) + size_t(xs[i])) * 4 + size_t(c)];
          next[(size_t(y) * size_t(nw) + size_t(x)) * 4 + size_t(c)] = sum * 0.25f;
        }
      }
    cur = std::move(next);
    w = nw;
    h = nh;
  }
  return tex;
}

float texture_lod(const Texture& tex, Vec2f duvdx, Vec2f duvdy) {
  if (tex.levels.empty()) return 0;
  const float w = float(tex.levels[0].width), h = float(tex.levels[0].height);
  const float lx = std::hypot(duvdx.x * w, duvdx.y * h), ly = std::hypot(duvdy.x * w, duvdy.y * h);
  const float width = std::max(lx, ly);
  if (!(width > 0)) return -kInfinity;
  return std::log2(width);
}

Vec4f sample_texture(const Texture& tex, Vec2f uv, float lod) {
  if (tex.levels.empty()) return {1, 1, 1, 1};
  const TextureSampler& s = tex.sampler;
  if (!(lod > 0)) return sample_level(tex.levels[0], s, uv, s.mag);  // also NaN lod
  const int last = int(tex.levels.size()) - 1;
  if (!s.mipmaps || last == 0) return sample_level(tex.levels[0], s, uv, s.min);
  const float l = std::min(lod, float(last));
  if (s.mip == TextureFilter::Nearest) return sample_level(tex.levels[size_t(std::lround(l))], s, uv, s.min);
  const int l0 = std::min(int(l), last), l1 = std::min(l0 + 1, last);
  const float t = l - float(l0);
  const Vec4f a = sample_level(tex.levels[size_t(l0)], s, uv, s.min);
  if (t <= 0 || l1 == l0) return a;
  return lerp4(a, sample_level(tex.levels[size_t(l1)], s, uv, s.min), t);
}

}  // namespace penumbra
