// The scene description and accelerator statistics of `penumbra info`, as text or JSON.
#include "apps/penumbra/info_command.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/scene_setup.h"
#include "render/session.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/scene/camera.h"
#include "renderer/scene/volume.h"

namespace penumbra::cli {

namespace {

// A shape's kind and size in a few words: "sphere (radius 1)", "implicit (7 CSG nodes)".
std::string describe_shape(const Shape& sh) {
  char buf[96];
  switch (sh.kind) {
    case ShapeKind::Sphere:
    case ShapeKind::Disk:
      std::snprintf(buf, sizeof buf, "(radius %.4g)", sh.radius);
      break;
    case ShapeKind::Plane:
      std::snprintf(buf, sizeof buf, "(%.4g x %.4g)", 2 * sh.half_size.x, 2 * sh.half_size.z);
      break;
    case ShapeKind::Box:
      std::snprintf(buf, sizeof buf, "(%.4g x %.4g x %.4g)", 2 * sh.half_size.x, 2 * sh.half_size.y,
                    2 * sh.half_size.z);
      break;
    case ShapeKind::Capsule:
      std::snprintf(buf, sizeof buf, "(radius %.4g, height %.4g)", sh.radius, 2 * sh.half_height);
      break;
    case ShapeKind::Segment:
      std::snprintf(buf, sizeof buf, "(radius %.4g, length %.4g)", sh.radius, length(sh.p1 - sh.p0));
      break;
    case ShapeKind::Splat:
      std::snprintf(buf, sizeof buf, "(opacity %.4g)", sh.opacity);
      break;
    case ShapeKind::Implicit:
      std::snprintf(buf, sizeof buf, "(%zu CSG node%s)", sh.sdf.nodes.size(),
                    sh.sdf.nodes.size() == 1 ? "" : "s");
      break;
  }
  return std::string(shape_kind_name(sh.kind)) + " " + buf;
}

// A procedural texture in one line: pattern, space and what it drives.
std::string describe_procedural(const ProceduralTexture& t) {
  static const char* kPatterns[] = {"noise", "voronoi", "wave"};
  static const char* kFractals[] = {"fbm", "turbulence", "ridged"};
  static const char* kSpaces[] = {"object", "world", "uv"};
  std::string d = kPatterns[int(t.kind)];
  if (t.kind != PatternKind::Voronoi) d += std::string(" (") + kFractals[int(t.fractal.kind)] + ")";
  d += std::string(" in ") + kSpaces[int(t.space)] + " space, seed " + std::to_string(t.seed) + "; drives";
  std::string drives;
  if (t.drives_base_color) drives += " base colour,";
  if (t.roughness.enabled) drives += " roughness,";
  if (t.metallic.enabled) drives += " metallic,";
  if (t.emission_strength.enabled) drives += " emission,";
  if (t.bump_height != 0) drives += " bump,";
  if (drives.empty()) drives = " nothing,";
  drives.pop_back();
  return d + drives;
}

// The shapes line and one line per shape: its node, kind, material and instance count.
void print_shapes(const Scene& s, const GltfInfo& i) {
  std::vector<size_t> placed(s.shapes.size(), 0);
  for (const Instance& inst : s.instances)
    if (inst.shape >= 0) ++placed[size_t(inst.shape)];
  std::printf("shapes       %zu, %llu instances\n", s.shapes.size(),
              static_cast<unsigned long long>(count_shape_instances(s)));
  for (size_t k = 0; k < s.shapes.size(); ++k) {
    const SceneShape& sh = s.shapes[k];
    const std::string node = sh.node >= 0 ? "nodes[" + std::to_string(sh.node) + "]" : "no node";
    const bool named =
        sh.node >= 0 && size_t(sh.node) < i.node_names.size() && i.node_names[size_t(sh.node)] != node;
    const std::string material = sh.material >= 0 ? "material " + std::to_string(sh.material) + " '" +
                                                        s.materials[size_t(sh.material)].name + "'"
                                                  : "default material";
    std::printf("  [%zu] %s%s%s: %s, %s, %zu instance%s\n", k, node.c_str(), named ? " '" : "",
                named ? (i.node_names[size_t(sh.node)] + "'").c_str() : "", describe_shape(sh.shape).c_str(),
                material.c_str(), placed[k], placed[k] == 1 ? "" : "s");
  }
}

/// How far Penumbra implements an extension: "supported", "partial" (with what is missing) or
/// "unsupported".
struct ExtensionSupport {
  std::string support, note;
};

ExtensionSupport extension_support(const std::string& e) {
  const std::vector<std::string> supported = supported_gltf_extensions();
  const auto partial = partial_gltf_extensions();
  const auto p = std::find_if(partial.begin(), partial.end(), [&](const auto& x) { return x.first == e; });
  if (p != partial.end()) return {"partial", p->second};
  if (std::find(supported.begin(), supported.end(), e) != supported.end()) return {"supported", ""};
  return {"unsupported", "ignored"};
}

// Each used extension as supported, partially supported (with what is missing) or not supported.
void print_extension_support(const std::vector<std::string>& used) {
  for (const auto& e : used) {
    const ExtensionSupport x = extension_support(e);
    if (x.support == "partial")
      std::printf("  %-40s partially supported: %s\n", e.c_str(), x.note.c_str());
    else if (x.support == "supported")
      std::printf("  %-40s supported\n", e.c_str());
    else
      std::printf("  %-40s not supported (ignored)\n", e.c_str());
  }
}

const char* light_type_name(LightType t) {
  return t == LightType::Point ? "point" : (t == LightType::Spot ? "spot" : "directional");
}

/// A float as the double of its shortest decimal form (0.8f -> 0.8, not 0.800000011920929), so
/// that values read back equal those the file wrote.
double num(float v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::strtod(std::string(buf, r.ptr).c_str(), nullptr);
}

nlohmann::ordered_json vec3(Vec3f v) {
  return {num(v.x), num(v.y), num(v.z)};
}

/// A finite number, or null (an infinite zfar).
nlohmann::ordered_json finite_or_null(float v) {
  return std::isfinite(v) ? nlohmann::ordered_json(num(v)) : nlohmann::ordered_json();
}

/// The camera render would use, for the image size it would render.
struct View {
  Camera camera;
  std::string source;  ///< what placed it, in words
  int width = 0, height = 0;
  Transform view, projection;
};

View resolve_view(const InfoArgs& a, const Scene& s) {
  const long long frame = a.frame.empty() ? 0 : parse_integer(a.frame, -(1ll << 40), 1ll << 40, "--frame");
  const CameraRig rig = check_camera_args(a.cam, frame);
  const int index = base_camera_index(s, a.camera, a.cam, a.file);
  View v;
  std::tie(v.width, v.height) = image_size(a.width, a.height, aspect_hint(s, index));
  v.camera = choose_camera(rig, s, index, v.width, v.height);
  const std::string lens =
      index >= 0 ? "camera " + std::to_string(index) + " '" + s.cameras[size_t(index)].name + "'"
                 : std::string("the default lens");
  switch (rig.placement) {
    case CameraPlacement::Base:
      v.source = index >= 0 ? lens : "auto-framed on the bounds";
      break;
    case CameraPlacement::LookAt:
      v.source = "--look-at, " + lens;
      break;
    case CameraPlacement::Orbit:
      v.source = (rig.turntable_frames > 0 ? "--turntable frame " + std::to_string(rig.turntable_frame) +
                                                 " of " + std::to_string(rig.turntable_frames)
                                           : std::string("--orbit")) +
                 ", " + lens;
      break;
    case CameraPlacement::Euler:
      v.source = "--euler, " + lens;
      break;
  }
  v.view = view_matrix(v.camera);
  v.projection = projection_matrix(v.camera, float(v.width) / float(v.height));
  return v;
}

nlohmann::ordered_json matrix_json(const Transform& t) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const auto& row : t.m) rows.push_back({row[0], row[1], row[2], row[3]});
  return rows;
}

