// KHR_gaussian_splatting primitives; see splats.h.
#include "io/gltf/splats.h"

#include <tiny_gltf.h>

#include <cmath>

#include "io/gltf/accessors.h"

namespace penumbra::gltf {

namespace {

std::string attribute_name(const char* what) {
  return std::string(kGaussianSplatting) + ":" + what;
}

// The accessor of a required or optional attribute; -1 when absent.
int attribute(const tinygltf::Primitive& prim, const std::string& name) {
  const auto it = prim.attributes.find(name);
  return it == prim.attributes.end() ? -1 : it->second;
}

std::string element(const std::string& where, const std::string& name, size_t i) {
  return where + ".attributes." + name + "[" + std::to_string(i) + "]";
}

// The extension object's properties: kernel (unknown ones fall back to the ellipse), colorSpace
// (required, one of the two the extension defines), projection and sortingMethod (their
// defaults, or a warning).
SplatColorSpace read_properties(const GltfContext& ctx, const tinygltf::Value& ext, const std::string& at) {
  if (!ext.IsObject()) ctx.fail(at, "not an object");
  const auto text = [&](const char* key) -> std::string {
    if (!ext.Has(key)) return {};
    const tinygltf::Value& v = ext.Get(key);
    if (!v.IsString()) ctx.fail(at + "." + key, "not a string");
    return v.Get<std::string>();
  };
  const std::string kernel = text("kernel");
  if (kernel.empty())
    ctx.fail(at, "no kernel (the extension requires one; \"ellipse\" is its default kernel)");
  if (kernel != "ellipse")
    ctx.warn(at + ".kernel", "'" + kernel + "' is not known: rendered as the ellipse kernel");
  const std::string space = text("colorSpace");
  if (space.empty()) ctx.fail(at, "no colorSpace (srgb_rec709_display or lin_rec709_display)");
  if (space != "srgb_rec709_display" && space != "lin_rec709_display")
    ctx.fail(at + ".colorSpace", "'" + space + "' is not known (srgb_rec709_display or lin_rec709_display)");
  const std::string projection = text("projection");
  if (!projection.empty() && projection != "perspective")
    ctx.warn(at + ".projection", "'" + projection + "' is not known: projected in perspective");
  const std::string sorting = text("sortingMethod");
  if (!sorting.empty() && sorting != "cameraDistance")
    ctx.warn(at + ".sortingMethod", "'" + sorting + "' is not known: sorted by distance");
  return space == "lin_rec709_display" ? SplatColorSpace::LinRec709Display
                                       : SplatColorSpace::SrgbRec709Display;
}

// The highest spherical-harmonic degree whose coefficients are all present; every attribute of
// a higher degree, or a partial degree, is an error.
int sh_degree(const GltfContext& ctx, const tinygltf::Primitive& prim, const std::string& where) {
  int degree = -1;
  for (int l = 0; l <= 3; ++l) {
    int present = 0;
    for (int n = 0; n < 2 * l + 1; ++n)
      present +=
          attribute(
              prim,
              attribute_name(("SH_DEGREE_" + std::to_string(l) + "_COEF_" + std::to_string(n)).c_str())) >= 0;
    if (present == 0) break;
    if (present != 2 * l + 1)
      ctx.fail(where + ".attributes", "spherical-harmonic degree " + std::to_string(l) + " has " +
                                          std::to_string(present) + " of its " + std::to_string(2 * l + 1) +
                                          " coefficients (a degree is given whole)");
    degree = l;
  }
  for (const auto& [name, accessor] : prim.attributes) {
    (void)accessor;
    if (name.rfind(attribute_name("SH_DEGREE_"), 0) != 0) continue;
    const int l = name.size() > 33 ? name[33] - '0' : -1;  // "KHR_gaussian_splatting:SH_DEGREE_" is 33 long
    if (l > degree)
      ctx.fail(where + ".attributes." + name, l > 3 ? "not a spherical-harmonic coefficient of degree 0 to 3"
                                                    : "given without every coefficient of degree " +
                                                          std::to_string(degree + 1) +
                                                          (degree + 1 < l ? " and below" : ""));
  }
  if (degree < 0)
    ctx.fail(where + ".attributes", "no " + attribute_name("SH_DEGREE_0_COEF_0") + " (required)");
  return degree;
}

}  // namespace

bool has_splats(const tinygltf::Primitive& prim) {
  return prim.extensions.count(kGaussianSplatting) > 0;
}

SplatCloud read_splats(const GltfContext& ctx, const tinygltf::Primitive& prim, const std::string& where,
                       const std::vector<double>& positions) {
  const std::string at = where + ".extensions." + kGaussianSplatting;
  if (prim.mode != 0)
    ctx.fail(at, "on a primitive of mode " + std::to_string(prim.mode) + " (it needs POINTS, 0)");
  SplatCloud cloud;
  cloud.color_space = read_properties(ctx, prim.extensions.at(kGaussianSplatting), at);
  const size_t n = positions.size() / 3;
  cloud.positions.resize(n);
  for (size_t i = 0; i < n; ++i)
    cloud.positions[i] = {float(positions[3 * i]), float(positions[3 * i + 1]), float(positions[3 * i + 2])};
  const auto read = [&](const char* what, std::initializer_list<int> types,
                        std::initializer_list<int> components, bool normalized, bool integer, size_t width) {
    const std::string name = attribute_name(what);
    const int a = attribute(prim, name);
    if (a < 0) ctx.fail(where + ".attributes", "no " + name + " (required)");
    std::vector<double> v =
        read_accessor(ctx, a, where + ".attributes." + name, types, components, normalized, integer);
    if (v.size() != n * width) ctx.fail(where + ".attributes." + name, "count differs from POSITION count");
    return v;
  };
  constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT, kByte = TINYGLTF_COMPONENT_TYPE_BYTE,
                kShort = TINYGLTF_COMPONENT_TYPE_SHORT, kUByte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                kUShort = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  // Rotation: unit quaternions (x, y, z, w), float or normalised signed integers.
  const std::string rot = attribute_name("ROTATION");
  const std::vector<double> q =
      read("ROTATION", {TINYGLTF_TYPE_VEC4}, {kFloat, kByte, kShort}, true, false, 4);
  const bool quantised = ctx.model.accessors[size_t(attribute(prim, rot))].componentType != kFloat;
  cloud.rotations.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const double len = std::sqrt(q[4 * i] * q[4 * i] + q[4 * i + 1] * q[4 * i + 1] +
                                 q[4 * i + 2] * q[4 * i + 2] + q[4 * i + 3] * q[4 * i + 3]);
    if (!std::isfinite(len) || !(len > 0) || (!quantised && std::fabs(len - 1) > 0.01))
      ctx.fail(element(where, rot, i),
               "length " + std::to_string(len) + " (a rotation is a unit quaternion)");
    cloud.rotations[i] = {float(q[4 * i] / len), float(q[4 * i + 1] / len), float(q[4 * i + 2] / len),
                          float(q[4 * i + 3] / len)};
  }
  // Scale: linear standard deviations, >= 0.
  const std::string sc = attribute_name("SCALE");
  const std::vector<double> s = read("SCALE", {TINYGLTF_TYPE_VEC3}, {kFloat, kByte, kShort}, true, true, 3);
  cloud.scales.resize(n);
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(s[3 * i + size_t(k)]) || s[3 * i + size_t(k)] < 0 || s[3 * i + size_t(k)] > 1e18)
        ctx.fail(element(where, sc, i),
                 "scale " + std::to_string(s[3 * i + size_t(k)]) +
                     " is not a finite number >= 0 (scales are linear, not logarithmic)");
    cloud.scales[i] = {float(s[3 * i]), float(s[3 * i + 1]), float(s[3 * i + 2])};
  }
  // Opacity in [0, 1].
  const std::string op = attribute_name("OPACITY");
  const std::vector<double> o =
      read("OPACITY", {TINYGLTF_TYPE_SCALAR}, {kFloat, kUByte, kUShort}, true, false, 1);
  cloud.opacities.resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (!(o[i] >= 0 && o[i] <= 1))
      ctx.fail(element(where, op, i), "opacity " + std::to_string(o[i]) + " is not in [0, 1]");
    cloud.opacities[i] = float(o[i]);
  }
  // Spherical harmonics, degree by degree, coefficient by coefficient.
  cloud.sh_degree = sh_degree(ctx, prim, where);
  const int per = sh_coefficient_count(cloud.sh_degree);
  ctx.charge(uint64_t(n) * uint64_t(per) * 12, where, "the splats' spherical harmonics need");
  cloud.sh.resize(n * size_t(per));
  int c = 0;
  for (int l = 0; l <= cloud.sh_degree; ++l)
    for (int m = 0; m < 2 * l + 1; ++m, ++c) {
      const std::string what = "SH_DEGREE_" + std::to_string(l) + "_COEF_" + std::to_string(m);
      const std::vector<double> v = read(what.c_str(), {TINYGLTF_TYPE_VEC3}, {kFloat}, false, false, 3);
      for (size_t i = 0; i < n; ++i) {
        if (!std::isfinite(v[3 * i]) || !std::isfinite(v[3 * i + 1]) || !std::isfinite(v[3 * i + 2]))
          ctx.fail(element(where, attribute_name(what.c_str()), i), "NaN or infinite coefficient");
        cloud.sh[i * size_t(per) + size_t(c)] = {float(v[3 * i]), float(v[3 * i + 1]), float(v[3 * i + 2])};
      }
    }
  return cloud;
}

}  // namespace penumbra::gltf
