// `penumbra query`; see query_command.h. Loading, the structure and the queries are the
// library's (render/scene_query.h, renderer/accel/query.h); this file parses and prints.
#include "apps/penumbra/query_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/scene_setup.h"
#include "io/files/error.h"
#include "io/files/points_file.h"
#include "io/mesh/point_cloud.h"
#include "render/scene_query.h"
#include "render/session.h"
#include "renderer/scene/camera.h"
#include "renderer/scene/scene.h"

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
  if (o.mesh >= 0 && s.meshes[size_t(o.mesh)].points) {
    const Mesh& mesh = s.meshes[size_t(o.mesh)];
    j["points"] = o.mesh;
    j["points_name"] = mesh.name;
    j["point_index"] = mesh.indices[size_t(m.prim_id) * 3];
  } else if (o.mesh >= 0) {
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
      j.contains("points")
          ? format("point set %d \"%s\" point %u", j["points"].get<int>(),
                   j["points_name"].get<std::string>().c_str(), j["point_index"].get<unsigned>())
      : j.contains("mesh")
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

// Most points of a point file queried, and the bytes each takes with its structure.
constexpr uint64_t kMaxTargetPoints = 200'000'000;
constexpr uint64_t kBytesPerTargetPoint = 160;

// Bytes one answer takes between the query and the printout: the match and its JSON.
constexpr uint64_t kAnswerBytes = sizeof(PrimitiveMatch) + 1024;

// Most answers held at once between the query and the printout.
constexpr uint64_t kAnswersInFlight = uint64_t(1) << 22;

struct Built {
  LoadedScene loaded;
  SceneGeometry geometry;
  std::unique_ptr<Accelerator> accel;
  uint64_t left = 0;  ///< what remains of --max-memory after the scene, the structure and the points
};

Built load_and_build(const QueryArgs& a, uint64_t budget) {
  parse_accel(a.accel, a.accel_params);
  Built b;
  if (is_point_cloud_file(a.file)) {
    if (a.time || !a.variant.empty() || a.scene >= 0)
      throw UsageError("query: --time, --variant and --scene apply to glTF scenes, not to the point file " +
                       a.file);
    b.loaded.scene =
        load_point_cloud(a.file, size_t(std::min<uint64_t>(kMaxTargetPoints, budget / kBytesPerTargetPoint)));
  } else {
    b.loaded =
        load_scene(a.file, a.scene, a.allow_external, a.flatten, budget, false, a.time, false, a.variant);
  }
  if (b.loaded.scene.instances.empty()) throw InputError(a.file, "", "holds no geometry to query");
  RenderSpec spec;
  spec.accel = a.accel;
  spec.accel_params = a.accel_params;
  b.accel = build_structure(b.loaded.scene, spec, false).accel;
  b.geometry = scene_geometry(b.loaded.scene);
  const uint64_t used = scene_memory_bytes(b.loaded.scene) + b.accel->stats().bytes;
  b.left = budget - std::min(budget, used);
  return b;
}

std::vector<Vec3f> query_points(const QueryArgs& a, uint64_t budget) {
  if (a.at.empty() == a.points_file.empty())
    throw UsageError("query: give one of --at X,Y,Z and --points FILE");
  if (!a.at.empty()) return {parse_vec3(a.at, "--at")};
  const uint64_t fit = budget / 2 / sizeof(Vec3f);
  return read_query_points(a.points_file, size_t(std::min<uint64_t>(kMaxQueryPoints, fit)));
}

// Prints a document result by result: the query's parameters, then "results" as each query
// point's answers arrive (JSON), or a heading and a line per answer (text).
class ResultPrinter {
 public:
  ResultPrinter(const QueryArgs& a, const char* kind, const Built& b, nlohmann::json params)
      : m_args(a), m_kind(kind), m_built(b) {
    if (!a.json) return;
    params["query"] = kind;
    params["file"] = a.file;
    params["accel"] = a.accel;
    std::string head = params.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
    head.resize(head.size() - 2);  // the closing "\n}"
    std::printf("%s,\n  \"results\": [", head.c_str());
  }

  // One query's answers; `at` its point, if it has one.
  void add(const Vec3f* at, std::span<const PrimitiveMatch> matches, bool measured,
           const nlohmann::json& more = nullptr) {
    nlohmann::json r;
    if (at) r["at"] = vec_json(*at);
    r["matches"] = nlohmann::json::array();
    for (const PrimitiveMatch& m : matches) {
      nlohmann::json j = match_json(m_built.loaded, m, measured);
      if (more.is_object()) j.update(more);
      r["matches"].push_back(std::move(j));
    }
    if (m_args.json) {
      std::string text = r.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
      std::string indented;
      for (char c : text) indented += c == '\n' ? std::string("\n    ") : std::string(1, c);
      std::printf("%s\n    %s", m_count ? "," : "", indented.c_str());
    } else {
      if (at)
        std::printf("%s at (%g, %g, %g): %zu\n", m_kind, at->x, at->y, at->z, matches.size());
      else
        std::printf("%s: %zu\n", m_kind, matches.size());
      size_t rank = 1;
      for (const auto& m : r["matches"]) print_match(m, rank++);
    }
    ++m_count;
  }

  void finish() {
    if (m_args.json) std::printf("%s]\n}\n", m_count ? "\n  " : "");
    std::fflush(stdout);
  }

 private:
  const QueryArgs& m_args;
  const char* m_kind;
  const Built& m_built;
  size_t m_count = 0;
};

// Points per batch: as many as kAnswersInFlight answers (and what is left of the budget) allow.
size_t batch_points(uint64_t left, uint64_t answers_per_point, const std::string& what) {
  const uint64_t per_point = std::max<uint64_t>(1, answers_per_point) * kAnswerBytes;
  if (per_point > left)
    throw UsageError("--max-memory: " + what + " needs " + std::to_string(per_point >> 20) +
                     " MiB per point beyond the scene and the structure");
  const uint64_t n = std::min(left / per_point, kAnswersInFlight / std::max<uint64_t>(1, answers_per_point));
  return size_t(std::clamp<uint64_t>(n, 1, 4096));
}

int run_nearest(const QueryArgs& a) {
  const uint64_t budget = memory_budget(a.max_memory);
  const std::vector<Vec3f> points = query_points(a, budget);
  const Built b = load_and_build(a, budget - std::min<uint64_t>(budget, points.size() * sizeof(Vec3f)));
  const size_t batch = batch_points(b.left, uint64_t(a.k), "--k " + std::to_string(a.k));
  const float max_d = a.max_distance < 0 ? kInfinity : float(a.max_distance);
  nlohmann::json params{{"k", a.k}};
  params["max_distance"] = a.max_distance < 0 ? nlohmann::json(nullptr) : nlohmann::json(a.max_distance);
  ResultPrinter out(a, "nearest", b, params);
  std::vector<PrimitiveMatch> flat;
  std::vector<uint32_t> counts;
  for (size_t first = 0; first < points.size(); first += batch) {
    const auto part = std::span(points).subspan(first, std::min(batch, points.size() - first));
    nearest_batch(*b.accel, b.geometry.view(), part, a.k, max_d, a.threads, flat, counts);
    for (size_t i = 0; i < part.size(); ++i)
      out.add(&part[i], std::span(flat).subspan(i * size_t(a.k), counts[i]), true);
  }
  out.finish();
  return kExitOk;
}

int run_within(const QueryArgs& a) {
  const uint64_t budget = memory_budget(a.max_memory);
  const std::vector<Vec3f> points = query_points(a, budget);
  const Built b = load_and_build(a, budget - std::min<uint64_t>(budget, points.size() * sizeof(Vec3f)));
  // Points in small batches; what they meet is charged to the budget as it is found.
  const size_t batch = std::min<size_t>(256, batch_points(b.left, 1, "--radius " + exact(a.radius)));
  ResultPrinter out(a, "within", b, {{"radius", a.radius}});
  std::vector<PrimitiveMatch> flat;
  std::vector<size_t> offsets;
  for (size_t first = 0; first < points.size(); first += batch) {
    const auto part = std::span(points).subspan(first, std::min(batch, points.size() - first));
    if (!within_batch(*b.accel, b.geometry.view(), part, float(a.radius), a.threads,
                      size_t(std::max<uint64_t>(1, b.left / kAnswerBytes)), flat, offsets))
      throw UsageError("--max-memory: the points within --radius " + exact(a.radius) +
                       " meet more primitives than the budget holds");
    for (size_t i = 0; i < part.size(); ++i)
      out.add(&part[i], std::span(flat).subspan(offsets[i], offsets[i + 1] - offsets[i]), true);
  }
  out.finish();
  return kExitOk;
}

int run_overlap(const QueryArgs& a) {
  if (a.box.empty() == a.sphere.empty()) throw UsageError("query overlap: give one of --box and --sphere");
  const uint64_t budget = memory_budget(a.max_memory);
  std::vector<PrimitiveMatch> matches;
  if (!a.box.empty()) {
    const std::vector<float> v = parse_numbers(a.box, 6, "--box");
    const Bounds3f box{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
    if (box.empty()) throw UsageError("--box: '" + a.box + "' has a minimum above its maximum");
    const Built b = load_and_build(a, budget);
    overlap(*b.accel, b.geometry.view(), box, matches);
    ResultPrinter out(a, "overlap", b, {{"box", {vec_json(box.lo), vec_json(box.hi)}}});
    out.add(nullptr, matches, false);
    out.finish();
    return kExitOk;
  }
  const std::vector<float> v = parse_numbers(a.sphere, 4, "--sphere");
  if (!(v[3] >= 0)) throw UsageError("--sphere: the radius must be >= 0");
  const Built b = load_and_build(a, budget);
  const Vec3f centre{v[0], v[1], v[2]};
  within(*b.accel, b.geometry.view(), centre, v[3], matches);
  ResultPrinter out(a, "overlap", b, {{"sphere", {v[0], v[1], v[2], v[3]}}});
  out.add(&centre, matches, true);
  out.finish();
  return kExitOk;
}

int run_ray(const QueryArgs& a) {
  const Vec3f org = parse_vec3(a.from, "--from"), dir = parse_vec3(a.dir, "--dir");
  if (!(dot(dir, dir) > 0)) throw UsageError("--dir: the direction must not be zero");
  const Built b = load_and_build(a, memory_budget(a.max_memory));
  Hit hit;
  std::vector<PrimitiveMatch> matches;
  if (b.accel->intersect({org, 0, normalize(dir), kInfinity}, hit)) {
    PrimitiveMatch m;
    m.distance = hit.t;
    m.point = org + normalize(dir) * hit.t;
    m.u = hit.u;
    m.v = hit.v;
    m.geom_id = hit.geom_id;
    m.prim_id = hit.prim_id;
    matches.push_back(m);
  }
  ResultPrinter out(a, "ray", b, {{"from", vec_json(org)}, {"dir", vec_json(normalize(dir))}});
  out.add(nullptr, matches, true);
  out.finish();
  return kExitOk;
}

int run_pick(const QueryArgs& a) {
  if (!a.frame.empty() && a.cam.turntable.empty())
    throw UsageError("query pick: --frame picks a --turntable frame");
  const long long frame = a.frame.empty() ? 0 : parse_integer(a.frame, -(1ll << 40), 1ll << 40, "--frame");
  check_camera_args(a.cam, frame);  // flags refused before the scene loads
  const std::vector<float> px = parse_numbers(a.pixel, 2, "--pixel");
  if (px[0] != std::floor(px[0]) || px[1] != std::floor(px[1]) || px[0] < 0 || px[1] < 0)
    throw UsageError("--pixel: '" + a.pixel + "' is not two whole numbers >= 0 (X,Y)");
  const Built b = load_and_build(a, memory_budget(a.max_memory));
  const ChosenView view = choose_view(b.loaded.scene, a.file, a.camera, a.cam, a.width, a.height, frame);
  if (px[0] >= float(view.width) || px[1] >= float(view.height))
    throw UsageError("--pixel " + a.pixel + " is outside the " + std::to_string(view.width) + "x" +
                     std::to_string(view.height) + " image");
  const int x = int(px[0]), y = int(px[1]);
  const Pick p = pick(b.loaded.scene, *b.accel, view.camera, view.width, view.height, x, y);
  nlohmann::json params{{"pixel", {x, y}},
                        {"width", view.width},
                        {"height", view.height},
                        {"camera", view.index >= 0 ? nlohmann::json(view.index) : nlohmann::json(nullptr)},
                        {"from", vec_json(p.ray.org)},
                        {"dir", vec_json(p.ray.dir)}};
  ResultPrinter out(a, "pick", b, params);
  if (p.hit)
    out.add(nullptr, std::span(&p.match, 1), true, {{"depth", p.depth}, {"normal", vec_json(p.normal)}});
  else
    out.add(nullptr, {}, true);
  out.finish();
  return kExitOk;
}

void add_common(CLI::App& c, QueryArgs& a) {
  c.add_option("scene", a.file,
               "glTF scene (.gltf or .glb), or a point set to query: .ply (its vertices; with faces, its "
               "mesh), .npy (N x 3), or a text file .txt, .xyz, .pts or .csv")
      ->required();
  c.add_option("--scene", a.scene, "glTF scene index")->check(CLI::Range(0, 1 << 30));
  c.add_option("--accel", a.accel,
               "acceleration structure that answers: " + accelerator_list() + " (embree by default)");
  c.add_option("--accel-param", a.accel_params, accel_param_help())->type_name("KEY=VALUE");
  c.add_flag("--allow-external-uris", a.allow_external,
             "let buffer URIs reach files outside the scene's folder");
  c.add_flag("--flatten", a.flatten, "as for render: no instancing");
  c.add_flag("--json", a.json, "print one JSON document (schema in docs/reference/formats.md)");
  c.add_option("--time", a.time, "pose the animation at this time in seconds (default: the static pose)")
      ->check(CLI::Range(-1e9, 1e9));
  c.add_option("--variant", a.variant, "KHR_materials_variants variant (names: `penumbra info`)")
      ->check(
          [](const std::string& v) { return v.empty() ? std::string("the value is empty") : std::string(); });
  c.add_option("--max-memory", a.max_memory,
               "budget for the scene, the structure, the points and the answers in flight, e.g. 4G "
               "(default: half the RAM)");
}

void add_points(CLI::App& c, QueryArgs& a) {
  c.add_option("--at", a.at, "the query point X,Y,Z (world space)");
  c.add_option("--points", a.points_file,
               "a file of query points: X Y Z per line, or a NumPy .npy array (N x 3)");
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
  auto* p = q->add_subcommand(
      "pick", "What the camera sees through a pixel's centre: node, mesh, triangle, material, distance");
  add_common(*p, a);
  p->add_option("--pixel", a.pixel, "the pixel X,Y (0,0: top left)")->required();
  p->add_option("--camera", a.camera, "as render: a camera's index or name");
  p->add_option("--width", a.width, "as render: image width (default 960)")->check(CLI::Range(1, 16384));
  p->add_option("--height", a.height, "as render: image height (default: the camera's aspect)")
      ->check(CLI::Range(1, 16384));
  p->add_option("--frame", a.frame, "the --turntable frame (default 0)");
  add_camera_options(*p, a.cam);
  return q;
}

int run_query(const CLI::App& q, const QueryArgs& a) {
  if (q.got_subcommand("nearest")) return run_nearest(a);
  if (q.got_subcommand("within")) return run_within(a);
  if (q.got_subcommand("overlap")) return run_overlap(a);
  if (q.got_subcommand("pick")) return run_pick(a);
  return run_ray(a);
}

}  // namespace penumbra::cli