nlohmann::ordered_json view_json(const View& v) {
  using J = nlohmann::ordered_json;
  const Camera& c = v.camera;
  const bool ortho = c.projection == Projection::Orthographic;
  return J{{"source", v.source},
           {"width", v.width},
           {"height", v.height},
           {"type", ortho ? "orthographic" : "perspective"},
           {"yfov", ortho ? J() : J(num(c.yfov))},
           {"ymag", ortho ? J(num(c.ymag)) : J()},
           {"znear", num(c.znear)},
           {"zfar", finite_or_null(c.zfar)},
           {"eye", vec3(c.eye)},
           {"u", vec3(c.u)},
           {"v", vec3(c.v)},
           {"w", vec3(c.w)},
           {"view_matrix", matrix_json(v.view)},
           {"projection_matrix", matrix_json(v.projection)}};
}

void print_matrix(const char* title, const Transform& t) {
  std::printf("  %s\n", title);
  for (const auto& row : t.m)
    std::printf("    [%12.6g %12.6g %12.6g %12.6g ]\n", row[0], row[1], row[2], row[3]);
}

void print_view(const View& v) {
  const Camera& c = v.camera;
  std::printf("view         %s, %dx%d\n", v.source.c_str(), v.width, v.height);
  if (c.projection == Projection::Orthographic)
    std::printf("  lens       orthographic, height %.6g", 2 * double(c.ymag));
  else
    std::printf("  lens       perspective, vertical fov %.6g degrees", double(c.yfov) * 180 / M_PI);
  std::printf(", near %.6g, far %.6g\n", double(c.znear), double(c.zfar));
  std::printf("  eye        (%.6g, %.6g, %.6g), looking along (%.6g, %.6g, %.6g), up (%.6g, %.6g, %.6g)\n",
              c.eye.x, c.eye.y, c.eye.z, -c.w.x, -c.w.y, -c.w.z, c.v.x, c.v.y, c.v.z);
  print_matrix("view matrix (world to camera, camera looks down -Z)", v.view);
  print_matrix("projection matrix (glTF: clip space, depth -1..1 from near to far)", v.projection);
}

