// penumbra.load_points, Scene.nearest, Scene.within, Scene.overlap, Scene.intersect and
// Scene.pick: the spatial queries of render/scene_query.h over NumPy arrays, on the session's
// kept structure, with the GIL released while they run. Answers are dicts of arrays; missing
// entries are -1 (ids), +inf (distances) and NaN (points).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>

#include "io/files/error.h"
#include "io/files/points_file.h"
#include "io/mesh/point_cloud.h"
#include "python/bindings.h"
#include "render/scene_query.h"
#include "renderer/accel/query.h"

namespace penumbra::python {

namespace {

using FloatIn = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Most answers one call returns (nearest: points x k; within and overlap: matches in all).
constexpr size_t kMaxAnswers = size_t(1) << 27;

/// Most points or rays one call takes.
constexpr size_t kMaxQueries = size_t(1) << 26;

/// An (N, 3) array (or one point of shape (3,)) of finite numbers within single precision, as
/// points; ValueError naming `what` otherwise.
std::vector<Vec3f> points_from(const py::handle& object, const char* what) {
  const FloatIn a = FloatIn::ensure(object);
  if (!a) {
    PyErr_Clear();
    throw py::type_error(std::string(what) + " must be an array of numbers of shape (N, 3)");
  }
  const bool one = a.ndim() == 1 && a.shape(0) == 3;
  if (!one && !(a.ndim() == 2 && a.shape(1) == 3))
    throw py::value_error(std::string(what) + " must have shape (N, 3) or (3,)");
  const size_t n = one ? 1 : size_t(a.shape(0));
  if (n > kMaxQueries) throw py::value_error(std::string(what) + ": more than 2^26 rows");
  std::vector<Vec3f> v(n);
  const double* d = a.data();
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c)
      if (!(std::fabs(d[3 * i + size_t(c)]) <= double(std::numeric_limits<float>::max())))
        throw py::value_error(std::string(what) + "[" + std::to_string(i) + "] is not three finite numbers");
    v[i] = {float(d[3 * i]), float(d[3 * i + 1]), float(d[3 * i + 2])};
  }
  return v;
}

RenderSpec accel_spec(const std::string& accel, const std::vector<std::string>& params) {
  RenderSpec spec;
  spec.accel = accel;
  spec.accel_params = params;
  return spec;
}

/// Refuses a scene without geometry as the command does.
void check_geometry(const SceneSession& s) {
  if (s.loaded.scene.instances.empty()) throw InputError(s.file, "", "holds no geometry to query");
}

/// `n` answers as arrays: distance (float32), point (float32, 3), barycentric (float32, 2),
/// instance, primitive, node, material (int64), mesh and shape (int64, -1 where not one).
py::dict answer_arrays(const Scene& scene, std::span<const PrimitiveMatch> m, std::span<const uint8_t> valid,
                       std::vector<py::ssize_t> shape) {
  std::vector<py::ssize_t> s3 = shape, s2 = shape;
  s3.push_back(3);
  s2.push_back(2);
  py::array_t<float> distance(shape), point(s3), bary(s2);
  py::array_t<int64_t> instance(shape), prim(shape), node(shape), material(shape), mesh(shape), shp(shape);
  float *dd = distance.mutable_data(), *pd = point.mutable_data(), *bd = bary.mutable_data();
  int64_t *id = instance.mutable_data(), *rd = prim.mutable_data(), *nd = node.mutable_data(),
          *md = material.mutable_data(), *hd = mesh.mutable_data(), *sd = shp.mutable_data();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < m.size(); ++i) {
    if (!valid.empty() && !valid[i]) {
      dd[i] = kInfinity;
      pd[3 * i] = pd[3 * i + 1] = pd[3 * i + 2] = bd[2 * i] = bd[2 * i + 1] = nan;
      id[i] = rd[i] = nd[i] = md[i] = hd[i] = sd[i] = -1;
      continue;
    }
    const MatchOwner o = match_owner(scene, m[i].geom_id);
    dd[i] = m[i].distance;
    pd[3 * i] = m[i].point.x;
    pd[3 * i + 1] = m[i].point.y;
    pd[3 * i + 2] = m[i].point.z;
    bd[2 * i] = m[i].u;
    bd[2 * i + 1] = m[i].v;
    id[i] = o.instance;
    rd[i] = m[i].prim_id;
    nd[i] = o.node;
    md[i] = o.material;
    hd[i] = o.mesh;
    sd[i] = o.shape;
  }
  py::dict d;
  d["distance"] = distance;
  d["point"] = point;
  d["barycentric"] = bary;
  d["instance"] = instance;
  d["primitive"] = prim;
  d["node"] = node;
  d["mesh"] = mesh;
  d["shape"] = shp;
  d["material"] = material;
  return d;
}

