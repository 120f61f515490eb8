// penumbra.load and penumbra.Scene: loading a glTF file with the loader's options, and what a
// scene holds as Python records (meshes, shapes, instances, cameras, lights, materials, the
// file's facts, the world bounds). Records are copies taken under the scene's lock; mesh
// geometry comes out as NumPy arrays.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "python/bindings.h"
#include "renderer/scene/scene.h"
#include "renderer/shapes/shape.h"

namespace penumbra::python {

namespace {

py::tuple tuple3(Vec3f v) {
  return py::make_tuple(v.x, v.y, v.z);
}

/// A mesh of a session: its name, counts and material, and its geometry as NumPy copies.
/// Meshes are never changed after loading, so a MeshRef reads without the lock.
struct MeshRef {
  std::shared_ptr<SceneSession> session;
  int index = 0;
  const Mesh& mesh() const { return session->loaded.scene.meshes[size_t(index)]; }
};

struct ShapeRecord {
  int index = 0;
  std::string name, kind;
  int material = -1, node = -1;
};

struct InstanceRecord {
  int index = 0;
  Instance instance;
  uint64_t triangles = 0;
};

/// (n, k) float32 copy of n records of k floats each.
template <typename T>
py::array_t<float> float_rows(const std::vector<T>& v, int k) {
  static_assert(sizeof(T) % sizeof(float) == 0);
  py::array_t<float> a({py::ssize_t(v.size()), py::ssize_t(k)});
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(T));
  return a;
}

py::array_t<double> matrix4(const Affine3f& a) {
  py::array_t<double> m({4, 4});
  auto r = m.mutable_unchecked<2>();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r(i, j) = i < 3 ? a.m[i][j] : (j == 3 ? 1.0 : 0.0);
  return m;
}

const char* light_type_name(LightType t) {
  return t == LightType::Point ? "point" : (t == LightType::Spot ? "spot" : "directional");
}

const char* alpha_mode_name(AlphaMode a) {
  return a == AlphaMode::Opaque ? "OPAQUE" : (a == AlphaMode::Mask ? "MASK" : "BLEND");
}

py::dict info_dict(const LoadedScene& loaded) {
  const GltfInfo& i = loaded.info;
  py::dict d;
  d["generator"] = i.generator;
  d["version"] = i.version;
  d["scene_count"] = i.scene_count;
  d["scene_index"] = i.scene_index;
  d["scene_names"] = i.scene_names;
  d["node_count"] = i.node_count;
  d["mesh_count"] = i.mesh_count;
  d["primitive_count"] = i.primitive_count;
  d["camera_count"] = i.gltf_camera_count;
  d["light_count"] = i.gltf_light_count;
  d["image_count"] = i.image_count;
  d["animation_count"] = i.animation_count;
  d["extensions_used"] = i.extensions_used;
  d["extensions_required"] = i.extensions_required;
  d["variants"] = i.variants;
  d["variant"] = i.variant >= 0 ? py::object(py::str(i.variants[size_t(i.variant)])) : py::object(py::none());
  d["image_light"] = i.image_light.empty() ? py::object(py::none()) : py::object(py::str(i.image_light));
  d["camera_instances"] = i.camera_instances;
  std::vector<std::string> files;
  for (const auto& f : i.source_files) files.push_back(f.string());
  d["source_files"] = files;
  d["source_sha256"] = i.source_sha256;
  return d;
}

/// Issues the loader's warnings as penumbra.SceneWarning, as many as `penumbra` prints.
void warn(const std::string& file, const std::vector<std::string>& warnings, py::handle category) {
  const size_t shown = std::min<size_t>(warnings.size(), 20);
  for (size_t i = 0; i < shown; ++i) {
    const std::string text = file + ": " + warnings[i];
    if (PyErr_WarnEx(category.ptr(), text.c_str(), 2) < 0) throw py::error_already_set();
  }
  if (warnings.size() > shown) {
    const std::string text = file + ": ... and " + std::to_string(warnings.size() - shown) + " more warnings";
    if (PyErr_WarnEx(category.ptr(), text.c_str(), 2) < 0) throw py::error_already_set();
  }
}

void bind_records(py::module_& m) {
  py::class_<MeshRef>(m, "Mesh", "A stored triangle mesh (one glTF primitive); instances place it.")
      .def_readonly("index", &MeshRef::index)
      .def_property_readonly("name", [](const MeshRef& r) { return r.mesh().name; })
      .def_property_readonly("triangle_count", [](const MeshRef& r) { return r.mesh().indices.size() / 3; })
      .def_property_readonly("vertex_count", [](const MeshRef& r) { return r.mesh().positions.size(); })
      .def_property_readonly(
          "material", [](const MeshRef& r) { return r.mesh().material; }, "material index, -1 = the default")
      .def_property_readonly(
          "node", [](const MeshRef& r) { return r.mesh().node; },
          "glTF node of a mesh moved into world space, -1 for a mesh its instances place")
      .def_property_readonly(
          "positions", [](const MeshRef& r) { return float_rows(r.mesh().positions, 3); },
          "float32 (vertex_count, 3): in world space if the mesh's instance is the identity, else in object "
          "space")
      .def_property_readonly(
          "normals", [](const MeshRef& r) { return float_rows(r.mesh().normals, 3); },
          "float32 (vertex_count, 3)")
      .def_property_readonly(
          "uvs", [](const MeshRef& r) { return float_rows(r.mesh().uvs, 2); },
          "float32 (n, 2), TEXCOORD_0 (n = 0 if absent)")
      .def_property_readonly(
          "indices",
          [](const MeshRef& r) {
            const auto& idx = r.mesh().indices;
            py::array_t<uint32_t> a({py::ssize_t(idx.size() / 3), py::ssize_t(3)});
            if (!idx.empty()) std::memcpy(a.mutable_data(), idx.data(), idx.size() * sizeof(uint32_t));
            return a;
          },
          "uint32 (triangle_count, 3), counter-clockwise = front")
      .def("__repr__", [](const MeshRef& r) {
        return "<penumbra.Mesh " + std::to_string(r.index) + " '" + r.mesh().name +
               "': " + std::to_string(r.mesh().indices.size() / 3) + " triangles>";
      });

  py::class_<ShapeRecord>(m, "Shape", "An analytic primitive or implicit surface (PENUMBRA_shapes).")
      .def_readonly("index", &ShapeRecord::index)
      .def_readonly("name", &ShapeRecord::name)
      .def_readonly("kind", &ShapeRecord::kind, "sphere, disk, plane, box, capsule or implicit")
      .def_readonly("material", &ShapeRecord::material)
      .def_readonly("node", &ShapeRecord::node)
      .def("__repr__", [](const ShapeRecord& s) {
        return "<penumbra.Shape " + std::to_string(s.index) + " '" + s.name + "': " + s.kind + ">";
      });

  py::class_<InstanceRecord>(m, "Instance", "One placement of a mesh or a shape in the world.")
      .def_readonly("index", &InstanceRecord::index)
      .def_property_readonly(
          "mesh", [](const InstanceRecord& r) { return r.instance.shape >= 0 ? -1 : r.instance.mesh; },
          "mesh index, -1 when it places a shape")
      .def_property_readonly(
          "shape", [](const InstanceRecord& r) { return r.instance.shape; }, "shape index, or -1")
      .def_property_readonly(
          "node", [](const InstanceRecord& r) { return r.instance.node; },
          "glTF node (the id AOV's object id is node + 1), -1 if not from glTF")
      .def_property_readonly(
          "copy", [](const InstanceRecord& r) { return r.instance.copy; },
          "EXT_mesh_gpu_instancing instance within the node, else -1")
      .def_property_readonly("identity", [](const InstanceRecord& r) { return r.instance.identity; })
      .def_property_readonly("mirrored", [](const InstanceRecord& r) { return r.instance.mirrored; })
      .def_property_readonly(
          "to_world", [](const InstanceRecord& r) { return matrix4(r.instance.to_world); },
          "float64 (4, 4) object-to-world matrix (column vectors: p_world = M @ [p, 1])")
      .def_readonly("triangle_count", &InstanceRecord::triangles, "triangles it renders (0 for a shape)")
      .def("__repr__", [](const InstanceRecord& r) {
        return "<penumbra.Instance " + std::to_string(r.index) + ": " +
               (r.instance.shape >= 0 ? "shape " + std::to_string(r.instance.shape)
                                      : "mesh " + std::to_string(r.instance.mesh)) +
               ", node " + std::to_string(r.instance.node) + ">";
      });

  py::class_<Camera>(m, "Camera", "A camera in world space (looking along -back).")
      .def_readonly("name", &Camera::name)
      .def_property_readonly("projection",
                             [](const Camera& c) {
                               return c.projection == Projection::Perspective ? "perspective"
                                                                              : "orthographic";
                             })
      .def_property_readonly("eye", [](const Camera& c) { return tuple3(c.eye); })
      .def_property_readonly("right", [](const Camera& c) { return tuple3(c.u); })
      .def_property_readonly("up", [](const Camera& c) { return tuple3(c.v); })
      .def_property_readonly("back", [](const Camera& c) { return tuple3(c.w); })
      .def_property_readonly("forward", [](const Camera& c) { return tuple3(-c.w); })
      .def_readonly("yfov", &Camera::yfov, "perspective: vertical field of view, radians")
      .def_readonly("aspect", &Camera::aspect, "the file's aspect-ratio hint (width / height), 0 = none")
      .def_readonly("xmag", &Camera::xmag, "orthographic half-width")
      .def_readonly("ymag", &Camera::ymag, "orthographic half-height")
      .def_readonly("znear", &Camera::znear)
      .def_readonly("zfar", &Camera::zfar, "inf for an infinite perspective")
      .def("__repr__", [](const Camera& c) {
        return "<penumbra.Camera '" + c.name + "' " +
               (c.projection == Projection::Perspective ? "perspective" : "orthographic") + ">";
      });

  py::class_<Light>(m, "Light", "A KHR_lights_punctual light in world space.")
      .def_readonly("name", &Light::name)
      .def_property_readonly("type", [](const Light& l) { return light_type_name(l.type); })
      .def_property_readonly("color", [](const Light& l) { return tuple3(l.color); })
      .def_readonly("intensity", &Light::intensity, "candela (point, spot) or lux (directional)")
      .def_property_readonly("position", [](const Light& l) { return tuple3(l.position); })
      .def_property_readonly(
          "direction", [](const Light& l) { return tuple3(l.direction); },
          "unit direction the light travels (spot, directional)")
      .def_readonly("range", &Light::range)
      .def_readonly("inner_cone", &Light::inner_cone, "radians")
      .def_readonly("outer_cone", &Light::outer_cone, "radians")
      .def("__repr__", [](const Light& l) {
        return "<penumbra.Light '" + l.name + "' " + light_type_name(l.type) + ">";
      });

  py::class_<Material>(m, "Material", "A glTF metallic-roughness material's main factors.")
      .def_readonly("name", &Material::name)
      .def_property_readonly(
          "base_color", [](const Material& x) { return tuple3(x.base_color); }, "linear RGB baseColorFactor")
      .def_readonly("alpha", &Material::alpha)
      .def_readonly("metallic", &Material::metallic)
      .def_readonly("roughness", &Material::roughness)
      .def_property_readonly(
          "emissive", [](const Material& x) { return tuple3(x.emissive); },
          "emissiveFactor x KHR_materials_emissive_strength")
      .def_readonly("unlit", &Material::unlit)
      .def_property_readonly("alpha_mode", [](const Material& x) { return alpha_mode_name(x.alpha_mode); })
      .def_readonly("alpha_cutoff", &Material::alpha_cutoff)
      .def_readonly("double_sided", &Material::double_sided)
      .def_readonly("ior", &Material::ior)
      .def_readonly("transmission", &Material::transmission)
      .def_readonly("clearcoat", &Material::clearcoat)
      .def_property_readonly("has_base_color_texture",
                             [](const Material& x) { return x.base_color_tex.texture >= 0; })
      .def_property_readonly(
          "procedural", [](const Material& x) { return x.procedural >= 0; },
          "a PENUMBRA_procedural texture drives it")
      .def("__repr__", [](const Material& x) { return "<penumbra.Material '" + x.name + "'>"; });
}

std::shared_ptr<SceneSession> load(const std::filesystem::path& path, std::optional<int> scene,
                                   const std::string& variant, std::optional<double> time, bool flatten,
                                   std::optional<uint64_t> max_memory, bool allow_external_uris,
                                   bool keep_animation, std::optional<uint64_t> max_file_bytes,
                                   std::optional<int> max_json_depth, bool quiet, py::handle warning) {
  GltfLoadOptions opt;
  opt.scene = scene.value_or(-1);
  opt.variant = variant;
  opt.time = time;
  opt.flatten = flatten;
  opt.max_memory_bytes = max_memory.value_or(default_memory_budget());
  opt.allow_external_uris = allow_external_uris;
  opt.keep_animation = keep_animation;
  if (max_file_bytes) opt.max_file_bytes = *max_file_bytes;
  if (max_json_depth) opt.max_json_depth = *max_json_depth;
  if (opt.scene < -1) throw py::value_error("scene must be >= 0 (None: the file's default scene)");
  if (time && !std::isfinite(*time)) throw py::value_error("time must be a finite number of seconds");
  std::shared_ptr<SceneSession> session;
  {
    py::gil_scoped_release release;
    session = load_session(path.string(), opt);
  }
  if (!quiet) warn(session->file, session->loaded.warnings, warning);
  return session;
}

}  // namespace