/// The description as one JSON document (schema: docs/reference/formats.md).
nlohmann::ordered_json info_json(const std::string& file, const LoadedScene& loaded, const View& view,
                                 const AccelStats& st) {
  using J = nlohmann::ordered_json;
  const Scene& s = loaded.scene;
  const GltfInfo& i = loaded.info;
  J j;
  j["schema"] = 1;
  j["file"] = file;
  j["asset"] = {{"version", i.version}, {"generator", i.generator}};
  j["scenes"] = J::array();
  for (int k = 0; k < i.scene_count; ++k)
    j["scenes"].push_back(
        {{"index", k}, {"name", i.scene_names[size_t(k)]}, {"rendered", k == i.scene_index}});
  j["scene"] = i.scene_index >= 0 ? J(i.scene_index) : J();
  j["nodes"] = i.node_count;
  j["meshes"] = J::array();
  for (const GltfMeshInfo& m : i.meshes)
    j["meshes"].push_back({{"name", m.name}, {"primitives", m.primitives}, {"triangles", m.triangles}});
  j["primitives"] = i.primitive_count;
  j["stored"] = {{"meshes", s.meshes.size()}, {"triangles", count_stored_triangles(s)}};
  const size_t placed = size_t(
      std::count_if(s.instances.begin(), s.instances.end(), [](const Instance& x) { return !x.identity; }));
  j["instances"] = {{"count", s.instances.size()},
                    {"world_space", s.instances.size() - placed},
                    {"placed", placed},
                    {"triangles", count_triangles(s)},
                    {"points", count_points(s)},
                    {"line_segments", count_line_segments(s)}};
  uint64_t splats = 0;
  for (const SplatInstance& si : s.splat_instances)
    splats += s.splat_clouds[size_t(si.cloud)].positions.size();
  j["splats"] = {
      {"clouds", s.splat_clouds.size()}, {"instances", s.splat_instances.size()}, {"placed", splats}};
  std::vector<size_t> shape_uses(s.shapes.size(), 0);
  for (const Instance& inst : s.instances)
    if (inst.shape >= 0) ++shape_uses[size_t(inst.shape)];
  j["shapes"] = J::array();
  for (size_t k = 0; k < s.shapes.size(); ++k) {
    const SceneShape& sh = s.shapes[k];
    j["shapes"].push_back({{"index", k},
                           {"node", sh.node >= 0 ? J(sh.node) : J()},
                           {"name", sh.name},
                           {"kind", shape_kind_name(sh.shape.kind)},
                           {"description", describe_shape(sh.shape)},
                           {"material", sh.material >= 0 ? J(sh.material) : J()},
                           {"instances", shape_uses[k]}});
  }
  j["materials"] = J::array();
  for (size_t k = 0; k < s.materials.size(); ++k) {
    const Material& m = s.materials[k];
    j["materials"].push_back(
        {{"index", k},
         {"name", m.name},
         {"base_color", vec3(m.base_color)},
         {"metallic", num(m.metallic)},
         {"roughness", num(m.roughness)},
         {"emissive", vec3(m.emissive)},
         {"procedural",
          m.procedural >= 0 ? J(describe_procedural(s.procedurals[size_t(m.procedural)])) : J()}});
  }
  j["cameras_defined"] = i.gltf_camera_count;
  j["cameras"] = J::array();
  for (size_t k = 0; k < s.cameras.size(); ++k) {
    const Camera& c = s.cameras[k];
    const bool ortho = c.projection == Projection::Orthographic;
    J cam = {{"index", k},
             {"name", c.name},
             {"type", ortho ? "orthographic" : "perspective"},
             {"yfov", ortho ? J() : J(num(c.yfov))},
             {"aspect", c.aspect > 0 ? J(num(c.aspect)) : J()},
             {"znear", num(c.znear)},
             {"zfar", finite_or_null(c.zfar)}};
    if (ortho) {
      cam["xmag"] = num(c.xmag);
      cam["ymag"] = num(c.ymag);
    }
    cam["description"] = k < i.camera_instances.size() ? i.camera_instances[k] : std::string();
    j["cameras"].push_back(cam);
  }
  j["lights_defined"] = i.gltf_light_count;
  j["lights"] = J::array();
  for (size_t k = 0; k < s.lights.size(); ++k) {
    const Light& l = s.lights[k];
    j["lights"].push_back({{"index", k},
                           {"name", l.name},
                           {"type", light_type_name(l.type)},
                           {"intensity", num(l.intensity)},
                           {"unit", l.type == LightType::Directional ? "lux" : "cd"},
                           {"color", vec3(l.color)}});
  }
  j["images"] = i.image_count;
  j["textures"] = s.textures.size();
  j["animations"] = i.animation_count;
  j["extensions"] = J::array();
  std::vector<std::string> named = i.extensions_used;
  for (const auto& e : i.extensions_required)
    if (std::find(named.begin(), named.end(), e) == named.end()) named.push_back(e);
  for (const auto& e : named) {
    const ExtensionSupport x = extension_support(e);
    const bool required = std::find(i.extensions_required.begin(), i.extensions_required.end(), e) !=
                          i.extensions_required.end();
    j["extensions"].push_back(
        {{"name", e}, {"required", required}, {"support", x.support}, {"note", x.note}});
  }
  j["variants"] = i.variants;
  j["environment"] = loaded.environment ? J{{"light", i.image_light},
                                            {"width", loaded.environment->width},
                                            {"height", loaded.environment->height}}
                                        : J();
  const Bounds3f b = compute_bounds(s);
  j["bounds"] = b.empty() ? J() : J{{"min", vec3(b.lo)}, {"max", vec3(b.hi)}};
  // Node figures are null where the structure keeps none (Embree; a grid has cells, not a tree).
  const bool tree = st.nodes > 0 && st.name != "grid";
  const auto figure = [](bool known, auto v) { return known ? J(v) : J(); };
  j["accelerator"] = {{"name", st.name},
                      {"config", st.config},
                      {"triangles", st.triangles},
                      {"shapes", st.shapes},
                      {"instances", st.instances},
                      {"build_seconds", st.build_seconds},
                      {"bytes", st.bytes},
                      {"nodes", figure(st.nodes > 0, st.nodes)},
                      {"leaves", figure(tree, st.leaves)},
                      {"empty_leaves", figure(st.nodes > 0, st.empty_leaves)},
                      {"references", figure(st.nodes > 0, st.references)},
                      {"avg_leaf_triangles", figure(st.nodes > 0, st.avg_leaf_prims)},
                      {"max_leaf_triangles", figure(st.nodes > 0, st.max_leaf_prims)},
                      {"max_depth", figure(tree, st.max_depth)},
                      {"sah_cost", figure(st.sah_cost > 0, st.sah_cost)}};
  j["warnings"] = loaded.warnings;
  j["view"] = view_json(view);
  return j;
}