py::dict nearest(SceneSession& s, const py::object& points, int k, double max_distance,
                 const std::string& accel, const std::vector<std::string>& params, int threads) {
  const std::vector<Vec3f> p = points_from(points, "points");
  if (k < 1 || k > kMaxNearest) throw py::value_error("k must be in [1, 65536]");
  if (!(max_distance >= 0)) throw py::value_error("max_distance must be >= 0 (inf: unlimited)");
  if (p.size() * size_t(k) > kMaxAnswers) throw py::value_error("points x k exceeds 2^27 answers");
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores)");
  SessionLock lock(s);
  check_geometry(s);
  std::vector<PrimitiveMatch> out;
  std::vector<uint32_t> counts;
  std::vector<uint8_t> valid(p.size() * size_t(k), 0);
  {
    py::gil_scoped_release release;
    const Accelerator& a = query_structure(s, accel_spec(accel, params));
    const SceneGeometry g = scene_geometry(s.loaded.scene);
    const float max_d = max_distance > 3e38 ? kInfinity : float(max_distance);
    nearest_batch(a, g.view(), p, k, max_d, threads, out, counts);
    for (size_t i = 0; i < p.size(); ++i)
      for (uint32_t j = 0; j < counts[i]; ++j) valid[i * size_t(k) + j] = 1;
  }
  py::dict d = answer_arrays(s.loaded.scene, out, valid, {py::ssize_t(p.size()), py::ssize_t(k)});
  py::array_t<int64_t> count(py::ssize_t(p.size()));
  for (size_t i = 0; i < p.size(); ++i) count.mutable_data()[i] = counts[i];
  d["count"] = count;
  return d;
}

py::dict within(SceneSession& s, const py::object& points, double radius, const std::string& accel,
                const std::vector<std::string>& params, int threads, size_t max_matches) {
  const std::vector<Vec3f> p = points_from(points, "points");
  if (!(radius >= 0 && radius <= 3e38)) throw py::value_error("radius must be finite and >= 0");
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores)");
  max_matches = std::min(max_matches, kMaxAnswers);
  SessionLock lock(s);
  check_geometry(s);
  std::vector<PrimitiveMatch> out;
  std::vector<size_t> offsets;
  bool fits = false;
  {
    py::gil_scoped_release release;
    const Accelerator& a = query_structure(s, accel_spec(accel, params));
    const SceneGeometry g = scene_geometry(s.loaded.scene);
    fits = within_batch(a, g.view(), p, float(radius), threads, max_matches, out, offsets);
  }
  if (!fits)
    throw py::value_error("the points meet more than max_matches = " + std::to_string(max_matches) +
                          " primitives within the radius");
  py::dict d = answer_arrays(s.loaded.scene, out, {}, {py::ssize_t(out.size())});
  py::array_t<int64_t> off(py::ssize_t(offsets.size()));
  for (size_t i = 0; i < offsets.size(); ++i) off.mutable_data()[i] = int64_t(offsets[i]);
  d["offsets"] = off;
  return d;
}

py::dict overlap(SceneSession& s, const py::object& box, const py::object& sphere, const std::string& accel,
                 const std::vector<std::string>& params) {
  if (box.is_none() == sphere.is_none()) throw py::value_error("give one of box and sphere");
  std::vector<double> v;
  try {
    v = (box.is_none() ? sphere : box).cast<std::vector<double>>();
  } catch (const py::cast_error&) {
    // ((min), (max)) for a box
    if (box.is_none()) throw py::type_error("sphere must be (x, y, z, r)");
    for (const auto& corner : box.cast<std::vector<std::vector<double>>>())
      v.insert(v.end(), corner.begin(), corner.end());
  }
  for (double x : v)
    if (!(std::fabs(x) <= 3e38)) throw py::value_error("box and sphere must hold finite numbers");
  std::vector<PrimitiveMatch> out;
  SessionLock lock(s);
  check_geometry(s);
  if (!box.is_none()) {
    if (v.size() != 6)
      throw py::value_error("box must be (minx, miny, minz, maxx, maxy, maxz) or ((min), (max))");
    const Bounds3f b{{float(v[0]), float(v[1]), float(v[2])}, {float(v[3]), float(v[4]), float(v[5])}};
    if (b.empty()) throw py::value_error("box has a minimum above its maximum");
    py::gil_scoped_release release;
    const Accelerator& a = query_structure(s, accel_spec(accel, params));
    penumbra::overlap(a, scene_geometry(s.loaded.scene).view(), b, out);
  } else {
    if (v.size() != 4 || !(v[3] >= 0)) throw py::value_error("sphere must be (x, y, z, r) with r >= 0");
    py::gil_scoped_release release;
    const Accelerator& a = query_structure(s, accel_spec(accel, params));
    penumbra::within(a, scene_geometry(s.loaded.scene).view(), {float(v[0]), float(v[1]), float(v[2])},
                     float(v[3]), out);
  }
  if (out.size() > kMaxAnswers) throw py::value_error("the region meets more than 2^27 primitives");
  return answer_arrays(s.loaded.scene, out, {}, {py::ssize_t(out.size())});
}

