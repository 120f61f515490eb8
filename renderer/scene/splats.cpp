// Gaussian splats' closed forms; see splats.h.
#include "renderer/scene/splats.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

Mat3 quaternion_matrix(Vec4f q) {
  const double x = q.x, y = q.y, z = q.z, w = q.w;
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
           {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
           {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

Mat3 splat_covariance(const SplatCloud& cloud, size_t i) {
  const Mat3 r = quaternion_matrix(cloud.rotations[i]);
  const double s[3] = {cloud.scales[i].x, cloud.scales[i].y, cloud.scales[i].z};
  Mat3 c{};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int k = 0; k < 3; ++k)
        c[size_t(a)][size_t(b)] += r[size_t(a)][size_t(k)] * s[k] * s[k] * r[size_t(b)][size_t(k)];
  return c;
}

Vec3f splat_sh_color(const SplatCloud& cloud, size_t i, Vec3f dir) {
  const int n = sh_coefficient_count(cloud.sh_degree);
  const Vec3f* c = cloud.sh.data() + i * size_t(n);
  const float x = dir.x, y = dir.y, z = dir.z;
  Vec3f sum = c[0] * 0.2820947917738781f;
  if (cloud.sh_degree >= 1)
    sum = sum + c[1] * (-0.4886025119029199f * y) + c[2] * (0.4886025119029199f * z) +
          c[3] * (-0.4886025119029199f * x);
  if (cloud.sh_degree >= 2) {
    const float xx = x * x, yy = y * y, zz = z * z;
    sum = sum + c[4] * (1.092548430592079f * x * y) + c[5] * (-1.092548430592079f * y * z) +
          c[6] * (0.3153915652525200f * (2 * zz - xx - yy)) + c[7] * (-1.092548430592079f * x * z) +
          c[8] * (0.5462742152960395f * (xx - yy));
    if (cloud.sh_degree >= 3)
      sum = sum + c[9] * (-0.5900435899266435f * y * (3 * xx - yy)) +
            c[10] * (2.890611442640554f * x * y * z) +
            c[11] * (-0.4570457994644657f * y * (4 * zz - xx - yy)) +
            c[12] * (0.3731763325901154f * z * (2 * zz - 3 * xx - 3 * yy)) +
            c[13] * (-0.4570457994644657f * x * (4 * zz - xx - yy)) +
            c[14] * (1.445305721320277f * z * (xx - yy)) + c[15] * (-0.5900435899266435f * x * (xx - 3 * yy));
  }
  return {std::max(0.0f, sum.x + 0.5f), std::max(0.0f, sum.y + 0.5f), std::max(0.0f, sum.z + 0.5f)};
}

Vec3f splat_linear_color(SplatColorSpace space, Vec3f c) {
  if (space == SplatColorSpace::LinRec709Display) return c;
  const auto decode = [](float v) {
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
  };
  return {decode(c.x), decode(c.y), decode(c.z)};
}

bool splat_ray_response(const SplatCloud& cloud, size_t i, const Ray& ray, float& t_max, float& alpha) {
  alpha = 0;
  const Mat3 r = quaternion_matrix(cloud.rotations[i]);
  const double s[3] = {cloud.scales[i].x, cloud.scales[i].y, cloud.scales[i].z};
  if (!(s[0] > 0 && s[1] > 0 && s[2] > 0)) return false;
  const Vec3f mu = cloud.positions[i];
  const double o[3] = {double(ray.org.x) - mu.x, double(ray.org.y) - mu.y, double(ray.org.z) - mu.z};
  const double d[3] = {ray.dir.x, ray.dir.y, ray.dir.z};
  double ow[3], dw[3];  // S^-1 R^T (o - mu), S^-1 R^T d
  for (int k = 0; k < 3; ++k) {
    ow[k] = (r[0][size_t(k)] * o[0] + r[1][size_t(k)] * o[1] + r[2][size_t(k)] * o[2]) / s[k];
    dw[k] = (r[0][size_t(k)] * d[0] + r[1][size_t(k)] * d[1] + r[2][size_t(k)] * d[2]) / s[k];
  }
  const double dd = dw[0] * dw[0] + dw[1] * dw[1] + dw[2] * dw[2];
  if (!(dd > 0)) return false;
  const double t = -(ow[0] * dw[0] + ow[1] * dw[1] + ow[2] * dw[2]) / dd;
  double m2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double v = ow[k] + t * dw[k];
    m2 += v * v;
  }
  t_max = float(t);
  alpha = float(cloud.opacities[i] * std::exp(-0.5 * m2));
  return std::isfinite(t_max) && std::isfinite(alpha);
}

Bounds3f splat_bounds(const SplatCloud& cloud, size_t i, float sigmas) {
  // The extent of the ellipsoid along world axis a: sigmas sqrt(sum_k (R_ak s_k)^2).
  const Mat3 r = quaternion_matrix(cloud.rotations[i]);
  const double s[3] = {cloud.scales[i].x, cloud.scales[i].y, cloud.scales[i].z};
  Vec3f half;
  for (int a = 0; a < 3; ++a) {
    double e = 0;
    for (int k = 0; k < 3; ++k) e += (r[size_t(a)][size_t(k)] * s[k]) * (r[size_t(a)][size_t(k)] * s[k]);
    half[a] = float(sigmas * std::sqrt(e));
  }
  const Vec3f c = cloud.positions[i];
  return {c - half, c + half};
}

}  // namespace penumbra
