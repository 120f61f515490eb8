// `penumbra query`; see query_command.h. Loading, the structure and the queries are the
// library's (render/scene_query.h, renderer/accel/query.h); this file parses and prints.
#include "apps/penumbra/query_command.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/scene_setup.h"
#include "io/files/error.h"
#include "io/files/points_file.h"
#include "render/scene_query.h"
#include "render/session.h"

namespace penumbra::cli {

namespace {

// Most points one query command measures from.
constexpr size_t kMaxQueryPoints = 10'000'000;

// Parses `n` comma-separated finite numbers.
std::vector<float> parse_numbers(const std::string& text, size_t n, const std::string& option) {
  std::vector<float> v;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ',')) {
    char* end = nullptr;
    const double d = std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0' || !std::isfinite(d) || std::fabs(d) > 3.0e38)
      throw UsageError(option + ": '" + text + "' is not " + std::to_string(n) +
                       " finite numbers separated by commas");
    v.push_back(float(d));
  }
  if (v.size() != n || (!text.empty() && text.back() == ','))
    throw UsageError(option + ": '" + text + "' is not " + std::to_string(n) +
                     " finite numbers separated by commas");
  return v;
}

Vec3f parse_vec3(const std::string& text, const std::string& option) {
  const std::vector<float> v = parse_numbers(text, 3, option);
  return {v[0], v[1], v[2]};
}

nlohmann::json vec_json(Vec3f v) {
  return {v.x, v.y, v.z};
}

// One answer with its scene element, as JSON and as a text line.
nlohmann::json match_json(const LoadedScene& loaded, const PrimitiveMatch& m, bool measured) {
  const Scene& s = loaded.scene;
  const MatchOwner o = match_owner(s, m.geom_id);
  nlohmann::json j;
  if (measured) j["distance"] = m.distance;
  j["point"] = vec_json(m.point);
  j["instance"] = o.instance;
  j["node"] = o.node;
  j["node_name"] = o.node >= 0 && size_t(o.node) < loaded.info.node_names.size()
                       ? loaded.info.node_names[size_t(o.node)]
                       : "";
  if (o.mesh >= 0) {
    j["mesh"] = o.mesh;
    j["mesh_name"] = s.meshes[size_t(o.mesh)].name;
    j["triangle"] = m.prim_id;
    j["barycentric"] = {m.u, m.v};
  } else {
    j["shape"] = o.shape;
    j["shape_kind"] = shape_kind_name(s.shapes[size_t(o.shape)].shape.kind);
  }
  j["material"] = o.material;
  j["material_name"] = o.material >= 0 ? s.materials[size_t(o.material)].name : "";
  return j;
}

void print_match(const nlohmann::json& j, size_t rank) {
  std::string what =
      j.contains("mesh")
          ? format("mesh %d \"%s\" triangle %u", j["mesh"].get<int>(),
                   j["mesh_name"].get<std::string>().c_str(), j["triangle"].get<unsigned>())
          : format("shape %d (%s)", j["shape"].get<int>(), j["shape_kind"].get<std::string>().c_str());
  const auto& p = j["point"];
  std::printf("  %zu. %snode %d \"%s\", %s, material %d \"%s\", point (%g, %g, %g)\n", rank,
              j.contains("distance") ? format("distance %.9g, ", j["distance"].get<double>()).c_str() : "",
              j["node"].get<int>(), j["node_name"].get<std::string>().c_str(), what.c_str(),
              j["material"].get<int>(), j["material_name"].get<std::string>().c_str(), p[0].get<double>(),
              p[1].get<double>(), p[2].get<double>());
}

std::vector<Vec3f> query_points(const QueryArgs& a) {
  if (a.at.empty() == a.points_file.empty())
    throw UsageError("query: give one of --at X,Y,Z and --points FILE");
  if (!a.at.empty()) return {parse_vec3(a.at, "--at")};
  return read_points_file(a.points_file, kMaxQueryPoints);
}

struct Built {
  LoadedScene loaded;
  SceneGeometry geometry;
  std::unique_ptr<Accelerator> accel;
};

