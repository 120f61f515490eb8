// glTF 2.0 writer: see gltf_writer.h.
#include "io/gltf/gltf_writer.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/files/atomic_file.h"
#include "io/files/error.h"
#include "io/gltf/procedural.h"
#include "renderer/scene/camera.h"

namespace penumbra {
namespace {

using nlohmann::json;

constexpr int kFloat = 5126, kUint32 = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

struct Writer {
  json j;
  std::vector<uint8_t> bin;
  std::string file;
  /// A polyhedron's solid -> the glTF mesh written for it.
  std::map<const SolidMesh*, int> polyhedron_meshes;

  int accessor(const void* data, size_t bytes, int component_type, size_t count, const char* type, int target,
               const json& minmax = nullptr) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t offset = bin.size();
    if (offset + bytes > (size_t(1) << 32) - 1)
      throw InputError(file, "buffers[0]", "geometry exceeds 4 GiB");
    bin.resize(offset + bytes);
    if (bytes) std::memcpy(bin.data() + offset, data, bytes);
    j["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}});
    json a = {{"bufferView", j["bufferViews"].size() - 1},
              {"componentType", component_type},
              {"count", count},
              {"type", type}};
    if (!minmax.is_null()) {
      a["min"] = minmax[0];
      a["max"] = minmax[1];
    }
    j["accessors"].push_back(a);
    return int(j["accessors"].size()) - 1;
  }
};

/// The glTF mesh holding a polyhedron's triangles (its welded, outward-wound mesh; one
/// TRIANGLES primitive, placed by no node), written once per solid.
int polyhedron_mesh(Writer& wr, const SolidMesh& solid) {
  if (const auto it = wr.polyhedron_meshes.find(&solid); it != wr.polyhedron_meshes.end()) return it->second;
  if (solid.positions.empty() || solid.indices.size() < 3)
    throw InputError(wr.file, "shapes", "a polyhedron CSG node without triangles");
  Bounds3f b;
  for (const Vec3f& p : solid.positions) b = merge(b, p);
  const json minmax = {{b.lo.x, b.lo.y, b.lo.z}, {b.hi.x, b.hi.y, b.hi.z}};
  const int positions = wr.accessor(solid.positions.data(), solid.positions.size() * 12, kFloat,
                                    solid.positions.size(), "VEC3", kArrayBuffer, minmax);
  const int indices = wr.accessor(solid.indices.data(), solid.indices.size() * 4, kUint32,
                                  solid.indices.size(), "SCALAR", kElementArrayBuffer);
  wr.j["meshes"].push_back(
      {{"name", "polyhedron"},
       {"primitives", {{{"attributes", {{"POSITION", positions}}}, {"indices", indices}, {"mode", 4}}}}});
  const int mesh = int(wr.j["meshes"].size()) - 1;
  wr.polyhedron_meshes[&solid] = mesh;
  return mesh;
}

/// Column-major 4x4 matrix of the frame (u, v, w) at `origin`.
json frame_matrix(Vec3f u, Vec3f v, Vec3f w, Vec3f origin) {
  return json::array({u.x, u.y, u.z, 0, v.x, v.y, v.z, 0, w.x, w.y, w.z, 0, origin.x, origin.y, origin.z, 1});
}

/// Appends `node` to the nodes and to the scene's roots.
void add_root(Writer& wr, json node) {
  wr.j["nodes"].push_back(std::move(node));
  wr.j["scenes"][0]["nodes"].push_back(wr.j["nodes"].size() - 1);
}

/// The materials (with their procedural textures); sets which material extensions they use.
void write_materials(Writer& wr, const Scene& scene, bool& emissive_strength, bool& unlit, bool& procedural) {
  if (!scene.materials.empty()) wr.j["materials"] = json::array();
  for (const Material& m : scene.materials) {
    json mat = {{"pbrMetallicRoughness",
                 {{"baseColorFactor", {m.base_color.x, m.base_color.y, m.base_color.z, m.alpha}},
                  {"metallicFactor", m.metallic},
                  {"roughnessFactor", m.roughness}}}};
    if (!m.name.empty()) mat["name"] = m.name;
    const float e = max_component(m.emissive);
    if (e > 0) {
      const float s = std::max(e, 1.0f);
      mat["emissiveFactor"] = {m.emissive.x / s, m.emissive.y / s, m.emissive.z / s};
      if (s > 1) {
        mat["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", s}};
        emissive_strength = true;
      }
    }
    if (m.alpha < 1) mat["alphaMode"] = "BLEND";
    if (m.double_sided) mat["doubleSided"] = true;  // glTF's default is single-sided
    if (m.unlit) {
      mat["extensions"]["KHR_materials_unlit"] = json::object();
      unlit = true;
    }
    if (m.procedural >= 0 && size_t(m.procedural) < scene.procedurals.size()) {
      mat["extensions"][gltf::kProceduralExtension] =
          gltf::procedural_json(scene.procedurals[size_t(m.procedural)]);
      procedural = true;
    }
    wr.j["materials"].push_back(mat);
  }
}

/// A world-space mesh moved there from a node (Mesh::object_from_world not the identity), mapped
/// back into that node's frame so that object-space procedural textures keep it: positions,
/// normals, and the winding turned back where the frame mirrors.
struct NodeFrameMesh {
  std::vector<Vec3f> positions, normals;
  std::vector<uint32_t> indices;
};
NodeFrameMesh to_node_frame(const Mesh& m) {
  NodeFrameMesh out;
  Affine3f to_world;
  if (!inverse(m.object_from_world, to_world)) return out;
  out.positions.reserve(m.positions.size());
  for (const Vec3f& p : m.positions) out.positions.push_back(apply_point(m.object_from_world, p));
  for (const Vec3f& n : m.normals) out.normals.push_back(normalize(apply_normal(to_world, n)));
  out.indices = m.indices;
  if (determinant3x3(to_transform(m.object_from_world)) < 0)
    for (size_t i = 0; i + 2 < out.indices.size(); i += 3) std::swap(out.indices[i + 1], out.indices[i + 2]);
  return out;
}

/// One glTF mesh per non-empty scene mesh (positions checked first), in its node's frame when it
/// has one; returns scene mesh -> glTF mesh, -1 for an empty one.
std::vector<int> write_meshes(Writer& wr, const Scene& scene) {
  std::vector<int> gltf_mesh(scene.meshes.size(), -1);  // scene mesh -> glTF mesh (-1: empty)
  for (size_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const Mesh& m = scene.meshes[mi];
    const std::string where = "meshes[" + std::to_string(mi) + "]";
    Bounds3f b;
    for (const Vec3f& p : m.positions) {
      if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
        throw InputError(wr.file, where, "non-finite position");
      b = merge(b, p);
    }
    if (m.indices.size() % 3 != 0)
      throw InputError(wr.file, where,
                       "index count " + std::to_string(m.indices.size()) + " is not a multiple of 3");
    for (uint32_t i : m.indices)
      if (i >= m.positions.size())
        throw InputError(
            wr.file, where,
            "index " + std::to_string(i) + " >= vertex count " + std::to_string(m.positions.size()));
    if (m.positions.empty() || m.indices.size() < 3) continue;  // glTF has no empty primitives
    const NodeFrameMesh framed = is_identity(m.object_from_world) ? NodeFrameMesh{} : to_node_frame(m);
    const bool in_frame = !framed.positions.empty();
    const std::vector<Vec3f>& positions = in_frame ? framed.positions : m.positions;
    const std::vector<Vec3f>& normals = in_frame ? framed.normals : m.normals;
    const std::vector<uint32_t>& indices = in_frame ? framed.indices : m.indices;
    if (in_frame) {
      b = {};
      for (const Vec3f& p : positions) b = merge(b, p);
    }
    const json minmax = {{b.lo.x, b.lo.y, b.lo.z}, {b.hi.x, b.hi.y, b.hi.z}};
    json attributes = {{"POSITION", wr.accessor(positions.data(), positions.size() * 12, kFloat,
                                                positions.size(), "VEC3", kArrayBuffer, minmax)}};
    // Point and line sets: mode 0 or 1 from their degenerate triangles, widths (_WIDTH) when the
    // file gave them, no NORMAL (points and lines without normals render unlit).
    const bool curves = m.points || m.lines;
    std::vector<uint32_t> curve_indices;
    std::vector<float> widths;
    if (curves) {
      for (size_t t = 0; t + 2 < indices.size(); t += 3) {
        curve_indices.push_back(indices[t]);
        if (m.lines) curve_indices.push_back(indices[t + 1]);
      }
      if (m.file_radii && m.radii.size() == positions.size()) {
        const float scale =
            in_frame ? std::cbrt(std::fabs(float(determinant3x3(to_transform(m.object_from_world))))) : 1.0f;
        for (float r : m.radii) widths.push_back(2 * r * scale);
        attributes["_WIDTH"] =
            wr.accessor(widths.data(), widths.size() * 4, kFloat, widths.size(), "SCALAR", kArrayBuffer);
      }
    }
    const std::vector<uint32_t>& written = curves ? curve_indices : indices;
    if (normals.size() == positions.size() && !curves)
      attributes["NORMAL"] =
          wr.accessor(normals.data(), normals.size() * 12, kFloat, normals.size(), "VEC3", kArrayBuffer);
    if (m.uvs.size() == m.positions.size())
      attributes["TEXCOORD_0"] =
          wr.accessor(m.uvs.data(), m.uvs.size() * 8, kFloat, m.uvs.size(), "VEC2", kArrayBuffer);
    json prim = {{"attributes", attributes},
                 {"indices", wr.accessor(written.data(), written.size() * 4, kUint32, written.size(),
                                         "SCALAR", kElementArrayBuffer)},
                 {"mode", m.points ? 0 : (m.lines ? 1 : 4)}};
    if (m.material >= 0 && size_t(m.material) < scene.materials.size()) prim["material"] = m.material;
    json mesh = {{"primitives", {prim}}};
    if (!m.name.empty()) mesh["name"] = m.name;
    wr.j["meshes"].push_back(mesh);
    gltf_mesh[mi] = int(wr.j["meshes"].size()) - 1;
  }
  return gltf_mesh;
}

/// Column-major 4x4 matrix of an affine map.
json affine_matrix(const Affine3f& a) {
  json matrix = json::array();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) matrix.push_back(r < 3 ? a.m[r][c] : (c == 3 ? 1.0f : 0.0f));
  return matrix;
}