SceneClass bind_scene(py::module_& m) {
  py::object warning = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
      "penumbra.SceneWarning", "Degenerate but harmless content the loader skipped (it names the element).",
      PyExc_UserWarning, nullptr));
  if (!warning.ptr()) throw py::error_already_set();
  m.attr("SceneWarning") = warning;
  bind_records(m);

  using SessionPtr = std::shared_ptr<SceneSession>;
  SceneClass scene(m, "Scene",
                   "A loaded glTF scene (penumbra.load). Its lists are snapshots; "
                   "renders of one scene run one at a time.");
  scene.def_property_readonly("file", [](const SceneSession& s) { return s.file; })
      .def_property_readonly(
          "warnings", [](const SceneSession& s) { return s.loaded.warnings; },
          "the loader's warnings, each naming its element")
      .def_property_readonly(
          "info", [](const SceneSession& s) { return info_dict(s.loaded); },
          "facts about the file: generator, counts as the file declares them, scene "
          "names, extensions, variants, source files and their SHA-256")
      .def_property_readonly("node_names", [](const SceneSession& s) { return s.loaded.info.node_names; })
      .def_property_readonly("meshes",
                             [](const SessionPtr& s) {
                               std::vector<MeshRef> v;
                               for (size_t i = 0; i < s->loaded.scene.meshes.size(); ++i)
                                 v.push_back({s, int(i)});
                               return v;
                             })
      .def_property_readonly("shapes",
                             [](const SceneSession& s) {
                               std::vector<ShapeRecord> v;
                               const auto& shapes = s.loaded.scene.shapes;
                               for (size_t i = 0; i < shapes.size(); ++i)
                                 v.push_back({int(i), shapes[i].name, shape_kind_name(shapes[i].shape.kind),
                                              shapes[i].material, shapes[i].node});
                               return v;
                             })
      .def_property_readonly("instances",
                             [](SceneSession& s) {
                               SessionLock lock(s);
                               const Scene& sc = s.loaded.scene;
                               std::vector<InstanceRecord> v;
                               for (size_t i = 0; i < sc.instances.size(); ++i) {
                                 const Instance& inst = sc.instances[i];
                                 const uint64_t tris =
                                     inst.shape >= 0 ? 0 : sc.meshes[size_t(inst.mesh)].indices.size() / 3;
                                 v.push_back({int(i), inst, tris});
                               }
                               return v;
                             })
      .def_property_readonly("cameras",
                             [](SceneSession& s) {
                               SessionLock lock(s);
                               return s.loaded.scene.cameras;
                             })
      .def_property_readonly("lights",
                             [](SceneSession& s) {
                               SessionLock lock(s);
                               return s.loaded.scene.lights;
                             })
      .def_property_readonly("materials", [](const SceneSession& s) { return s.loaded.scene.materials; })
      .def_property_readonly(
          "bounds",
          [](SceneSession& s) -> py::object {
            SessionLock lock(s);
            const Bounds3f b = compute_bounds(s.loaded.scene);
            if (b.empty()) return py::none();
            return py::make_tuple(tuple3(b.lo), tuple3(b.hi));
          },
          "world-space bounds ((x0, y0, z0), (x1, y1, z1)) of everything rendered, None if empty")
      .def_property_readonly(
          "triangle_count",
          [](SceneSession& s) {
            SessionLock lock(s);
            return count_triangles(s.loaded.scene);
          },
          "triangles rendered: each mesh once per instance")
      .def_property_readonly("stored_triangle_count",
                             [](const SceneSession& s) { return count_stored_triangles(s.loaded.scene); })
      .def_property_readonly(
          "has_environment", [](const SceneSession& s) { return s.loaded.environment != nullptr; },
          "the file's EXT_lights_image_based light lights path renders")
      .def_property_readonly(
          "animated", [](const SceneSession& s) { return s.loaded.animation != nullptr; },
          "loaded with a time and keep_animation: pose() can move it")
      .def(
          "pose",
          [](SceneSession& s, double time) {
            if (!std::isfinite(time)) throw py::value_error("time must be a finite number of seconds");
            py::gil_scoped_release release;
            std::lock_guard<std::mutex> lock(s.mutex);
            return pose_session(s, time);
          },
          py::arg("time"),
          "Moves instances, cameras and lights to `time` seconds without loading the file again (the "
          "scene must be loaded with time= and keep_animation=True). False, with the scene unchanged, "
          "when the animation changes more than placements: load the file again at that time.")
      .def("__repr__", [](const SceneSession& s) {
        return "<penumbra.Scene '" + s.file + "': " + std::to_string(s.loaded.scene.meshes.size()) +
               " meshes, " + std::to_string(s.loaded.scene.instances.size()) + " instances>";
      });

  m.def(
      "load",
      [warning](const std::filesystem::path& path, std::optional<int> scene_index, const std::string& variant,
                std::optional<double> time, bool flatten, std::optional<uint64_t> max_memory,
                bool allow_external_uris, bool keep_animation, std::optional<uint64_t> max_file_bytes,
                std::optional<int> max_json_depth, bool quiet) {
        return load(path, scene_index, variant, time, flatten, max_memory, allow_external_uris,
                    keep_animation, max_file_bytes, max_json_depth, quiet, warning);
      },
      py::arg("path"), py::kw_only(), py::arg("scene") = py::none(), py::arg("variant") = "",
      py::arg("time") = py::none(), py::arg("flatten") = false, py::arg("max_memory") = py::none(),
      py::arg("allow_external_uris") = false, py::arg("keep_animation") = false,
      py::arg("max_file_bytes") = py::none(), py::arg("max_json_depth") = py::none(),
      py::arg("quiet") = false,
      "Loads a .gltf or .glb file.\n\n"
      "scene: glTF scene index (None: the file's default); variant: KHR_materials_variants name; time: "
      "animation time in seconds (None: the static pose); flatten: a world-space copy per placement (no "
      "instancing); max_memory: bytes for decoded geometry (None: half the RAM, as `penumbra`); "
      "allow_external_uris: URIs may leave the file's folder; keep_animation: with time, keep what "
      "Scene.pose needs; max_file_bytes, max_json_depth: the loader's limits (None: its defaults); quiet: "
      "no penumbra.SceneWarning for the loader's warnings (Scene.warnings keeps them).\n\n"
      "Raises penumbra.InputError with the message `penumbra` prints for the same file.");
  return scene;
}

}  // namespace penumbra::python