py::dict intersect(SceneSession& s, const py::object& origins, const py::object& directions,
                   const std::string& accel, const std::vector<std::string>& params, int threads) {
  const std::vector<Vec3f> o = points_from(origins, "origins"), d = points_from(directions, "directions");
  if (o.size() != d.size() && o.size() != 1)
    throw py::value_error("origins must have one row, or as many rows as directions");
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores)");
  std::vector<Ray> rays(d.size());
  for (size_t i = 0; i < d.size(); ++i) {
    const float m = std::max({std::fabs(d[i].x), std::fabs(d[i].y), std::fabs(d[i].z)});
    if (!(m > 0)) throw py::value_error("directions[" + std::to_string(i) + "] is zero");
    rays[i] = {o[o.size() == 1 ? 0 : i], 0, normalize(d[i] / m), kInfinity};
  }
  SessionLock lock(s);
  check_geometry(s);
  std::vector<Hit> hits(rays.size());
  std::vector<PrimitiveMatch> m(rays.size());
  std::vector<uint8_t> valid(rays.size(), 0);
  {
    py::gil_scoped_release release;
    const Accelerator& a = query_structure(s, accel_spec(accel, params));
    intersect_batch(a, rays, hits, threads);
    for (size_t i = 0; i < rays.size(); ++i) {
      if (hits[i].geom_id == Hit::kInvalidId) continue;
      valid[i] = 1;
      m[i].distance = hits[i].t;
      m[i].point = rays[i].org + rays[i].dir * hits[i].t;
      m[i].u = hits[i].u;
      m[i].v = hits[i].v;
      m[i].geom_id = hits[i].geom_id;
      m[i].prim_id = hits[i].prim_id;
    }
  }
  return answer_arrays(s.loaded.scene, m, valid, {py::ssize_t(rays.size())});
}

py::object pick_pixel(SceneSession& s, int x, int y, const py::object& settings, const py::kwargs& kw) {
  const RenderSettings rs = settings_from(settings, kw);
  SessionLock lock(s);
  check_geometry(s);
  Pick p;
  RenderView view;
  {
    py::gil_scoped_release release;
    PrepareOptions o;
    o.scene_file = s.file;
    view = render_view(s.loaded.scene, rs, o);
    if (x < 0 || y < 0 || x >= view.config.width || y >= view.config.height)
      throw std::invalid_argument("pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                  ") is outside the " + std::to_string(view.config.width) + "x" +
                                  std::to_string(view.config.height) + " image");
    const Accelerator& a = query_structure(s, rs);
    p = pick(s.loaded.scene, a, view.camera, view.config.width, view.config.height, x, y);
  }
  if (!p.hit) return py::none();
  const Scene& scene = s.loaded.scene;
  const auto& names = s.loaded.info.node_names;
  py::dict d;
  d["distance"] = p.match.distance;
  d["point"] = py::make_tuple(p.match.point.x, p.match.point.y, p.match.point.z);
  d["depth"] = p.depth;
  d["normal"] = py::make_tuple(p.normal.x, p.normal.y, p.normal.z);
  d["barycentric"] = py::make_tuple(p.match.u, p.match.v);
  d["instance"] = p.owner.instance;
  d["node"] = p.owner.node;
  d["node_name"] =
      p.owner.node >= 0 && size_t(p.owner.node) < names.size() ? names[size_t(p.owner.node)] : "";
  d["mesh"] = p.owner.mesh;
  d["shape"] = p.owner.shape;
  d["primitive"] = p.match.prim_id;
  d["material"] = p.owner.material;
  d["material_name"] = p.owner.material >= 0 ? scene.materials[size_t(p.owner.material)].name : "";
  return d;
}

/// Most points of a point set loaded from Python, and the bytes each takes with a structure (as
/// `penumbra query` charges them).
constexpr size_t kMaxPointSet = size_t(1) << 28;
constexpr uint64_t kBytesPerPoint = 160;