/// A displace node's noise fields (offset and gain only for ridged noise, as the loader reads them).
void displacement_json(const SdfDisplacement& d, json& j) {
  static const char* const kNoiseNames[] = {"fbm", "turbulence", "ridged"};
  const FractalParams& p = d.params;
  j["amplitude"] = d.amplitude;
  j["frequency"] = d.frequency;
  j["seed"] = d.table.seed;
  j["noise"] = kNoiseNames[int(p.kind)];
  j["detail"] = p.detail;
  j["roughness"] = p.roughness;
  j["lacunarity"] = p.lacunarity;
  j["distortion"] = p.distortion;
  if (p.kind == FractalKind::Ridged) {
    j["offset"] = p.offset;
    j["gain"] = p.gain;
  }
}

/// CSG node `index` of `tree` as a PENUMBRA_shapes CSG object (the inverse of the loader's
/// reading): its type and fields, a matrix placing its frame unless that is the identity, and
/// its operands as children. A polyhedron's triangles become a glTF mesh it names.
json csg_json(const SdfTree& tree, int index, Writer& wr, int depth = 1) {
  const std::string& file = wr.file;
  if (depth > kMaxSdfDepth)
    throw InputError(file, "shapes", "a CSG tree deeper than " + std::to_string(kMaxSdfDepth) + " levels");
  const SdfNode& n = tree.nodes[size_t(index)];
  static const char* const kNames[] = {"sphere",
                                       "box",
                                       "roundBox",
                                       "capsule",
                                       "cylinder",
                                       "cone",
                                       "torus",
                                       "halfSpace",
                                       "convexPolyhedron",
                                       "polyhedron",
                                       "union",
                                       "intersection",
                                       "subtraction",
                                       "complement",
                                       "smoothUnion",
                                       "smoothIntersection",
                                       "smoothSubtraction",
                                       "displace"};
  json j = {{"type", kNames[int(n.kind)]}};
  switch (n.kind) {
    case SdfKind::Sphere:
      j["radius"] = n.size.x;
      break;
    case SdfKind::Box:
    case SdfKind::RoundBox:
      j["size"] = {2 * n.size.x, 2 * n.size.y, 2 * n.size.z};
      if (n.kind == SdfKind::RoundBox) j["radius"] = n.radius;
      break;
    case SdfKind::Capsule:
    case SdfKind::Cylinder:
    case SdfKind::Cone:
      j["radius"] = n.radius;
      j["height"] = 2 * n.size.y;
      break;
    case SdfKind::Torus:
      j["majorRadius"] = n.size.x;
      j["minorRadius"] = n.radius;
      break;
    case SdfKind::HalfSpace:
      j["normal"] = {n.normal.x, n.normal.y, n.normal.z};
      j["offset"] = n.offset;
      break;
    case SdfKind::ConvexPolyhedron:
      j["planes"] = json::array();
      for (int i = n.first_plane; i < n.first_plane + n.plane_count; ++i) {
        const Vec4f& p = tree.planes[size_t(i)];
        j["planes"].push_back({p.x, p.y, p.z, p.w});
      }
      break;
    case SdfKind::Polyhedron:
      if (n.polyhedron < 0 || size_t(n.polyhedron) >= tree.polyhedra.size())
        throw InputError(file, "shapes",
                         "a polyhedron node's mesh " + std::to_string(n.polyhedron) + " out of range");
      j["mesh"] = polyhedron_mesh(wr, tree.polyhedra[size_t(n.polyhedron)]);
      break;
    case SdfKind::Displace:
      if (n.displacement < 0 || size_t(n.displacement) >= tree.displacements.size())
        throw InputError(file, "shapes",
                         "a displace node's noise " + std::to_string(n.displacement) + " out of range");
      displacement_json(tree.displacements[size_t(n.displacement)], j);
      break;
    default:
      break;
  }
  if (is_operator(n.kind)) {
    j["children"] = json::array({csg_json(tree, n.a, wr, depth + 1)});
    if (!is_unary(n.kind)) j["children"].push_back(csg_json(tree, n.b, wr, depth + 1));
    if (n.kind >= SdfKind::SmoothUnion && n.kind <= SdfKind::SmoothSubtraction) j["radius"] = n.radius;
  }
  if (!is_identity(n.to_local)) {
    Affine3f to_parent;
    if (!inverse(n.to_local, to_parent))
      throw InputError(file, "shapes", "a CSG node's transform is singular");
    j["matrix"] = affine_matrix(to_parent);
  }
  return j;
}

