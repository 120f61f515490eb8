// Gaussian splats' closed forms; see splats.h.
#include "renderer/scene/splats.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

Shape splat_shape(const SplatCloud& cloud, size_t i, uint32_t element) {
  return make_splat_shape(cloud.positions[i], cloud.rotations[i], cloud.scales[i], cloud.opacities[i],
                          element);
}

bool splat_ray_response(const SplatCloud& cloud, size_t i, const Ray& ray, float& t_max, float& alpha) {
  alpha = 0;
  const Shape s = splat_shape(cloud, i, uint32_t(i));
  double t = 0, m2 = 0, a = 0;
  if (!(s.half_size.x >= 0) || !splat_response(s, ray, t, m2, a)) return false;
  t_max = float(t);
  alpha = float(a);
  return std::isfinite(t_max) && std::isfinite(alpha);
}

Bounds3f splat_bounds(const SplatCloud& cloud, size_t i) {
  return shape_bounds(splat_shape(cloud, i, uint32_t(i)));
}

Vec3f fibonacci_direction(int i, int n) {
  const double golden = 3.14159265358979323846 * (3 - std::sqrt(5.0));
  const double y = 1 - 2 * (i + 0.5) / n, r = std::sqrt(std::max(0.0, 1 - y * y)), phi = golden * i;
  return {float(r * std::cos(phi)), float(y), float(r * std::sin(phi))};
}

SplatCloud make_splat_sphere(const SplatSphereConfig& c) {
  if (!(c.radius > 0) || !std::isfinite(c.radius) || c.count < 1 || !(c.tangent_scale >= 0) ||
      !(c.normal_scale >= 0) || !(c.opacity >= 0 && c.opacity <= 1) || !is_finite(c.centre))
    throw std::invalid_argument("splat sphere: radius > 0, count >= 1, scales >= 0, opacity in [0, 1]");
  const float spacing = std::sqrt(4 * 3.14159265f * c.radius * c.radius / float(c.count));
  const float st = c.tangent_scale > 0 ? c.tangent_scale : 0.6f * spacing;
  const float sn = c.normal_scale > 0 ? c.normal_scale : st / 10;
  SplatCloud cloud;
  cloud.name = "splat sphere";
  cloud.color_space = SplatColorSpace::LinRec709Display;
  for (int i = 0; i < c.count; ++i) {
    const Vec3f n = fibonacci_direction(i, c.count);
    cloud.positions.push_back(c.centre + n * c.radius);
    // The rotation taking +z to n: axis z x n = (-n.y, n.x, 0), half-angle form (1 + n.z, axis).
    Vec4f q{-n.y, n.x, 0, 1 + n.z};
    const float len = std::sqrt(q.x * q.x + q.y * q.y + q.w * q.w);
    q = len > 1e-6f ? Vec4f{q.x / len, q.y / len, 0, q.w / len} : Vec4f{1, 0, 0, 0};
    cloud.rotations.push_back(q);
    cloud.scales.push_back({st, st, sn});
    cloud.opacities.push_back(c.opacity);
    cloud.sh.push_back(n * (0.5f / 0.2820947917738781f));
  }
  return cloud;
}

}  // namespace penumbra