/// What an instance is, for the volumes section: "mesh NAME" or the shape's kind.
std::string instance_what(const Scene& s, const Instance& inst) {
  return inst.shape >= 0 ? std::string(shape_kind_name(s.shapes[size_t(inst.shape)].shape.kind))
                         : "mesh \"" + s.meshes[size_t(inst.mesh)].name + "\"";
}

std::string node_name(const LoadedScene& loaded, int node) {
  return node >= 0 && size_t(node) < loaded.info.node_names.size() ? loaded.info.node_names[size_t(node)]
                                                                   : "";
}

nlohmann::ordered_json volumes_json(const LoadedScene& loaded) {
  using J = nlohmann::ordered_json;
  const Scene& s = loaded.scene;
  J list = J::array();
  for (const InstanceVolume& v : instance_volumes(s)) {
    const Instance& inst = s.instances[v.instance];
    J e{{"instance", v.instance},
        {"node", inst.node},
        {"node_name", node_name(loaded, inst.node)},
        {"kind", inst.shape >= 0 ? shape_kind_name(s.shapes[size_t(inst.shape)].shape.kind) : "mesh"},
        {"closed", v.closed},
        {"volume", v.closed ? J(v.volume) : J()},
        {"error", v.closed ? J(v.error) : J()}};
    if (inst.shape < 0) {
      e["mesh"] = inst.mesh;
      e["inward"] = v.inward;
      e["open_edges"] = v.open_edges;
      e["bad_edges"] = v.bad_edges;
    }
    list.push_back(std::move(e));
  }
  return list;
}