Built load_and_build(const QueryArgs& a) {
  parse_accel(a.accel, a.accel_params);
  Built b;
  b.loaded = load_scene(a.file, a.scene, a.allow_external, a.flatten, default_memory_budget(), false);
  if (b.loaded.scene.instances.empty()) throw InputError(a.file, "", "holds no geometry to query");
  RenderSpec spec;
  spec.accel = a.accel;
  spec.accel_params = a.accel_params;
  b.accel = build_structure(b.loaded.scene, spec, false).accel;
  b.geometry = scene_geometry(b.loaded.scene);
  return b;
}

// Prints `results` (one list per query point) as JSON or text.
void print_results(const QueryArgs& a, const char* kind, const Built& b, const std::vector<Vec3f>& points,
                   const std::vector<std::vector<PrimitiveMatch>>& results, bool measured,
                   nlohmann::json extra) {
  nlohmann::json doc = std::move(extra);
  doc["query"] = kind;
  doc["file"] = a.file;
  doc["accel"] = a.accel;
  doc["results"] = nlohmann::json::array();
  for (size_t i = 0; i < results.size(); ++i) {
    nlohmann::json r;
    if (!points.empty()) r["at"] = vec_json(points[i]);
    r["matches"] = nlohmann::json::array();
    for (const PrimitiveMatch& m : results[i]) r["matches"].push_back(match_json(b.loaded, m, measured));
    doc["results"].push_back(std::move(r));
  }
  if (a.json) {
    std::printf("%s\n", doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
    return;
  }
  for (const auto& r : doc["results"]) {
    if (r.contains("at"))
      std::printf("%s at (%g, %g, %g): %zu\n", kind, r["at"][0].get<double>(), r["at"][1].get<double>(),
                  r["at"][2].get<double>(), r["matches"].size());
    else
      std::printf("%s: %zu\n", kind, r["matches"].size());
    size_t rank = 1;
    for (const auto& m : r["matches"]) print_match(m, rank++);
  }
}

int run_nearest(const QueryArgs& a) {
  const std::vector<Vec3f> points = query_points(a);
  if (uint64_t(points.size()) * uint64_t(a.k) > 100'000'000ull)
    throw UsageError("query nearest: " + std::to_string(points.size()) + " points x --k " +
                     std::to_string(a.k) + " exceeds 10^8 answers");
  const Built b = load_and_build(a);
  const float max_d = a.max_distance < 0 ? kInfinity : float(a.max_distance);
  std::vector<PrimitiveMatch> flat;
  std::vector<uint32_t> counts;
  nearest_batch(*b.accel, b.geometry.view(), points, a.k, max_d, a.threads, flat, counts);
  std::vector<std::vector<PrimitiveMatch>> results(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    results[i].assign(flat.begin() + std::ptrdiff_t(i * size_t(a.k)),
                      flat.begin() + std::ptrdiff_t(i * size_t(a.k) + counts[i]));
  nlohmann::json extra{{"k", a.k}};
  extra["max_distance"] = a.max_distance < 0 ? nlohmann::json(nullptr) : nlohmann::json(a.max_distance);
  print_results(a, "nearest", b, points, results, true, extra);
  return kExitOk;
}

int run_within(const QueryArgs& a) {
  const std::vector<Vec3f> points = query_points(a);
  const Built b = load_and_build(a);
  std::vector<std::vector<PrimitiveMatch>> results(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    within(*b.accel, b.geometry.view(), points[i], float(a.radius), results[i]);
  print_results(a, "within", b, points, results, true, {{"radius", a.radius}});
  return kExitOk;
}

int run_overlap(const QueryArgs& a) {
  if (a.box.empty() == a.sphere.empty()) throw UsageError("query overlap: give one of --box and --sphere");
  std::vector<std::vector<PrimitiveMatch>> results(1);
  nlohmann::json extra;
  if (!a.box.empty()) {
    const std::vector<float> v = parse_numbers(a.box, 6, "--box");
    const Bounds3f box{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
    if (box.empty()) throw UsageError("--box: '" + a.box + "' has a minimum above its maximum");
    const Built b = load_and_build(a);
    overlap(*b.accel, b.geometry.view(), box, results[0]);
    extra["box"] = {vec_json(box.lo), vec_json(box.hi)};
    print_results(a, "overlap", b, {}, results, false, extra);
    return kExitOk;
  }
  const std::vector<float> v = parse_numbers(a.sphere, 4, "--sphere");
  if (!(v[3] >= 0)) throw UsageError("--sphere: the radius must be >= 0");
  const Built b = load_and_build(a);
  within(*b.accel, b.geometry.view(), {v[0], v[1], v[2]}, v[3], results[0]);
  extra["sphere"] = {v[0], v[1], v[2], v[3]};
  print_results(a, "overlap", b, {{v[0], v[1], v[2]}}, results, true, extra);
  return kExitOk;
}

int run_ray(const QueryArgs& a) {
  const Vec3f org = parse_vec3(a.from, "--from"), dir = parse_vec3(a.dir, "--dir");
  if (!(dot(dir, dir) > 0)) throw UsageError("--dir: the direction must not be zero");
  const Built b = load_and_build(a);
  Hit hit;
  std::vector<std::vector<PrimitiveMatch>> results(1);
  if (b.accel->intersect({org, 0, normalize(dir), kInfinity}, hit)) {
    PrimitiveMatch m;
    m.distance = hit.t;
    m.point = org + normalize(dir) * hit.t;
    m.u = hit.u;
    m.v = hit.v;
    m.geom_id = hit.geom_id;
    m.prim_id = hit.prim_id;
    results[0].push_back(m);
  }
  print_results(a, "ray", b, {}, results, true, {{"from", vec_json(org)}, {"dir", vec_json(normalize(dir))}});
  return kExitOk;
}

void add_common(CLI::App& c, QueryArgs& a) {
  c.add_option("scene", a.file, "glTF scene (.gltf or .glb)")->required();
  c.add_option("--scene", a.scene, "glTF scene index")->check(CLI::Range(0, 1 << 30));
  c.add_option("--accel", a.accel,
               "acceleration structure that answers: " + accelerator_list() + " (embree by default)");
  c.add_option("--accel-param", a.accel_params, accel_param_help())->type_name("KEY=VALUE");
  c.add_flag("--allow-external-uris", a.allow_external,
             "let buffer URIs reach files outside the scene's folder");
  c.add_flag("--flatten", a.flatten, "as for render: no instancing");
  c.add_flag("--json", a.json, "print one JSON document (schema in docs/reference/formats.md)");
}

void add_points(CLI::App& c, QueryArgs& a) {
  c.add_option("--at", a.at, "the query point X,Y,Z (world space)");
  c.add_option("--points", a.points_file, "a text file of query points, X Y Z per line");
}

}  // namespace

CLI::App* add_query_command(CLI::App& app, QueryArgs& a) {
  auto* q =
      app.add_subcommand("query", "Ask a glTF scene spatial questions: nearest primitives, regions, rays");
  q->require_subcommand(1);
  auto* n =
      q->add_subcommand("nearest", "The k primitives nearest to points, with distance and closest point");
  add_common(*n, a);
  add_points(*n, a);
  n->add_option("--k", a.k, "how many primitives per point (1 by default)")
      ->check(CLI::Range(1, kMaxNearest));
  n->add_option("--max-distance", a.max_distance, "farthest distance to look (unlimited by default)")
      ->check(CLI::Range(0.0, 3.0e38));
  n->add_option("--threads", a.threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 1024));
  auto* w = q->add_subcommand("within", "Every primitive within a distance of points");
  add_common(*w, a);
  add_points(*w, a);
  w->add_option("--radius", a.radius, "the distance")->required()->check(CLI::Range(0.0, 3.0e38));
  auto* o = q->add_subcommand("overlap", "Every primitive meeting a box or a ball");
  add_common(*o, a);
  o->add_option("--box", a.box, "MINX,MINY,MINZ,MAXX,MAXY,MAXZ");
  o->add_option("--sphere", a.sphere, "X,Y,Z,R");
  auto* r = q->add_subcommand("ray", "The first surface a ray meets");
  add_common(*r, a);
  r->add_option("--from", a.from, "the ray's origin X,Y,Z")->required();
  r->add_option("--dir", a.dir, "the ray's direction X,Y,Z (normalised)")->required();
  return q;
}

int run_query(const CLI::App& q, const QueryArgs& a) {
  if (q.got_subcommand("nearest")) return run_nearest(a);
  if (q.got_subcommand("within")) return run_within(a);
  if (q.got_subcommand("overlap")) return run_overlap(a);
  return run_ray(a);
}

}  // namespace penumbra::cli