/// The PENUMBRA_shapes object of a scene shape.
json shape_json(const SceneShape& ss, size_t material_count, Writer& wr) {
  const std::string& file = wr.file;
  const Shape& s = ss.shape;
  json j = {{"type", shape_kind_name(s.kind)}};
  switch (s.kind) {
    case ShapeKind::Sphere:
    case ShapeKind::Disk:
      j["radius"] = s.radius;
      break;
    case ShapeKind::Plane:
      j["size"] = {2 * s.half_size.x, 2 * s.half_size.z};
      break;
    case ShapeKind::Box:
      j["size"] = {2 * s.half_size.x, 2 * s.half_size.y, 2 * s.half_size.z};
      break;
    case ShapeKind::Capsule:
      j["radius"] = s.radius;
      j["height"] = 2 * s.half_height;
      break;
    case ShapeKind::Segment:
      throw InputError(file, "shapes", ss.name + ": a curve segment is written with its curve set");
    case ShapeKind::Splat:
      throw InputError(file, "shapes", ss.name + ": a Gaussian splat is written with its splat cloud");
    case ShapeKind::Implicit:
      if (s.sdf.root < 0) throw InputError(file, "shapes", ss.name + ": an implicit shape without a tree");
      j["csg"] = csg_json(s.sdf, s.sdf.root, wr);
      j["maxSteps"] = s.trace.max_steps;
      j["epsilon"] = s.trace.relative_epsilon;
      break;
  }
  if (ss.material >= 0 && size_t(ss.material) < material_count) j["material"] = ss.material;
  return j;
}

