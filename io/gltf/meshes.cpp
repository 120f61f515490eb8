// Meshes: each primitive decoded in steps (mode and material, indices and topology, vertex
// attributes, validation, morph targets, skinning, texture coordinates, tangents and colours),
// then each mesh use placed as world-space copies or instances of one object-space copy.
#include "io/gltf/meshes.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "io/gltf/accessors.h"
#include "io/gltf/splats.h"

namespace penumbra::gltf {

namespace {

// KHR_mesh_quantization's component types: any integer type, normalized or not (positions,
// texture coordinates), or signed normalized integers (normals, tangents).
constexpr std::initializer_list<int> kQuantizedAny = {
    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
    TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT};
constexpr std::initializer_list<int> kQuantizedDirection = {
    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT};

// True if the file declares KHR_mesh_quantization (then attributes may be integers).
bool uses_quantization(const GltfContext& ctx) {
  const auto& used = ctx.model.extensionsUsed;
  return std::find(used.begin(), used.end(), "KHR_mesh_quantization") != used.end();
}

float finite_or_zero(double v) {
  return std::isfinite(v) ? float(v) : 0.0f;
}

// The material of the selected KHR_materials_variants variant for `prim`, else `material`.
int variant_material(const GltfContext& ctx, const tinygltf::Primitive& prim, const std::string& where,
                     int material) {
  const int variant = ctx.out.info.variant;
  const auto it = prim.extensions.find("KHR_materials_variants");
  if (variant < 0 || it == prim.extensions.end()) return material;
  const std::string mw = where + ".extensions.KHR_materials_variants.mappings";
  const auto& mappings = it->second.Get("mappings");
  if (!mappings.IsArray()) ctx.fail(mw, "must be an array");
  for (size_t i = 0; i < mappings.ArrayLen(); ++i) {
    const auto& m = mappings.Get(int(i));
    const std::string w = mw + "[" + std::to_string(i) + "]";
    const auto& variants = m.Get("variants");
    if (!m.Get("material").IsInt() || !variants.IsArray()) ctx.fail(w, "needs a material and variants");
    const int mat = m.Get("material").GetNumberAsInt();
    if (mat < 0 || mat >= int(ctx.model.materials.size()))
      ctx.fail(w + ".material", "material index " + std::to_string(mat) + " out of range (" +
                                    std::to_string(ctx.model.materials.size()) + " materials)");
    for (size_t k = 0; k < variants.ArrayLen(); ++k) {
      const auto& v = variants.Get(int(k));
      if (!v.IsInt() || v.GetNumberAsInt() < 0 || v.GetNumberAsInt() >= int(ctx.out.info.variants.size()))
        ctx.fail(w + ".variants", "variant index out of range (" +
                                      std::to_string(ctx.out.info.variants.size()) + " variants)");
      if (v.GetNumberAsInt() == variant) return mat;
    }
  }
  return material;
}

// The vertex attributes of a primitive as read, before conversion.
struct RawAttributes {
  std::vector<double> pos, nrm, uv, uv1, tan, col;
  int col_components = 0;
};

// The triangle list of a primitive (glTF spec 3.7.2.1, "Topology Types") from its indices, or
// 0..nv-1 without, each index checked against the vertex count.
std::vector<uint32_t> triangle_list(const GltfContext& ctx, const tinygltf::Primitive& prim,
                                    const std::string& where, size_t nv) {
  std::vector<uint32_t> raw;
  if (prim.indices >= 0 || prim.indices < -1) {
    raw = read_indices(ctx, prim.indices, where + ".indices");
    for (uint32_t i : raw)
      if (i >= nv) ctx.fail(where, "index " + std::to_string(i) + " >= vertex count " + std::to_string(nv));
  } else {
    raw.resize(nv);
    for (size_t i = 0; i < nv; ++i) raw[i] = uint32_t(i);
  }
  std::vector<uint32_t> tris;
  if (prim.mode == 4) {
    if (raw.size() % 3)
      ctx.warn(where,
               "index count " + std::to_string(raw.size()) + " not a multiple of 3; extra indices ignored");
    tris.assign(raw.begin(), raw.begin() + ptrdiff_t(raw.size() / 3 * 3));
  } else if (prim.mode == 5) {
    for (size_t i = 0; i + 2 < raw.size(); ++i) {
      const bool odd = i % 2;
      tris.insert(tris.end(), {raw[i], raw[i + (odd ? 2 : 1)], raw[i + (odd ? 1 : 2)]});
    }
  } else if (prim.mode == 0) {
    ctx.charge(uint64_t(raw.size()) * 12, where, "a point set's degenerate triangles need");
    tris.reserve(raw.size() * 3);
    for (uint32_t i : raw) tris.insert(tris.end(), {i, i, i});
  } else if (prim.mode >= 1 && prim.mode <= 3) {
    // LINES pairs its indices; LINE_STRIP joins each to the next; LINE_LOOP closes the strip.
    const char* kind = prim.mode == 1 ? "LINES" : (prim.mode == 2 ? "LINE_LOOP" : "LINE_STRIP");
    const std::string count = std::to_string(raw.size()) + (prim.indices >= 0 ? " indices" : " vertices");
    if (prim.mode == 1 && raw.size() % 2)
      ctx.fail(where, std::string(kind) + " with an odd count (" + count + "): every segment needs two");
    if (prim.mode != 1 && raw.size() == 1)
      ctx.fail(where, std::string(kind) + " with one vertex: a line needs at least two");
    const size_t segments =
        prim.mode == 1 ? raw.size() / 2 : (raw.size() < 2 ? 0 : raw.size() - 1 + (prim.mode == 2 ? 1 : 0));
    ctx.charge(uint64_t(segments) * 12, where, "a line set's segments need");
    tris.reserve(segments * 3);
    for (size_t s = 0; s < segments; ++s) {
      const uint32_t a = prim.mode == 1 ? raw[2 * s] : raw[s];
      const uint32_t b = prim.mode == 1 ? raw[2 * s + 1] : raw[(s + 1) % raw.size()];
      tris.insert(tris.end(), {a, b, b});
    }
  } else {
    for (size_t i = 1; i + 1 < raw.size(); ++i) tris.insert(tris.end(), {raw[i], raw[i + 1], raw[0]});
  }
  return tris;
}

// NORMAL, TEXCOORD_0/1, TANGENT and COLOR_0, each with the POSITION count; all are read before
// anything is dropped, so a malformed one is an error even on a primitive that is skipped.
void read_vertex_attributes(const GltfContext& ctx, const tinygltf::Primitive& prim, const std::string& where,
                            size_t nv, RawAttributes& raw) {
  const bool quantized = uses_quantization(ctx);
  if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
    raw.nrm = quantized ? read_accessor(ctx, it->second, where + ".attributes.NORMAL", {TINYGLTF_TYPE_VEC3},
                                        kQuantizedDirection, true)
                        : read_accessor(ctx, it->second, where + ".attributes.NORMAL", {TINYGLTF_TYPE_VEC3},
                                        {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
    if (raw.nrm.size() != raw.pos.size())
      ctx.fail(where + ".attributes.NORMAL", "count differs from POSITION count");
  }
  for (const char* name : {"TEXCOORD_0", "TEXCOORD_1"}) {
    auto it = prim.attributes.find(name);
    if (it == prim.attributes.end()) continue;
    auto& dst = name[9] == '0' ? raw.uv : raw.uv1;
    dst = quantized ? read_accessor(ctx, it->second, where + ".attributes." + name, {TINYGLTF_TYPE_VEC2},
                                    kQuantizedAny, true, true)
                    : read_accessor(ctx, it->second, where + ".attributes." + name, {TINYGLTF_TYPE_VEC2},
                                    {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                                    true);
    if (dst.size() / 2 != nv) ctx.fail(where + ".attributes." + name, "count differs from POSITION count");
  }
  if (auto it = prim.attributes.find("TANGENT"); it != prim.attributes.end()) {
    raw.tan = quantized ? read_accessor(ctx, it->second, where + ".attributes.TANGENT", {TINYGLTF_TYPE_VEC4},
                                        kQuantizedDirection, true)
                        : read_accessor(ctx, it->second, where + ".attributes.TANGENT", {TINYGLTF_TYPE_VEC4},
                                        {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
    if (raw.tan.size() / 4 != nv)
      ctx.fail(where + ".attributes.TANGENT", "count differs from POSITION count");
  }
  if (auto it = prim.attributes.find("COLOR_0"); it != prim.attributes.end()) {
    raw.col = read_accessor(ctx, it->second, where + ".attributes.COLOR_0",
                            {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4},
                            {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                            true);
    raw.col_components = ctx.model.accessors[size_t(it->second)].type == TINYGLTF_TYPE_VEC4 ? 4 : 3;
    if (raw.col.size() / size_t(raw.col_components) != nv)
      ctx.fail(where + ".attributes.COLOR_0", "count differs from POSITION count");
  }
}

// Positions (false: NaN, infinite or huge, the primitive is dropped with a warning) and normals
// (cleared with a warning if any is zero or not finite; smooth normals are computed later).
bool convert_positions_and_normals(const GltfContext& ctx, const RawAttributes& raw, const std::string& where,
                                   size_t nv, LocalPrimitive& out) {
  out.positions.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    out.positions[i] = {float(raw.pos[i * 3]), float(raw.pos[i * 3 + 1]), float(raw.pos[i * 3 + 2])};
    if (!is_finite(out.positions[i]) || max_component(abs(out.positions[i])) > 1e18f) {
      ctx.warn(where, "POSITION has NaN, infinite or huge (> 1e18) values; primitive dropped");
      return false;
    }
  }
  if (raw.nrm.empty()) return true;
  out.normals.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    out.normals[i] = {float(raw.nrm[i * 3]), float(raw.nrm[i * 3 + 1]), float(raw.nrm[i * 3 + 2])};
    if (!is_finite(out.normals[i]) || !(dot(out.normals[i], out.normals[i]) > 0)) {
      ctx.warn(where + ".attributes.NORMAL",
               "zero, NaN or infinite normals; computing smooth normals instead");
      out.normals.clear();
      break;
    }
  }
  return true;
}

// Morph targets: POSITION and NORMAL displacements (glTF 3.7.2.2); non-finite deltas are 0.
void read_morph_targets(const GltfContext& ctx, const tinygltf::Primitive& prim, const std::string& where,
                        size_t nv, LocalPrimitive& out) {
  for (size_t ti = 0; ti < prim.targets.size(); ++ti) {
    const std::string tw = where + "." + idx("targets", ti);
    std::vector<Vec3f> dp(nv), dn;
    for (const auto& [name, accessor] : prim.targets[ti]) {
      if (name != "POSITION" && name != "NORMAL") continue;
      const auto d = read_accessor(
          ctx, accessor, tw + "." + name, {TINYGLTF_TYPE_VEC3},
          {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT}, true,
          uses_quantization(ctx) && name == "POSITION");
      if (d.size() != nv * 3) ctx.fail(tw + "." + name, "count differs from POSITION count");
      auto& dst = name == "POSITION" ? dp : dn;
      dst.resize(nv);
      for (size_t i = 0; i < nv; ++i)
        dst[i] = {finite_or_zero(d[i * 3]), finite_or_zero(d[i * 3 + 1]), finite_or_zero(d[i * 3 + 2])};
    }
    out.target_positions.push_back(std::move(dp));
    out.target_normals.push_back(std::move(dn));
  }
}

// Skinning attributes (glTF 3.7.3): JOINTS_0 with WEIGHTS_0, both or neither.
void read_skin_attributes(const GltfContext& ctx, const tinygltf::Primitive& prim, const std::string& where,
                          size_t nv, LocalPrimitive& out) {
  const auto jt = prim.attributes.find("JOINTS_0"), wt = prim.attributes.find("WEIGHTS_0");
  if (jt == prim.attributes.end() || wt == prim.attributes.end()) return;
  const auto j = read_accessor(
      ctx, jt->second, where + ".attributes.JOINTS_0", {TINYGLTF_TYPE_VEC4},
      {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}, false, true);
  const auto w = read_accessor(ctx, wt->second, where + ".attributes.WEIGHTS_0", {TINYGLTF_TYPE_VEC4},
                               {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                               true);
  if (j.size() != nv * 4 || w.size() != nv * 4)
    ctx.fail(where + ".attributes.JOINTS_0", "JOINTS_0/WEIGHTS_0 counts differ from POSITION count");
  out.joints.resize(nv);
  out.weights.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    for (size_t c = 0; c < 4; ++c) out.joints[i][c] = uint16_t(j[i * 4 + c]);
    out.weights[i] = {finite_or_zero(w[i * 4]), finite_or_zero(w[i * 4 + 1]), finite_or_zero(w[i * 4 + 2]),
                      finite_or_zero(w[i * 4 + 3])};
  }
}

// Texture coordinates, tangents (cleared with a warning if any is unusable) and colours in [0,1].
void convert_surface_attributes(const GltfContext& ctx, const RawAttributes& raw, const std::string& where,
                                size_t nv, LocalPrimitive& out) {
  if (!raw.uv.empty()) {
    out.uvs.resize(nv);
    for (size_t i = 0; i < nv; ++i)
      out.uvs[i] = {finite_or_zero(raw.uv[i * 2]), finite_or_zero(raw.uv[i * 2 + 1])};
  }
  if (!raw.uv1.empty()) {
    out.uvs1.resize(nv);
    for (size_t i = 0; i < nv; ++i)
      out.uvs1[i] = {finite_or_zero(raw.uv1[i * 2]), finite_or_zero(raw.uv1[i * 2 + 1])};
  }
  if (!raw.tan.empty()) {
    out.tangents.resize(nv);
    for (size_t i = 0; i < nv; ++i) {
      const Vec3f t{float(raw.tan[i * 4]), float(raw.tan[i * 4 + 1]), float(raw.tan[i * 4 + 2])};
      if (!is_finite(t) || !(dot(t, t) > 0) || !std::isfinite(raw.tan[i * 4 + 3])) {
        ctx.warn(where + ".attributes.TANGENT",
                 "zero, NaN or infinite tangents; generating tangents instead");
        out.tangents.clear();
        break;
      }
      out.tangents[i] = {t.x, t.y, t.z, raw.tan[i * 4 + 3] < 0 ? -1.0f : 1.0f};
    }
  }
  if (!raw.col.empty()) {
    out.colors.resize(nv);
    const size_t k = size_t(raw.col_components);
    for (size_t i = 0; i < nv; ++i) {
      auto c = [&](size_t j) { return std::clamp(finite_or_zero(raw.col[i * k + j]), 0.0f, 1.0f); };
      out.colors[i] = {c(0), c(1), c(2), k == 4 ? c(3) : 1.0f};
    }
  }
}

// The radii of a point or line primitive from PENUMBRA_points: half the per-vertex "_WIDTH"
// attribute, else half the extension's "width" for every vertex; empty without either.
std::vector<float> read_widths(const GltfContext& ctx, const tinygltf::Primitive& prim,
                               const std::string& where, size_t nv) {
  std::vector<float> radii;
  if (auto it = prim.attributes.find("_WIDTH"); it != prim.attributes.end()) {
    const std::string at = where + ".attributes._WIDTH";
    const std::vector<double> w =
        read_accessor(ctx, it->second, at, {TINYGLTF_TYPE_SCALAR}, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
    if (w.size() != nv) ctx.fail(at, "count differs from POSITION count");
    radii.resize(nv);
    for (size_t i = 0; i < nv; ++i) {
      if (!(float(w[i] / 2) > 0) || !std::isfinite(w[i]) || w[i] > 1e18)
        ctx.fail(at, "width " + std::to_string(w[i]) + " of vertex " + std::to_string(i) +
                         " is not a finite positive number");
      radii[i] = float(w[i] / 2);
    }
    return radii;
  }
  const auto ext = prim.extensions.find(kPointsExtension);
  if (ext == prim.extensions.end()) return radii;
  const std::string at = where + ".extensions." + kPointsExtension;
  if (!ext->second.IsObject()) ctx.fail(at, "not an object");
  for (const std::string& key : ext->second.Keys())
    if (key != "width") ctx.fail(at, "unknown key '" + key + "' (known: width)");
  if (!ext->second.Has("width")) return radii;
  const tinygltf::Value& v = ext->second.Get("width");
  const double w = v.IsNumber() ? v.GetNumberAsDouble() : std::nan("");
  if (!(float(w / 2) > 0) || !std::isfinite(w) || w > 1e18)
    ctx.fail(at + ".width", "not a finite positive number");
  radii.assign(nv, float(w / 2));
  return radii;
}

LocalPrimitive decode_primitive(const GltfContext& ctx, size_t mesh_index, size_t pi) {
  const auto& prim = ctx.model.meshes[mesh_index].primitives[pi];
  const std::string where = idx("meshes", mesh_index) + "." + idx("primitives", pi);
  LocalPrimitive out;
  // Mode and material.
  if (prim.mode < 0 || prim.mode > 6) ctx.fail(where, "invalid mode " + std::to_string(prim.mode));
  out.points = prim.mode == 0;
  out.lines = prim.mode >= 1 && prim.mode <= 3;
  if (prim.material < -1 || prim.material >= int(ctx.model.materials.size()))
    ctx.fail(where + ".material", "material index " + std::to_string(prim.material) + " out of range (" +
                                      std::to_string(ctx.model.materials.size()) + " materials)");
  out.material = variant_material(ctx, prim, where, prim.material);
  // Positions, then indices and topology, then the other attributes.
  const auto pos_it = prim.attributes.find("POSITION");
  if (pos_it == prim.attributes.end()) {
    if (out.points || out.lines)
      ctx.fail(where,
               std::string(out.points ? "POINTS" : "a lines primitive") + " without a POSITION attribute");
    ctx.warn(where, "no POSITION attribute; skipped");
    return out;
  }
  RawAttributes raw;
  raw.pos = uses_quantization(ctx)
                ? read_accessor(ctx, pos_it->second, where + ".attributes.POSITION", {TINYGLTF_TYPE_VEC3},
                                kQuantizedAny, true, true)
                : read_accessor(ctx, pos_it->second, where + ".attributes.POSITION", {TINYGLTF_TYPE_VEC3},
                                {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
  const size_t nv = raw.pos.size() / 3;
  if (nv >= 0xffffffffu) ctx.fail(where, "too many vertices");
  out.indices = triangle_list(ctx, prim, where, nv);
  read_vertex_attributes(ctx, prim, where, nv, raw);
  if (out.points || out.lines) out.radii = read_widths(ctx, prim, where, nv);
  if (has_splats(prim)) {
    out.splats = read_splats(ctx, prim, where, raw.pos);
    out.splats->mesh = int(mesh_index);
    out.splats->primitive = int(pi);
    out.splats->name = idx("meshes", mesh_index) + "[" + std::to_string(pi) + "]";
    return out;  // rendered as splats: the extension's fallback points are not needed
  }
  if (out.indices.empty()) {
    ctx.warn(where,
             out.points ? "no points; skipped" : (out.lines ? "no lines; skipped" : "no triangles; skipped"));
    return out;
  }
  // Validation and conversion.
  if (!convert_positions_and_normals(ctx, raw, where, nv, out)) return out;
  read_morph_targets(ctx, prim, where, nv, out);
  read_skin_attributes(ctx, prim, where, nv, out);
  convert_surface_attributes(ctx, raw, where, nv, out);
  out.usable = true;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Placement.

// Where primitives go: world-space meshes with identity instances (object_ids == nullptr), or
// object-space meshes appended without instances, their indices recorded in *object_ids.
struct Emit {
  int mesh = -1, node = -1;  // node -1: the object-space copy of an instanced mesh
  const std::vector<double>* morph = nullptr;
  const std::vector<Transform>* joint_mats = nullptr;  // empty: not skinned
  std::vector<int>* object_ids = nullptr;
};

// Local positions and normals with the morph weights applied.
void morph(const LocalPrimitive& local, const std::vector<double>& weights, std::vector<Vec3f>& lp,
           std::vector<Vec3f>& ln) {
  lp = local.positions;
  ln = local.normals;
  for (size_t t = 0; t < local.target_positions.size() && t < weights.size(); ++t) {
    const float w = float(weights[t]);
    if (w == 0 || !std::isfinite(w)) continue;
    for (size_t i = 0; i < lp.size(); ++i) lp[i] += local.target_positions[t][i] * w;
    if (!ln.empty() && !local.target_normals[t].empty())
      for (size_t i = 0; i < ln.size(); ++i) ln[i] += local.target_normals[t][i] * w;
  }
}

// Per-vertex transforms of a skinned primitive: the weight-normalised blend of its joint
// matrices, `world` where all weights are 0.
std::vector<Transform> skin_transforms(const GltfContext& ctx, const LocalPrimitive& local,
                                       const std::vector<Transform>& joint_mats, const Transform& world,
                                       const std::string& where) {
  std::vector<Transform> vertex_xf(local.positions.size());
  for (size_t i = 0; i < vertex_xf.size(); ++i) {
    Transform b;
    b.m = {};
    const float wsum = local.weights[i].x + local.weights[i].y + local.weights[i].z + local.weights[i].w;
    const float wk[4] = {local.weights[i].x, local.weights[i].y, local.weights[i].z, local.weights[i].w};
    for (size_t k = 0; k < 4; ++k) {
      if (wk[k] == 0) continue;
      const size_t j = local.joints[i][k];
      if (j >= joint_mats.size())
        ctx.fail(where + ".attributes.JOINTS_0",
                 "joint " + std::to_string(j) + " >= skin joint count " + std::to_string(joint_mats.size()));
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
          b.m[size_t(r)][size_t(c)] +=
              double(wk[k] / (wsum > 0 ? wsum : 1)) * joint_mats[j].m[size_t(r)][size_t(c)];
    }
    vertex_xf[i] = wsum > 0 ? b : world;
  }
  return vertex_xf;
}

// Tangents only where a normal map (the base's or the clear coat's) or anisotropy needs them:
// the file's (to world space; a mirroring transform flips the bitangent sign), else generated
// from the UV set of the map (or of the anisotropy texture).
void add_tangents(const GltfContext& ctx, const LocalPrimitive& local, const Transform& world, bool flip,
                  const std::string& where, Mesh& out) {
  if (local.material < 0) return;
  const Material& mat = ctx.out.scene.materials[size_t(local.material)];
  TextureRef nt = mat.normal_tex;
  if (nt.texture < 0) nt = mat.clearcoat_normal_tex;
  if (nt.texture < 0 && mat.anisotropy > 0) {
    nt = mat.anisotropy_tex;
    nt.texture = 0;  // tangents are needed with or without the texture
  }
  const auto& nuv = nt.texcoord == 1 ? out.uvs1 : out.uvs;
  if (nt.texture >= 0 && !local.tangents.empty()) {
    out.tangents.resize(local.tangents.size());
    for (size_t i = 0; i < local.tangents.size(); ++i) {
      const Vec4f t = local.tangents[i];
      const Vec3f tw = normalize(transform_vector(world, {t.x, t.y, t.z}));
      out.tangents[i] = {tw.x, tw.y, tw.z, flip ? -t.w : t.w};
    }
  } else if (nt.texture >= 0 && !nuv.empty()) {
    out.tangents = compute_tangents(out.positions, out.normals, nuv, out.indices);
  } else if (nt.texture >= 0) {
    ctx.warn(where,
             "normal texture without TEXCOORD_" + std::to_string(nt.texcoord) + "; normal map ignored");
  }
}

// The material points and lines without NORMAL render with: the glTF spec (3.7.2.1) has them
// unlit, base colour (times COLOR_0) only. An unlit copy of `material` (the default material for
// -1), made once per material.
int unlit_material(const GltfContext& ctx, int material) {
  auto& materials = ctx.out.scene.materials;
  const std::string name = (material >= 0 ? materials[size_t(material)].name : std::string("default")) +
                           " (points and lines without normals: unlit)";
  for (size_t i = 0; i < materials.size(); ++i)
    if (materials[i].unlit && materials[i].name == name) return int(i);
  Material m = material >= 0 ? materials[size_t(material)] : Material{};
  m.name = name;
  m.unlit = true;
  materials.push_back(std::move(m));
  return int(materials.size() - 1);
}

// One usable primitive placed by `world` (or skinned), as a Mesh; false if its world-space
// positions are not usable (warned about).
bool place_primitive(const GltfContext& ctx, const LocalPrimitive& local, const Emit& e, size_t pi,
                     const Transform& world, const Transform& inv, bool flip, Mesh& out) {
  const auto& mesh = ctx.model.meshes[size_t(e.mesh)];
  const std::string where = idx("meshes", size_t(e.mesh)) + "." + idx("primitives", pi);
  const std::string node_where = e.node >= 0 ? idx("nodes", size_t(e.node)) : "object space (instanced mesh)";
  ctx.charge(uint64_t(local.indices.size()) * 4 + uint64_t(local.positions.size()) * 96, where,
             "a placed copy needs");
  out.name = (mesh.name.empty() ? idx("meshes", size_t(e.mesh)) : mesh.name) + "[" + std::to_string(pi) + "]";
  out.node = e.node;
  out.material = (local.points || local.lines) && local.normals.empty() ? unlit_material(ctx, local.material)
                                                                        : local.material;
  out.points = local.points;
  out.lines = local.lines;
  if (!local.radii.empty()) {  // the file's sizes, scaled as the placement scales lengths
    const float scale = float(std::cbrt(std::fabs(determinant3x3(world))));
    out.radii.resize(local.radii.size());
    for (size_t i = 0; i < local.radii.size(); ++i) out.radii[i] = local.radii[i] * scale;
    out.file_radii = true;
  }
  std::vector<Vec3f> lp, ln;
  morph(local, *e.morph, lp, ln);
  const bool skinned = !e.joint_mats->empty() && !local.joints.empty();
  const std::vector<Transform> vertex_xf =
      skinned ? skin_transforms(ctx, local, *e.joint_mats, world, where) : std::vector<Transform>{};
  out.positions.resize(lp.size());
  for (size_t i = 0; i < lp.size(); ++i) {
    out.positions[i] = transform_point(skinned ? vertex_xf[i] : world, lp[i]);
    if (!is_finite(out.positions[i]) || max_component(abs(out.positions[i])) > 1e18f) {
      ctx.warn(where + " in " + node_where, "world-space positions are NaN, infinite or huge; dropped");
      return false;
    }
  }
  out.indices = local.indices;
  if (flip)
    for (size_t i = 0; i < out.indices.size(); i += 3) std::swap(out.indices[i + 1], out.indices[i + 2]);
  if (!ln.empty()) {
    out.normals.resize(ln.size());
    for (size_t i = 0; i < ln.size(); ++i) {
      Transform vinv = inv;
      if (skinned && !inverse(vertex_xf[i], vinv)) vinv = inv;
      out.normals[i] = normalize(transform_normal(vinv, ln[i]));
    }
  } else {
    out.normals = compute_smooth_normals(out.positions, out.indices);
  }
  out.uvs = local.uvs;
  out.uvs1 = local.uvs1;
  out.colors = local.colors;
  add_tangents(ctx, local, world, flip, where, out);
  return true;
}

// Emits the usable primitives of mesh e.mesh placed by `world` (or skinned by e.joint_mats).
void emit_primitives(const GltfContext& ctx, const std::vector<LocalPrimitive>& primitives, const Emit& e,
                     const Transform& world) {
  Transform inv;
  if (!inverse(world, inv)) return;  // callers skip singular placements
  const bool flip = !e.joint_mats->empty()
                        ? determinant3x3((*e.joint_mats)[0]) < 0
                        : determinant3x3(world) < 0;  // mirrored: keep counter-clockwise = front
  for (size_t pi = 0; pi < primitives.size(); ++pi) {
    if (!primitives[pi].usable || primitives[pi].splats) continue;
    Mesh out;
    if (!place_primitive(ctx, primitives[pi], e, pi, world, inv, flip, out)) continue;
    if (!e.object_ids) out.object_from_world = to_affine(inv);
    if (e.object_ids) {
      e.object_ids->push_back(int(ctx.out.scene.meshes.size()));
      ctx.out.scene.meshes.push_back(std::move(out));
    } else {
      add_world_mesh(ctx.out.scene, std::move(out));
    }
  }
}

// Charges the placements of a mesh use before they are made: per placement its Transform, and
// per primitive an Instance and what an accelerator allocates for it.
void charge_placements(const GltfContext& ctx, const MeshUse& use) {
  if (use.mesh < 0 || size_t(use.mesh) >= ctx.model.meshes.size()) return;  // add_mesh reports it
  const auto& gnode = ctx.model.nodes[size_t(use.node)];
  const uint64_t count = declared_placements(ctx, use.node);
  std::string where = idx("nodes", size_t(use.node));
  if (gnode.extensions.count("EXT_mesh_gpu_instancing")) where += ".extensions.EXT_mesh_gpu_instancing";
  const uint64_t primitives = std::max<uint64_t>(1, ctx.model.meshes[size_t(use.mesh)].primitives.size());
  const uint64_t per_placement = sizeof(Transform) + primitives * (sizeof(Instance) + kAccelBytesPerInstance);
  uint64_t bytes = 0;
  if (!mul_ok(count, per_placement, bytes)) bytes = UINT64_MAX;
  ctx.charge(bytes, where, std::to_string(count) + (count == 1 ? " instance needs" : " instances need"));
}

// (mesh, morph weights) -> the Scene::meshes of its object-space copy.
using ObjectMeshes = std::map<std::pair<int, std::vector<double>>, std::vector<int>>;

// Instances of the object-space copy of mesh e.mesh (made on first use), one per placement and
// primitive; returns how many placements were skipped as singular, non-finite or huge. A moving
// node's instances are never marked the identity, so that posing them leaves the vertices alone.
uint64_t add_instances(const GltfContext& ctx, const std::vector<LocalPrimitive>& primitives, Emit e,
                       const std::vector<Transform>& placements, int node, bool moving,
                       ObjectMeshes& objects) {
  auto [it, inserted] = objects.try_emplace({e.mesh, *e.morph});
  if (inserted) {
    e.node = -1;
    e.object_ids = &it->second;
    emit_primitives(ctx, primitives, e, Transform{});
  }
  std::vector<Bounds3f> object_bounds;
  for (int id : it->second) {
    Bounds3f b;
    for (Vec3f p : ctx.out.scene.meshes[size_t(id)].positions) b = merge(b, p);
    object_bounds.push_back(b);
  }
  const bool per_copy = ctx.model.nodes[size_t(node)].extensions.count("EXT_mesh_gpu_instancing") > 0;
  uint64_t singular = 0;
  for (size_t k = 0; k < placements.size(); ++k) {
    Instance inst;
    try {
      inst = make_instance(0, to_affine(placements[k]), node);
    } catch (const std::invalid_argument&) {
      ++singular;
      continue;
    }
    inst.copy = per_copy ? int(k) : -1;
    if (moving) inst.identity = false;
    bool usable = true;  // world-space corners finite and not huge, as for flattened meshes
    for (const Bounds3f& b : object_bounds) {
      const Bounds3f w = transform_bounds(inst.to_world, b);
      usable =
          usable && (b.empty() || (is_finite(w.lo) && is_finite(w.hi) &&
                                   std::max(max_component(abs(w.lo)), max_component(abs(w.hi))) <= 1e18f));
    }
    if (!usable) {
      ++singular;
      continue;
    }
    for (int id : it->second) {
      inst.mesh = id;
      ctx.out.scene.instances.push_back(inst);
    }
  }
  return singular;
}

// The splat clouds of `primitives` (each stored once in the scene) placed by every invertible
// placement of `node`; a skinned node's splats are not placed (warned).
void add_splat_instances(const GltfContext& ctx, const std::vector<LocalPrimitive>& primitives,
                         const std::vector<Transform>& placements, int node, const std::string& node_where,
                         bool skinned) {
  Scene& scene = ctx.out.scene;
  for (const LocalPrimitive& p : primitives) {
    if (!p.splats) continue;
    if (skinned) {
      ctx.warn(node_where, "Gaussian splats of a skinned mesh are not placed");
      continue;
    }
    int cloud = -1;
    for (size_t c = 0; c < scene.splat_clouds.size() && cloud < 0; ++c)
      if (scene.splat_clouds[c].mesh == p.splats->mesh &&
          scene.splat_clouds[c].primitive == p.splats->primitive)
        cloud = int(c);
    if (cloud < 0) {
      // The cloud, and its splats' shapes as the splat structure copies them (twice: the
      // view's and the structure's) with a node's share.
      ctx.charge(uint64_t(p.splats->positions.size()) * (12 + 16 + 12 + 4 + 2 * sizeof(Shape) + 64) +
                     p.splats->sh.size() * 12,
                 p.splats->name, "its Gaussian splats need");
      scene.splat_clouds.push_back(*p.splats);
      cloud = int(scene.splat_clouds.size()) - 1;
    }
    for (const Transform& world : placements) {
      Transform inv;
      if (!inverse(world, inv)) continue;
      scene.splat_instances.push_back({cloud, to_affine(world), node});
    }
  }
}

// A node's mesh placed by `placements` (the node's world transform, or one per
// EXT_mesh_gpu_instancing instance). shared: stored once in object space and instanced; else
// one world-space copy per placement (skinned meshes always). Placements of a moving node left
// out are counted in nodes.moving_skipped.
void add_mesh(const GltfContext& ctx, const std::vector<std::vector<LocalPrimitive>>& decoded,
              NodeTransforms& nodes, const MeshUse& use, const std::vector<Transform>& placements,
              bool shared, ObjectMeshes& objects) {
  const std::string node_where = idx("nodes", size_t(use.node));
  if (use.mesh < 0 || size_t(use.mesh) >= ctx.model.meshes.size())
    ctx.fail(node_where + ".mesh", "mesh index " + std::to_string(use.mesh) + " out of range (" +
                                       std::to_string(ctx.model.meshes.size()) + " meshes)");
  const auto& gnode = ctx.model.nodes[size_t(use.node)];
  const std::vector<LocalPrimitive>& primitives = decoded[size_t(use.mesh)];
  const std::vector<double> weights = morph_weights(ctx, *nodes.poses, use.mesh, use.node);
  const std::vector<Transform> no_joints;
  Emit e{use.mesh, use.node, &weights, &no_joints, nullptr};
  add_splat_instances(ctx, primitives, placements, use.node, node_where, gnode.skin >= 0 || gnode.skin < -1);
  // A skinned mesh ignores its node's own transform (glTF 3.7.3.3).
  if (gnode.skin >= 0 || gnode.skin < -1) {
    const std::vector<Transform> joint_mats = joint_matrices(ctx, nodes, gnode.skin, node_where);
    if (placements.size() != 1) ctx.warn(node_where, "EXT_mesh_gpu_instancing on a skinned mesh is ignored");
    e.joint_mats = &joint_mats;
    emit_primitives(ctx, primitives, e, nodes.world[size_t(use.node)]);
    return;
  }
  uint64_t singular = 0;
  if (shared) {
    singular = add_instances(ctx, primitives, e, placements, use.node, is_moving(nodes, use.node), objects);
  } else {
    for (const Transform& world : placements) {
      Transform inv;
      if (!inverse(world, inv)) {
        ++singular;
        continue;
      }
      emit_primitives(ctx, primitives, e, world);
    }
  }
  if (is_moving(nodes, use.node)) nodes.moving_skipped += singular;
  if (singular == 1 && placements.size() == 1)
    ctx.warn(node_where,
             "singular, non-finite or huge transform; mesh " + std::to_string(use.mesh) + " skipped");
  else if (singular > 0)
    ctx.warn(node_where + ".extensions.EXT_mesh_gpu_instancing",
             std::to_string(singular) + " of " + std::to_string(placements.size()) +
                 " instances have a singular, non-finite or huge transform; skipped");
}

}  // namespace

uint64_t declared_placements(const GltfContext& ctx, int node) {
  const auto& gnode = ctx.model.nodes[size_t(node)];
  const auto ext = gnode.extensions.find("EXT_mesh_gpu_instancing");
  if (ext == gnode.extensions.end()) return 1;
  const tinygltf::Value& attributes = ext->second.Get("attributes");
  uint64_t count = 1;
  for (const char* name : {"TRANSLATION", "ROTATION", "SCALE"}) {
    if (!attributes.IsObject() || !attributes.Has(name) || !attributes.Get(name).IsInt()) continue;
    const int a = attributes.Get(name).Get<int>();
    if (a >= 0 && size_t(a) < ctx.model.accessors.size())
      count = std::max<uint64_t>(count, ctx.model.accessors[size_t(a)].count);
  }
  return count;
}

std::vector<Transform> placements_of(const GltfContext& ctx, int node, const Transform& world) {
  const auto& gnode = ctx.model.nodes[size_t(node)];
  const auto ext = gnode.extensions.find("EXT_mesh_gpu_instancing");
  if (ext == gnode.extensions.end()) return {world};
  const std::string where = idx("nodes", size_t(node)) + ".extensions.EXT_mesh_gpu_instancing";
  const tinygltf::Value& attributes = ext->second.Get("attributes");
  // tinygltf stores an empty JSON object (and a missing member) as a null value.
  if (attributes.Type() == tinygltf::NULL_TYPE) {
    ctx.warn(where + ".attributes", "no TRANSLATION, ROTATION or SCALE; the node is placed once");
    return {world};
  }
  if (!attributes.IsObject()) ctx.fail(where + ".attributes", "must be an object");
  // TRANSLATION (VEC3 float), ROTATION (VEC4 float or normalized byte/short), SCALE (VEC3 float).
  std::vector<double> values[3];
  const char* names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
  uint64_t count = 0;
  std::string first;
  for (int k = 0; k < 3; ++k) {
    if (!attributes.Has(names[k])) continue;
    const std::string aw = where + ".attributes." + names[k];
    const tinygltf::Value& a = attributes.Get(names[k]);
    if (!a.IsInt()) ctx.fail(aw, "must be an accessor index");
    if (k == 1)
      values[k] = read_accessor(
          ctx, a.Get<int>(), aw, {TINYGLTF_TYPE_VEC4},
          {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT}, true);
    else
      values[k] =
          read_accessor(ctx, a.Get<int>(), aw, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
    const uint64_t n = values[k].size() / (k == 1 ? 4 : 3);
    if (!first.empty() && n != count)
      ctx.fail(aw, "has " + std::to_string(n) + " elements but " + first + " has " + std::to_string(count) +
                       " (all instance attributes must have the same count)");
    if (first.empty()) first = names[k];
    count = n;
  }
  for (const auto& key : attributes.Keys())
    if (key != "TRANSLATION" && key != "ROTATION" && key != "SCALE" && (key.empty() || key[0] != '_'))
      ctx.warn(where + ".attributes." + key, "unknown instance attribute; ignored");
  if (first.empty()) {
    ctx.warn(where + ".attributes", "no TRANSLATION, ROTATION or SCALE; the node is placed once");
    return {world};
  }
  std::vector<Transform> out;
  out.reserve(size_t(count));
  for (size_t i = 0; i < count; ++i) {
    std::array<double, 3> t{0, 0, 0}, sc{1, 1, 1};
    Quat q;
    if (!values[0].empty()) t = {values[0][3 * i], values[0][3 * i + 1], values[0][3 * i + 2]};
    if (!values[1].empty())
      q = {values[1][4 * i], values[1][4 * i + 1], values[1][4 * i + 2], values[1][4 * i + 3]};
    if (!values[2].empty()) sc = {values[2][3 * i], values[2][3 * i + 1], values[2][3 * i + 2]};
    out.push_back(world * compose_trs(t, q, sc));  // NodeWorldXform x InstanceXform
  }
  return out;
}

std::vector<std::vector<LocalPrimitive>> decode_meshes(const GltfContext& ctx) {
  std::vector<std::vector<LocalPrimitive>> meshes(ctx.model.meshes.size());
  for (size_t m = 0; m < ctx.model.meshes.size(); ++m)
    for (size_t p = 0; p < ctx.model.meshes[m].primitives.size(); ++p)
      meshes[m].push_back(decode_primitive(ctx, m, p));
  return meshes;
}

void place_meshes(const GltfContext& ctx, const std::vector<std::vector<LocalPrimitive>>& decoded,
                  NodeTransforms& nodes, const std::vector<MeshUse>& uses) {
  // Meshes placed more than once are stored once and instanced (unless flattening is asked
  // for); a mesh placed once is put in world space, as Cycles applies the transform of a mesh
  // with one user, so single-level scenes keep single-level structures, unless its node moves:
  // then it stays in object space, so that another pose moves only its instance.
  std::vector<std::vector<Transform>> placements;
  std::map<int, uint64_t> counts;
  for (const MeshUse& u : uses) {
    charge_placements(ctx, u);
    placements.push_back(placements_of(ctx, u.node, nodes.world[size_t(u.node)]));
    if (u.mesh >= 0) counts[u.mesh] += placements.back().size();
  }
  ObjectMeshes objects;
  for (size_t k = 0; k < uses.size(); ++k)
    add_mesh(ctx, decoded, nodes, uses[k], placements[k],
             !ctx.options.flatten && (counts[uses[k].mesh] > 1 || is_moving(nodes, uses[k].node)), objects);
}

}  // namespace penumbra::gltf
