// Point and line sizes in pixels or scene units; see curve_size.h.
#include "renderer/scene/curve_size.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace penumbra {

namespace {
float linear_determinant(const Affine3f& a) {
  const auto& m = a.m;
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}
}  // namespace

CurveSize parse_curve_size(const std::string& text, const std::string& setting) {
  CurveSize out;
  std::string number = text;
  out.pixels = number.size() > 2 && number.compare(number.size() - 2, 2, "px") == 0;
  if (out.pixels) number.resize(number.size() - 2);
  size_t used = 0;
  double v = std::nan("");
  try {
    v = std::stod(number, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (number.empty() || used != number.size() || !(float(v / 2) > 0) || !std::isfinite(v) || v > 1e18)
    throw std::invalid_argument(setting + ": '" + text +
                                "' is not a positive size (a number of scene units, or of pixels "
                                "followed by px: 0.01, 2px)");
  out.value = float(v);
  return out;
}

float pixel_footprint(const Camera& camera, int height, Vec3f p) {
  if (camera.projection == Projection::Orthographic) return 2 * camera.ymag / float(height);
  const float depth = std::max({dot(p - camera.eye, -camera.w), camera.znear, 1e-6f});
  return 2 * depth * std::tan(0.5f * camera.yfov) / float(height);
}

void set_curve_radii(Scene& scene, const Camera& camera, int height, CurveSize points, CurveSize lines) {
  std::vector<int> first(scene.meshes.size(), -1);  // each mesh's first instance
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.shape < 0 && first[size_t(inst.mesh)] < 0) first[size_t(inst.mesh)] = int(i);
  }
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    Mesh& mesh = scene.meshes[m];
    if ((!mesh.points && !mesh.lines) || mesh.file_radii) continue;
    if (first[m] < 0) {
      mesh.radii.clear();
      continue;
    }
    const Instance& inst = scene.instances[size_t(first[m])];
    const CurveSize size = mesh.points ? points : lines;
    // Object-space lengths per world length: the placement's mean stretch.
    const float scale = inst.identity ? 1.0f : std::cbrt(std::fabs(linear_determinant(inst.to_world)));
    mesh.radii.resize(mesh.positions.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      float r = 0.5f * size.value;
      if (size.pixels) {
        const Vec3f p = inst.identity ? mesh.positions[i] : apply_point(inst.to_world, mesh.positions[i]);
        r *= is_finite(p) ? pixel_footprint(camera, height, p) : 0.0f;
      }
      mesh.radii[i] = scale > 0 && std::isfinite(scale) ? r / scale : 0.0f;
    }
  }
}

}  // namespace penumbra