/// One node per shape instance, carrying the shape in PENUMBRA_shapes and its placement.
void write_shape_instance(Writer& wr, const Scene& scene, const Instance& inst, size_t ii) {
  if (size_t(inst.shape) >= scene.shapes.size())
    throw InputError(wr.file, "instances[" + std::to_string(ii) + "]",
                     "shape " + std::to_string(inst.shape) + " out of range");
  const SceneShape& ss = scene.shapes[size_t(inst.shape)];
  json node = {{"name", ss.name.empty() ? "shapes[" + std::to_string(inst.shape) + "]" : ss.name}};
  node["extensions"]["PENUMBRA_shapes"] = shape_json(ss, scene.materials.size(), wr);
  if (!inst.identity) node["matrix"] = affine_matrix(inst.to_world);
  add_root(wr, node);
}

/// One node per instance; shared meshes stay shared, placements become node matrices.
void write_instances(Writer& wr, const Scene& scene, const std::vector<int>& gltf_mesh) {
  for (size_t ii = 0; ii < scene.instances.size(); ++ii) {
    const Instance& inst = scene.instances[ii];
    if (inst.shape >= 0) {
      write_shape_instance(wr, scene, inst, ii);
      continue;
    }
    if (inst.mesh < 0 || size_t(inst.mesh) >= scene.meshes.size())
      throw InputError(wr.file, "instances[" + std::to_string(ii) + "]",
                       "mesh " + std::to_string(inst.mesh) + " out of range");
    if (gltf_mesh[size_t(inst.mesh)] < 0) continue;
    const Mesh& m = scene.meshes[size_t(inst.mesh)];
    json node = {{"mesh", gltf_mesh[size_t(inst.mesh)]},
                 {"name", m.name.empty() ? "meshes[" + std::to_string(inst.mesh) + "]" : m.name}};
    Affine3f frame;
    if (!inst.identity)
      node["matrix"] = affine_matrix(inst.to_world);
    else if (!is_identity(m.object_from_world) && inverse(m.object_from_world, frame))
      node["matrix"] = affine_matrix(frame);  // the node the mesh was moved into world space from
    add_root(wr, node);
  }
}

