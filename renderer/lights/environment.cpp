// Environment light: lookup and importance sampling.
#include "renderer/lights/environment.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "renderer/core/rng.h"

namespace penumbra {

namespace {
// Index of the bin of a CDF (n + 1 entries, cdf[0] = 0, cdf[n] = 1) that holds u, and the
// offset of u inside it in [0, 1).
int find_bin(const float* cdf, int n, float u, float& t) {
  const float* it = std::upper_bound(cdf, cdf + n + 1, u);
  int i = std::clamp(int(it - cdf) - 1, 0, n - 1);
  while (i > 0 && !(cdf[i + 1] > cdf[i]) && u >= cdf[i]) --i;  // never land in an empty bin
  while (i < n - 1 && !(cdf[i + 1] > cdf[i])) ++i;
  const float c0 = cdf[i], c1 = cdf[i + 1];
  t = c1 > c0 ? std::clamp((u - c0) / (c1 - c0), 0.0f, 0x1.fffffep-1f) : 0.5f;
  return i;
}
}  // namespace

Environment make_constant_environment(Vec3f radiance) {
  Environment e;
  e.color = radiance;
  return e;
}

Environment make_map_environment(int width, int height, std::vector<Vec3f> texels, float intensity,
                                 float rotation) {
  if (width < 1 || height < 1 || texels.size() != size_t(width) * size_t(height))
    throw std::invalid_argument("environment map: size does not match its texels");
  if (!std::isfinite(intensity) || intensity < 0 || !std::isfinite(rotation))
    throw std::invalid_argument("environment map: intensity and rotation must be finite, intensity >= 0");
  Environment e;
  e.width = width;
  e.height = height;
  e.texels = std::move(texels);
  e.intensity = intensity;
  e.rotation = rotation;
  for (auto& t : e.texels)
    if (!is_finite(t) || t.x < 0 || t.y < 0 || t.z < 0) t = {0, 0, 0};  // callers validate; stay safe
  const size_t w = size_t(width), h = size_t(height);
  e.conditional_cdf.assign(h * (w + 1), 0.0f);
  e.marginal_cdf.assign(h + 1, 0.0f);
  std::vector<double> row_sum(h, 0.0);
  for (size_t y = 0; y < h; ++y) {
    const double sin_theta = std::sin(kPi * (double(y) + 0.5) / double(h));
    double acc = 0;
    float* cdf = &e.conditional_cdf[y * (w + 1)];
    std::vector<double> c(w + 1, 0.0);
    for (size_t x = 0; x < w; ++x) {
      acc += double(std::max(0.0f, luminance(e.texels[y * w + x]))) * sin_theta;
      c[x + 1] = acc;
    }
    for (size_t x = 0; x <= w; ++x) cdf[x] = acc > 0 ? float(c[x] / acc) : float(x) / float(w);
    cdf[w] = 1;
    row_sum[y] = acc;
  }
  double total = 0;
  for (size_t y = 0; y < h; ++y) total += row_sum[y];
  double acc = 0;
  for (size_t y = 0; y < h; ++y) {
    acc += row_sum[y];
    e.marginal_cdf[y + 1] = total > 0 ? float(acc / total) : float(y + 1) / float(h);
  }
  e.marginal_cdf[h] = 1;
  // Density in the uv square: P(texel) / (1 / (w h)).
  e.texel_pdf.assign(w * h, 0.0f);
  e.map_emits = total > 0;
  if (total > 0)
    for (size_t y = 0; y < h; ++y) {
      const double sin_theta = std::sin(kPi * (double(y) + 0.5) / double(h));
      for (size_t x = 0; x < w; ++x)
        e.texel_pdf[y * w + x] =
            float(double(std::max(0.0f, luminance(e.texels[y * w + x]))) * sin_theta / total * double(w * h));
    }
  return e;
}

bool is_black(const Environment& env) {
  if (env.texels.empty()) return !(max_component(env.color) > 0);
  return !(env.intensity > 0) || !env.map_emits;
}

Vec2f env_direction_to_uv(const Environment& env, Vec3f d) {
  // Undo the rotation about +Y, then phi measured from -Z towards +X.
  const float c = std::cos(env.rotation), s = std::sin(env.rotation);
  const Vec3f l{c * d.x - s * d.z, d.y, s * d.x + c * d.z};
  const float phi = std::atan2(l.x, -l.z);
  const float theta = std::acos(std::clamp(l.y, -1.0f, 1.0f));
  return {0.5f + phi / (2 * kPi), theta / kPi};
}

namespace {

// v rotated by the conjugate of unit quaternion q (x, y, z, w): v' = v + 2 u x (u x v - w v),
// u = -(x, y, z).
Vec3f rotate_inverse(Vec4f q, Vec3f v) {
  const Vec3f u{-q.x, -q.y, -q.z};
  const Vec3f t = cross(u, v) * 2;
  return v + t * q.w + cross(u, t);
}

// The cube face and its texel for direction d (OpenGL's major-axis rule).
Vec3f cube_lookup(const std::vector<Vec3f> (&faces)[6], int n, Vec3f d) {
  const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  int face;
  float sc, tc, ma;
  if (ax >= ay && ax >= az) {
    face = d.x > 0 ? 0 : 1;
    sc = d.x > 0 ? -d.z : d.z;
    tc = -d.y;
    ma = ax;
  } else if (ay >= az) {
    face = d.y > 0 ? 2 : 3;
    sc = d.x;
    tc = d.y > 0 ? d.z : -d.z;
    ma = ay;
  } else {
    face = d.z > 0 ? 4 : 5;
    sc = d.z > 0 ? d.x : -d.x;
    tc = -d.y;
    ma = az;
  }
  const float s = 0.5f * (sc / ma + 1), t = 0.5f * (tc / ma + 1);
  const int x = std::clamp(int(s * float(n)), 0, n - 1), y = std::clamp(int(t * float(n)), 0, n - 1);
  return faces[face][size_t(y) * size_t(n) + size_t(x)];
}

}  // namespace

std::vector<Vec3f> equirect_from_cube(const std::vector<Vec3f> (&faces)[6], int face_size, int width,
                                      int height, Vec4f rotation) {
  Environment frame;  // the convention's axes, unrotated
  std::vector<Vec3f> out(size_t(width) * size_t(height));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Vec3f d =
          env_uv_to_direction(frame, {(float(x) + 0.5f) / float(width), (float(y) + 0.5f) / float(height)});
      out[size_t(y) * size_t(width) + size_t(x)] = cube_lookup(faces, face_size, rotate_inverse(rotation, d));
    }
  return out;
}