void print_volumes(const LoadedScene& loaded) {
  const Scene& s = loaded.scene;
  const std::vector<InstanceVolume> vols = instance_volumes(s);
  double total = 0;
  size_t closed = 0;
  for (const InstanceVolume& v : vols)
    if (v.closed) total += v.volume, ++closed;
  std::printf("volumes      %zu of %zu instances closed, %.6g enclosed in all\n", closed, vols.size(), total);
  for (const InstanceVolume& v : vols) {
    const Instance& inst = s.instances[v.instance];
    std::string text;
    if (v.closed)
      text = format("%.6g", v.volume) + (v.error > 0 ? format(" +- %.2g", v.error) : std::string()) +
             (v.inward ? " (faces inwards)" : "");
    else if (inst.shape >= 0)
      text = "not closed";
    else
      text =
          format("not closed (%llu open edges, %llu shared by more than two faces or the same way)",
                 static_cast<unsigned long long>(v.open_edges), static_cast<unsigned long long>(v.bad_edges));
    std::printf("  [%u] node %d \"%s\", %s: %s\n", v.instance, inst.node,
                node_name(loaded, inst.node).c_str(), instance_what(s, inst).c_str(), text.c_str());
  }
}

}  // namespace

void add_info_options(CLI::App& info, InfoArgs& a) {
  info.add_option("scene", a.file, "glTF scene (.gltf or .glb)")->required();
  info.add_option("--scene", a.scene, "glTF scene index")->check(CLI::Range(0, 1 << 30));
  info.add_option(
      "--accel", a.accel,
      "acceleration structure to build and describe: " + accelerator_list() + " (embree by default)");
  info.add_option("--accel-param", a.accel_params, accel_param_help())->type_name("KEY=VALUE");
  info.add_flag("--allow-external-uris", a.allow_external,
                "let buffer URIs reach files outside the scene's folder");
  info.add_flag("--flatten", a.flatten, "as for render: no instancing");
  info.add_flag("--json", a.json,
                "print the description as one JSON document (the schema is in the reference, "
                "docs/reference/formats.md)");
  info.add_option("--camera", a.camera, "as for render: the camera the view section describes");
  info.add_option("--width", a.width, "as for render: the image width the view is described for")
      ->check(CLI::Range(1, 16384));
  info.add_option("--height", a.height, "as for render: the image height")->check(CLI::Range(1, 16384));
  info.add_option("--frame", a.frame, "the --turntable frame the view section describes (default 0)");
  info.add_flag(
      "--volumes", a.volumes,
      "add each instance's enclosed volume: closed meshes by the divergence theorem, analytic shapes "
      "exactly, implicit ones with an error bound");
  add_camera_options(info, a.cam);
}