/// Cameras, each on a root node holding its frame.
void write_cameras(Writer& wr, const Scene& scene) {
  if (!scene.cameras.empty()) wr.j["cameras"] = json::array();
  for (size_t ci = 0; ci < scene.cameras.size(); ++ci) {
    const Camera& c = scene.cameras[ci];
    json cam;
    if (c.projection == Projection::Perspective) {
      json p = {{"yfov", c.yfov}, {"znear", c.znear > 0 ? c.znear : 1e-3f}};
      if (c.aspect > 0) p["aspectRatio"] = c.aspect;
      if (std::isfinite(c.zfar)) p["zfar"] = c.zfar;
      cam = {{"type", "perspective"}, {"perspective", p}};
    } else {
      json o = {{"xmag", c.xmag},
                {"ymag", c.ymag},
                {"znear", c.znear},
                {"zfar", std::isfinite(c.zfar) ? c.zfar : 1e30f}};
      cam = {{"type", "orthographic"}, {"orthographic", o}};
    }
    if (!c.name.empty()) cam["name"] = c.name;
    wr.j["cameras"].push_back(cam);
    add_root(wr, {{"camera", ci},
                  {"matrix", frame_matrix(c.u, c.v, c.w, c.eye)},
                  {"name", c.name.empty() ? "camera" + std::to_string(ci) : c.name}});
  }
}

/// KHR_lights_punctual lights, each on a root node holding its frame.
void write_lights(Writer& wr, const Scene& scene) {
  if (!scene.lights.empty()) {
    json lights = json::array();
    for (size_t li = 0; li < scene.lights.size(); ++li) {
      const Light& l = scene.lights[li];
      json light = {{"color", {l.color.x, l.color.y, l.color.z}}, {"intensity", l.intensity}};
      light["type"] =
          l.type == LightType::Point ? "point" : (l.type == LightType::Spot ? "spot" : "directional");
      if (l.type != LightType::Directional && std::isfinite(l.range)) light["range"] = l.range;
      if (l.type == LightType::Spot)
        light["spot"] = {{"innerConeAngle", l.inner_cone}, {"outerConeAngle", l.outer_cone}};
      if (!l.name.empty()) light["name"] = l.name;
      lights.push_back(light);
      // The light shines down its local -Z: the frame of a camera looking along its direction.
      Camera frame;
      if (l.type != LightType::Point) frame = look_at({0, 0, 0}, l.direction, {0, 1, 0}, 0);
      add_root(wr, {{"matrix", frame_matrix(frame.u, frame.v, frame.w,
                                            l.type == LightType::Directional ? Vec3f{} : l.position)},
                    {"extensions", {{"KHR_lights_punctual", {{"light", li}}}}},
                    {"name", l.name.empty() ? "light" + std::to_string(li) : l.name}});
    }
    wr.j["extensions"]["KHR_lights_punctual"]["lights"] = lights;
  }
}