Vec3f env_uv_to_direction(const Environment& env, Vec2f uv) {
  const float phi = (uv.x - 0.5f) * 2 * kPi, theta = uv.y * kPi;
  const float st = std::sin(theta);
  const Vec3f l{st * std::sin(phi), std::cos(theta), -st * std::cos(phi)};
  const float c = std::cos(env.rotation), s = std::sin(env.rotation);
  return {c * l.x + s * l.z, l.y, -s * l.x + c * l.z};
}

namespace {
size_t texel_index(const Environment& env, Vec2f uv) {
  const int x = std::clamp(int(uv.x * float(env.width)), 0, env.width - 1);
  const int y = std::clamp(int(uv.y * float(env.height)), 0, env.height - 1);
  return size_t(y) * size_t(env.width) + size_t(x);
}
}  // namespace

Vec3f env_eval(const Environment& env, Vec3f dir) {
  if (env.texels.empty()) return env.color;
  const Vec2f uv = env_direction_to_uv(env, dir);
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return {0, 0, 0};
  return env.texels[texel_index(env, uv)] * env.intensity;
}

float env_pdf(const Environment& env, Vec3f dir) {
  if (is_black(env)) return 0;
  if (env.texels.empty()) return 1 / (4 * kPi);
  const Vec2f uv = env_direction_to_uv(env, dir);
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return 0;
  const float sin_theta = std::sin(uv.y * kPi);
  if (!(sin_theta > 0)) return 0;
  return env.texel_pdf[texel_index(env, uv)] / (2 * kPi * kPi * sin_theta);
}

bool env_sample(const Environment& env, Vec2f u, Vec3f& dir, Vec3f& radiance, float& pdf) {
  if (is_black(env)) return false;
  if (env.texels.empty()) {
    dir = sample_uniform_sphere(u);
    radiance = env.color;
    pdf = 1 / (4 * kPi);
    return true;
  }
  float ty = 0, tx = 0;
  const int y = find_bin(env.marginal_cdf.data(), env.height, u.y, ty);
  const int x = find_bin(&env.conditional_cdf[size_t(y) * size_t(env.width + 1)], env.width, u.x, tx);
  const Vec2f uv{(float(x) + tx) / float(env.width), (float(y) + ty) / float(env.height)};
  dir = env_uv_to_direction(env, uv);
  // Look the direction up again so that sampling, env_eval and env_pdf agree exactly even
  // where rounding moves a direction across a texel border.
  radiance = env_eval(env, dir);
  pdf = env_pdf(env, dir);
  if (!(pdf > 0) || !std::isfinite(pdf)) return false;
  return true;
}

}  // namespace penumbra