int run_info(const InfoArgs& a) {
  const std::string& file = a.file;
  // The structure's name and parameters, checked before loading with the command's messages.
  parse_accel(a.accel, a.accel_params);
  // Bad camera flags fail before the scene loads.
  if (!a.frame.empty() && a.cam.turntable.empty())
    throw UsageError("info: --frame picks a --turntable frame");
  check_camera_args(a.cam);
  LoadedScene loaded = load_scene(file, a.scene, a.allow_external, a.flatten, default_memory_budget(), false);
  const Scene& s = loaded.scene;
  const GltfInfo& i = loaded.info;
  const View view = resolve_view(a, s);
  // The structure as a render of these settings builds it (the render session's build phase).
  RenderSpec spec;
  spec.accel = a.accel;
  spec.accel_params = a.accel_params;
  if (a.json) {
    const auto accel = build_structure(s, spec, false).accel;
    nlohmann::ordered_json j = info_json(file, loaded, view, accel->stats());
    if (a.volumes) j["volumes"] = volumes_json(loaded);
    const std::string doc = j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
    std::printf("%s\n", doc.c_str());
    return kExitOk;
  }
  std::printf("file         %s\n", file.c_str());
  std::printf("asset        glTF %s%s%s\n", i.version.c_str(),
              i.generator.empty() ? "" : ", generator: ", i.generator.c_str());
  std::printf("scenes       %d", i.scene_count);
  for (int k = 0; k < i.scene_count; ++k)
    std::printf("%s%d: %s%s", k ? ", " : " (", k, i.scene_names[size_t(k)].c_str(),
                k == i.scene_index ? " [rendered]" : "");
  std::printf("%s\n", i.scene_count ? ")" : "");
  std::printf("nodes        %d\n", i.node_count);
  std::printf("meshes       %d (%d primitives); stored: %zu triangle meshes, %llu triangles\n", i.mesh_count,
              i.primitive_count, s.meshes.size(), static_cast<unsigned long long>(count_stored_triangles(s)));
  const size_t placed = size_t(
      std::count_if(s.instances.begin(), s.instances.end(), [](const Instance& x) { return !x.identity; }));
  std::printf("instances    %zu (%zu in world space, %zu placed by a transform), %llu triangles rendered\n",
              s.instances.size(), s.instances.size() - placed, placed,
              static_cast<unsigned long long>(count_triangles(s)));
  if (const uint64_t points = count_points(s))
    std::printf("points       %llu (rendered as spheres of --point-size unless the file sizes them)\n",
                static_cast<unsigned long long>(points));
  if (!s.splat_instances.empty()) {
    uint64_t splats = 0;
    int degree = 0;
    for (const SplatInstance& si : s.splat_instances)
      splats += s.splat_clouds[size_t(si.cloud)].positions.size();
    for (const SplatCloud& c : s.splat_clouds) degree = std::max(degree, c.sh_degree);
    std::printf(
        "splats       %llu in %zu placements of %zu clouds, spherical harmonics to degree %d "
        "(KHR_gaussian_splatting: ray traced and rasterised)\n",
        static_cast<unsigned long long>(splats), s.splat_instances.size(), s.splat_clouds.size(), degree);
  }
  if (const uint64_t segments = count_line_segments(s))
    std::printf(
        "lines        %llu segments (glTF LINES, LINE_LOOP, LINE_STRIP: rendered as capsules of "
        "--line-width unless the file sizes them)\n",
        static_cast<unsigned long long>(segments));
  print_shapes(s, i);
  std::printf("materials    %zu\n", s.materials.size());
  for (size_t k = 0; k < s.materials.size(); ++k) {
    const auto& m = s.materials[k];
    std::printf("  [%zu] %s: base (%.3g %.3g %.3g) metallic %.3g roughness %.3g emissive (%.3g %.3g %.3g)\n",
                k, m.name.c_str(), m.base_color.x, m.base_color.y, m.base_color.z, m.metallic, m.roughness,
                m.emissive.x, m.emissive.y, m.emissive.z);
    if (m.procedural >= 0)
      std::printf("      procedural: %s\n", describe_procedural(s.procedurals[size_t(m.procedural)]).c_str());
  }
  std::printf("cameras      %d defined, %zu in the scene (use --camera N or NAME)\n", i.gltf_camera_count,
              i.camera_instances.size());
  for (size_t k = 0; k < i.camera_instances.size(); ++k)
    std::printf("  [%zu] %s\n", k, i.camera_instances[k].c_str());
  std::printf("lights       %d defined, %zu in the scene\n", i.gltf_light_count, s.lights.size());
  for (size_t k = 0; k < s.lights.size(); ++k) {
    const auto& l = s.lights[k];
    const char* type = light_type_name(l.type);
    std::printf("  [%zu] %s: %s, intensity %.4g %s\n", k, l.name.c_str(), type, l.intensity,
                l.type == LightType::Directional ? "lux" : "cd");
  }
  std::printf("images       %d, %zu textures decoded\n", i.image_count, s.textures.size());
  std::printf("animations   %d\n", i.animation_count);
  auto join = [](const std::vector<std::string>& v) {
    std::string r;
    for (const auto& x : v) r += (r.empty() ? "" : ", ") + x;
    return r.empty() ? std::string("none") : r;
  };
  std::printf("extensions   used: %s; required: %s\n", join(i.extensions_used).c_str(),
              join(i.extensions_required).c_str());
  print_extension_support(i.extensions_used);
  if (!i.variants.empty()) std::printf("variants     %s (--variant NAME)\n", join(i.variants).c_str());
  if (loaded.environment)
    std::printf("environment  %s (EXT_lights_image_based, %dx%d map; --env replaces it)\n",
                i.image_light.c_str(), loaded.environment->width, loaded.environment->height);
  const Bounds3f b = compute_bounds(s);
  if (!b.empty())
    std::printf("bounds       (%.4g, %.4g, %.4g) - (%.4g, %.4g, %.4g)\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x,
                b.hi.y, b.hi.z);
  else
    std::printf("bounds       empty\n");
  print_view(view);
  const auto accel = build_structure(s, spec, false).accel;
  const AccelStats st = accel->stats();
  std::printf("accelerator  %s%s%s%s\n", st.name.c_str(), st.config.empty() ? "" : " (", st.config.c_str(),
              st.config.empty() ? "" : ")");
  std::printf("  triangles  %llu\n", static_cast<unsigned long long>(st.triangles));
  if (st.instances > 0)
    std::printf("  instances  %llu (two levels)\n", static_cast<unsigned long long>(st.instances));
  std::printf("  build      %.3f s\n", st.build_seconds);
  std::printf("  memory     %.2f MiB\n", double(st.bytes) / (1 << 20));
  if (st.nodes > 0) {
    const bool grid = st.name == "grid";
    std::printf("  %s      %llu%s\n", grid ? "cells" : "nodes", static_cast<unsigned long long>(st.nodes),
                grid ? "" : (" (" + std::to_string(st.nodes - st.leaves) + " interior)").c_str());
    if (!grid) std::printf("  leaves     %llu\n", static_cast<unsigned long long>(st.leaves));
    std::printf("  empty      %llu %s\n", static_cast<unsigned long long>(st.empty_leaves),
                grid ? "cells" : "leaves");
    std::printf("  references %llu (%.2f per triangle)\n", static_cast<unsigned long long>(st.references),
                st.triangles ? double(st.references) / double(st.triangles) : 0.0);
    std::printf("  per %s   avg %.2f, max %llu triangles (non-empty)\n", grid ? "cell" : "leaf",
                st.avg_leaf_prims, static_cast<unsigned long long>(st.max_leaf_prims));
    if (!grid) std::printf("  max depth  %llu\n", static_cast<unsigned long long>(st.max_depth));
    if (st.sah_cost > 0) std::printf("  SAH cost   %.2f\n", st.sah_cost);
  } else if (st.name == "embree") {
    std::printf("  (Embree does not report its node statistics)\n");
  }
  std::printf("warnings     %zu\n", loaded.warnings.size());
  if (a.volumes) print_volumes(loaded);
  return kExitOk;
}

}  // namespace penumbra::cli