// The document and its binary buffer; the buffer's uri is `bin_uri` (empty: none, for GLB).
Writer build_document(const Scene& scene, const std::filesystem::path& file, const std::string& bin_uri) {
  Writer wr;
  wr.file = file.string();
  wr.j = {{"asset", {{"version", "2.0"}, {"generator", "Penumbra write_gltf"}}},
          {"accessors", json::array()},
          {"bufferViews", json::array()},
          {"meshes", json::array()},
          {"nodes", json::array()},
          {"scenes", {{{"nodes", json::array()}}}},
          {"scene", 0}};
  bool emissive_strength = false, unlit = false, procedural = false;
  write_materials(wr, scene, emissive_strength, unlit, procedural);
  write_instances(wr, scene, write_meshes(wr, scene));
  write_cameras(wr, scene);
  write_lights(wr, scene);
  json used = json::array();
  if (!scene.lights.empty()) used.push_back("KHR_lights_punctual");
  if (emissive_strength) used.push_back("KHR_materials_emissive_strength");
  if (unlit) used.push_back("KHR_materials_unlit");
  if (count_shape_instances(scene) > 0) used.push_back("PENUMBRA_shapes");
  if (procedural) used.push_back(gltf::kProceduralExtension);
  if (!used.empty()) wr.j["extensionsUsed"] = used;
  if (!wr.bin.empty()) {
    wr.j["buffers"] = {{{"byteLength", wr.bin.size()}}};
    if (!bin_uri.empty()) wr.j["buffers"][0]["uri"] = bin_uri;
  }
  return wr;
}

void append_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int b = 0; b < 4; ++b) out.push_back(uint8_t(v >> (8 * b)));  // little endian
}

}  // namespace

void write_gltf(const Scene& scene, const std::filesystem::path& file) {
  const std::string bin_name = file.stem().string() + ".bin";
  const Writer wr = build_document(scene, file, bin_name);
  if (!wr.bin.empty()) {
    const auto bin_path = file.parent_path() / bin_name;
    write_atomically(bin_path, [&](const std::filesystem::path& tmp) {
      write_file_checked(tmp, wr.bin.data(), wr.bin.size(), bin_path);
    });
  }
  const std::string text = wr.j.dump(1);
  write_atomically(file, [&](const std::filesystem::path& tmp) {
    write_file_checked(tmp, text.data(), text.size(), file);
  });
}

void write_glb(const Scene& scene, const std::filesystem::path& file) {
  const Writer wr = build_document(scene, file, "");
  std::string text = wr.j.dump();
  while (text.size() % 4) text.push_back(' ');
  const size_t bin_padded = (wr.bin.size() + 3) / 4 * 4;
  const uint64_t total = 12 + 8 + text.size() + (wr.bin.empty() ? 0 : 8 + bin_padded);
  if (total > UINT32_MAX) throw InputError(file.string(), "", "a GLB file is limited to 4 GiB");
  std::vector<uint8_t> glb;
  glb.reserve(size_t(total));
  append_u32(glb, 0x46546C67u);  // "glTF"
  append_u32(glb, 2);
  append_u32(glb, uint32_t(total));
  append_u32(glb, uint32_t(text.size()));
  append_u32(glb, 0x4E4F534Au);  // "JSON"
  glb.insert(glb.end(), text.begin(), text.end());
  if (!wr.bin.empty()) {
    append_u32(glb, uint32_t(bin_padded));
    append_u32(glb, 0x004E4942u);  // "BIN\0"
    glb.insert(glb.end(), wr.bin.begin(), wr.bin.end());
    glb.resize(size_t(total), 0);
  }
  write_atomically(
      file, [&](const std::filesystem::path& tmp) { write_file_checked(tmp, glb.data(), glb.size(), file); });
}

}  // namespace penumbra