std::shared_ptr<SceneSession> load_points(const py::object& source, std::optional<uint64_t> max_memory) {
  auto session = std::make_shared<SceneSession>();
  if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
    const auto path = source.cast<std::filesystem::path>();
    const uint64_t budget = max_memory.value_or(default_memory_budget());
    session->file = path.string();
    py::gil_scoped_release release;
    session->loaded.scene =
        load_point_cloud(path, size_t(std::min<uint64_t>(kMaxPointSet, budget / kBytesPerPoint)));
    return session;
  }
  std::vector<Vec3f> points = points_from(source, "points");
  if (points.empty()) throw py::value_error("points holds no point");
  session->file = "<points>";
  add_world_mesh(session->loaded.scene, make_point_set(std::move(points), "points"));
  return session;
}

}  // namespace

void bind_queries(py::module_& m, SceneClass& scene) {
  m.def("load_points", &load_points, py::arg("source"), py::kw_only(), py::arg("max_memory") = py::none(),
        "A Scene of one point set to query (nearest, within, overlap) in every structure: source is an array "
        "of shape (N, 3), or a file: .ply (its vertices; a PLY with faces gives its mesh), .npy (N x 3 "
        "float32 or float64), or text (x y z per line); a file may hold as many points as max_memory bytes "
        "allow at 160 bytes each (None: half the RAM, as penumbra.load). Rendered, the points are spheres "
        "of the render's point_size. Raises "
        "penumbra.InputError for a malformed file, ValueError for points that are not finite.");
  const char* answers =
      " Returns a dict of NumPy arrays: distance (float32), point (float32, 3), barycentric (float32, 2: "
      "u, v of the triangle's second and third vertex; 0 for shapes), instance, primitive (triangle index, 0 "
      "for "
      "a shape), node, mesh, shape, material (int64; -1 where not one). accel names the structure that "
      "answers (every one gives the same answers); it is kept between queries and renders with the same "
      "accel and accel_params. The GIL is released while the query runs.";
  scene.def("nearest", &nearest, py::arg("points"), py::arg("k") = 1,
            py::arg("max_distance") = std::numeric_limits<double>::infinity(), py::kw_only(),
            py::arg("accel") = "embree", py::arg("accel_params") = std::vector<std::string>{},
            py::arg("threads") = 0,
            (std::string("The k primitives nearest to each of points ((N, 3) or (3,), world space) within "
                         "max_distance, nearest first, ties by instance then primitive: arrays of shape (N, "
                         "k), missing entries -1, +inf or NaN, and count (N,) the answers per point.") +
             answers)
                .c_str());
  scene.def("within", &within, py::arg("points"), py::arg("radius"), py::kw_only(),
            py::arg("accel") = "embree", py::arg("accel_params") = std::vector<std::string>{},
            py::arg("threads") = 0, py::arg("max_matches") = size_t(1) << 24,
            (std::string("Every primitive within radius of each of points, nearest first: flat arrays, point "
                         "i's answers at offsets[i]:offsets[i + 1] (offsets: int64, N + 1). ValueError when "
                         "they exceed max_matches in all.") +
             answers)
                .c_str());
  scene.def(
      "overlap", &overlap, py::kw_only(), py::arg("box") = py::none(), py::arg("sphere") = py::none(),
      py::arg("accel") = "embree", py::arg("accel_params") = std::vector<std::string>{},
      (std::string("Every primitive meeting a closed box ((minx, miny, minz, maxx, maxy, maxz) or ((min), "
                   "(max)); ordered by instance and primitive, distance from the box's centre) or a ball "
                   "(sphere=(x, y, z, r), as within).") +
       answers)
          .c_str());
  scene.def("intersect", &intersect, py::arg("origins"), py::arg("directions"), py::kw_only(),
            py::arg("accel") = "embree", py::arg("accel_params") = std::vector<std::string>{},
            py::arg("threads") = 0,
            (std::string("The first surface each ray meets (origins: (N, 3) or one row for all; directions: "
                         "(N, 3), not zero, normalised): arrays of shape (N,), distance the t along the "
                         "normalised direction, +inf and -1 on a miss.") +
             answers)
                .c_str());
  scene.def("pick", &pick_pixel, py::arg("x"), py::arg("y"), py::arg("settings") = py::none(),
            "What the camera sees through the centre of pixel (x, y) of the image a render with these "
            "settings (a RenderSettings, or keywords: camera, width, height, accel, ...) makes: a dict with "
            "distance, point, depth (along the view axis, as the Z AOV), normal (facing the camera), "
            "barycentric, instance, node, node_name, mesh, shape, primitive, material, material_name, or "
            "None on a miss. Alpha-masked texels and the back faces of single-sided materials are passed "
            "through as a render's camera rays pass them: the node and material are the id AOV's where one "
            "surface covers the pixel.");
}

}  // namespace penumbra::python
