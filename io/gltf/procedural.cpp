// The PENUMBRA_procedural material extension: the mapping, the pattern by type, the ramp and the
// scalar drives, each read and checked against the schema.
#include "io/gltf/procedural.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "io/gltf/context.h"
#include "io/gltf/json_reader.h"

namespace penumbra::gltf {

namespace {

using nlohmann::json;

constexpr const char* kTopKeys[] = {"space",    "texCoord",         "translation", "rotation",  "scale",
                                    "matrix",   "filter",           "pattern",     "baseColor", "roughness",
                                    "metallic", "emissiveStrength", "bump"};
constexpr const char* kPatternCommon[] = {"type", "seed"};
constexpr const char* kFractalKeys[] = {"fractal", "detail", "roughness", "lacunarity",
                                        "offset",  "gain",   "distortion"};
constexpr const char* kVoronoiKeys[] = {"feature", "metric", "randomness", "output"};
constexpr const char* kWaveKeys[] = {"wave",    "axis",   "profile",   "phaseDistortion",
                                     "fractal", "detail", "roughness", "lacunarity",
                                     "offset",  "gain",   "distortion"};
constexpr const char* kPatternKeys[] = {"type",       "seed",           "fractal", "detail",     "roughness",
                                        "lacunarity", "offset",         "gain",    "distortion", "feature",
                                        "metric",     "randomness",     "output",  "wave",       "axis",
                                        "profile",    "phaseDistortion"};
constexpr const char* kColorKeys[] = {"ramp", "interpolation", "compose"};
constexpr const char* kDriveKeys[] = {"range", "compose"};
constexpr const char* kStopKeys[] = {"position", "color"};
constexpr const char* kBumpKeys[] = {"height"};

class ProceduralReader : public JsonReader {
 public:
  using JsonReader::JsonReader;
  ProceduralTexture read(const json& ext, const std::string& where) const;

 private:
  void mapping(const json& ext, const std::string& where, ProceduralTexture& tex) const;
  void pattern(const json& p, const std::string& where, ProceduralTexture& tex) const;
  void base_color(const json& c, const std::string& where, ProceduralTexture& tex) const;
  ScalarDrive drive(const json& d, const std::string& where, float hi) const;
};

ProceduralTexture ProceduralReader::read(const json& ext, const std::string& where) const {
  require_object(ext, where, "an extension");
  check_keys(ext, where, "the extension", kTopKeys, {}, {});
  ProceduralTexture tex;
  tex.space = ProceduralSpace(choice_or(ext, "space", where, kSpaces, 0));
  if (find(ext, "texCoord") && tex.space != ProceduralSpace::Uv)
    fail(where + ".texCoord", "applies only to space \"uv\"");
  tex.texcoord = integer_or(ext, "texCoord", where, 0, 0, 1);
  tex.filter = boolean_or(ext, "filter", where, true);
  mapping(ext, where, tex);
  if (const json* p = find(ext, "pattern")) pattern(*p, where + ".pattern", tex);
  tex.table = make_perlin_table(tex.seed);
  if (const json* c = find(ext, "baseColor")) base_color(*c, where + ".baseColor", tex);
  if (const json* d = find(ext, "roughness")) tex.roughness = drive(*d, where + ".roughness", 1);
  if (const json* d = find(ext, "metallic")) tex.metallic = drive(*d, where + ".metallic", 1);
  if (const json* d = find(ext, "emissiveStrength"))
    tex.emission_strength = drive(*d, where + ".emissiveStrength", 1e6f);
  if (const json* b = find(ext, "bump")) {
    const std::string bw = where + ".bump";
    require_object(*b, bw, "a bump");
    check_keys(*b, bw, "bump", kBumpKeys, {}, {});
    tex.bump_height = number_in(*b, "height", bw, 0.0f, -1e3f, 1e3f);
  }
  return tex;
}

// The mapping's limits: every scale factor, translation and matrix entry within 1e6 in
// magnitude and every scale factor at least 1e-6, so that the map and its inverse (written back as
// a matrix) stay far inside the float range.
constexpr float kMaxMapping = 1e6f, kMinScale = 1e-6f;

void ProceduralReader::mapping(const json& ext, const std::string& where, ProceduralTexture& tex) const {
  Transform m;
  if (matrix_or(ext, "matrix", where, m)) {
    tex.mapping = to_affine(m);
    Affine3f inv;
    bool bounded = true;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) bounded = bounded && std::fabs(tex.mapping.m[r][c]) <= kMaxMapping;
    if (!bounded) fail(where + ".matrix", "entries must be within 1e6 in magnitude");
    if (!inverse(tex.mapping, inv) || !(std::fabs(determinant3x3(m)) >= 1e-18))
      fail(where + ".matrix", "is singular or nearly so (|det| < 1e-18)");
    return;
  }
  const Vec3f t = vec3_or(ext, "translation", where, {}, Bound::Any);
  const Vec3f r = vec3_or(ext, "rotation", where, {}, Bound::Any);
  Vec3f s{1, 1, 1};
  if (const json* v = find(ext, "scale")) {
    const std::string sw = where + ".scale";
    if (v->is_number()) {
      const float k = number(*v, sw, Bound::NonZero);
      s = {k, k, k};
    } else {
      s = vec3_or(ext, "scale", where, s, Bound::NonZero);
    }
    const Vec3f a = abs(s);
    if (!(std::min({a.x, a.y, a.z}) >= kMinScale && max_component(a) <= kMaxMapping))
      fail(sw, "must be within [1e-6, 1e6] in magnitude on every axis");
  }
  if (!(max_component(abs(t)) <= kMaxMapping))
    fail(where + ".translation", "must be within 1e6 in magnitude");
  if (!(max_component(abs(r)) <= kMaxMapping)) fail(where + ".rotation", "angles must be within 1e6 degrees");
  tex.mapping = procedural_mapping(t, r, s);
}

void ProceduralReader::pattern(const json& p, const std::string& where, ProceduralTexture& tex) const {
  require_object(p, where, "a pattern");
  tex.kind = PatternKind(choice_or(p, "type", where, kPatternTypes, 0));
  const std::string what = std::string("pattern type \"") + kPatternTypes[int(tex.kind)] + "\"";
  using Keys = std::span<const char* const>;
  const Keys typed = tex.kind == PatternKind::Noise     ? Keys(kFractalKeys)
                     : tex.kind == PatternKind::Voronoi ? Keys(kVoronoiKeys)
                                                        : Keys(kWaveKeys);
  check_keys(p, where, what, kPatternCommon, typed, kPatternKeys);
  tex.seed = uint32_or(p, "seed", where, 0);
  if (tex.kind != PatternKind::Voronoi) tex.fractal = read_fractal_params(*this, p, where, "fractal");
  if (tex.kind == PatternKind::Voronoi) {
    tex.voronoi.feature = WorleyFeature(choice_or(p, "feature", where, kFeatures, 0));
    tex.voronoi.metric = WorleyMetric(choice_or(p, "metric", where, kMetrics, 0));
    tex.voronoi.randomness = number_in(p, "randomness", where, 1, 0, 1);
    tex.voronoi_output = VoronoiOutput(choice_or(p, "output", where, kVoronoiOutputs, 0));
  }
  if (tex.kind == PatternKind::Wave) {
    tex.wave.type = WaveType(choice_or(p, "wave", where, kWaveTypes, 0));
    tex.wave.axis = choice_or(p, "axis", where, kAxes, tex.wave.type == WaveType::Rings ? 2 : 0);
    tex.wave.profile = WaveProfile(choice_or(p, "profile", where, kProfiles, 0));
    tex.wave.distortion = number_in(p, "phaseDistortion", where, 0, -1e3f, 1e3f);
  }
}

void ProceduralReader::base_color(const json& c, const std::string& where, ProceduralTexture& tex) const {
  require_object(c, where, "a base colour");
  check_keys(c, where, "baseColor", kColorKeys, {}, {});
  tex.drives_base_color = true;
  tex.base_color.interpolation = RampInterpolation(choice_or(c, "interpolation", where, kInterpolations, 0));
  tex.base_color_compose = Compose(choice_or(c, "compose", where, kComposes, 0));
  const json* ramp = find(c, "ramp");
  if (!ramp) return;
  const std::string rw = where + ".ramp";
  if (!ramp->is_array() || ramp->empty() || ramp->size() > size_t(kMaxRampStops))
    fail(rw,
         "must be an array of 1 to " + std::to_string(kMaxRampStops) + " stops (got " + shown(*ramp) + ")");
  tex.base_color.stops.clear();
  for (size_t i = 0; i < ramp->size(); ++i) {
    const json& s = (*ramp)[i];
    const std::string sw = idx(rw.c_str(), i);
    require_object(s, sw, "a ramp stop");
    check_keys(s, sw, "a ramp stop", kStopKeys, {}, {});
    if (!find(s, "position") || !find(s, "color")) fail(sw, "needs a position and a color");
    RampStop stop;
    stop.position = number_in(s, "position", sw, 0, 0, 1);
    const auto col = numbers<3>(s["color"], sw + ".color", Bound::NonNegative);
    for (int k = 0; k < 3; ++k)
      if (col[size_t(k)] > 1) fail(sw + ".color", "components must be in [0, 1] (linear RGB)");
    stop.color = {col[0], col[1], col[2]};
    if (!tex.base_color.stops.empty() && stop.position < tex.base_color.stops.back().position)
      fail(sw + ".position", "positions must not decrease along the ramp (" + format_number(stop.position) +
                                 " after " + format_number(tex.base_color.stops.back().position) + ")");
    tex.base_color.stops.push_back(stop);
  }
}

ScalarDrive ProceduralReader::drive(const json& d, const std::string& where, float hi) const {
  require_object(d, where, "a scalar input");
  check_keys(d, where, "a scalar input", kDriveKeys, {}, {});
  ScalarDrive out;
  out.enabled = true;
  out.compose = Compose(choice_or(d, "compose", where, kComposes, 0));
  if (const json* r = find(d, "range")) {
    const auto v = numbers<2>(*r, where + ".range", Bound::NonNegative);
    if (v[0] > hi || v[1] > hi)
      fail(where + ".range", "values must be in [0, " + format_number(hi) + "] (got " + shown(*r) + ")");
    out.min = v[0];
    out.max = v[1];
  }
  return out;
}

}  // namespace

FractalParams read_fractal_params(const JsonReader& reader, const json& j, const std::string& where,
                                  const char* kind_key) {
  FractalParams f;
  f.kind = FractalKind(reader.choice_or(j, kind_key, where, kFractalKinds, 0));
  f.detail = reader.number_in(j, "detail", where, f.detail, 0, 15);
  f.roughness = reader.number_in(j, "roughness", where, f.roughness, 0, 1);
  f.lacunarity = reader.number_in(j, "lacunarity", where, f.lacunarity, 1.01f, 16);
  f.distortion = reader.number_in(j, "distortion", where, f.distortion, 0, 16);
  if (f.kind == FractalKind::Ridged) {
    f.offset = reader.number_in(j, "offset", where, f.offset, 0, 2);
    f.gain = reader.number_in(j, "gain", where, f.gain, 0, 16);
  } else {
    for (const char* key : {"offset", "gain"})
      if (JsonReader::find(j, key))
        reader.fail(where + "." + key, std::string("applies to \"ridged\" ") + kind_key +
                                           " only (this one is \"" + kFractalKinds[int(f.kind)] + "\")");
  }
  return f;
}

std::vector<MaterialProcedural> read_material_procedurals(const json& doc, const std::string& file,
                                                          MemoryBudget& budget) {
  std::vector<MaterialProcedural> out;
  const auto materials = doc.find("materials");
  if (materials == doc.end() || !materials->is_array()) return out;
  for (size_t i = 0; i < materials->size(); ++i) {
    const json& m = (*materials)[i];
    if (!m.is_object()) continue;
    const auto ext = m.find("extensions");
    if (ext == m.end() || !ext->is_object()) continue;
    const auto proc = ext->find(kProceduralExtension);
    if (proc == ext->end()) continue;
    const auto name = m.find("name");
    const std::string label = name != m.end() && name->is_string()
                                  ? " (material '" + name->get<std::string>().substr(0, 60) + "')"
                                  : "";
    const ProceduralReader reader(file, label);
    const std::string where = idx("materials", i) + ".extensions." + kProceduralExtension;
    budget.charge(sizeof(MaterialProcedural) + kMaxRampStops * sizeof(RampStop), where,
                  "its procedural texture needs");
    out.push_back({int(i), reader.read(*proc, where)});
  }
  return out;
}

json procedural_json(const ProceduralTexture& t) {
  json j = {{"space", kSpaces[int(t.space)]}, {"filter", t.filter}};
  if (t.space == ProceduralSpace::Uv) j["texCoord"] = t.texcoord;
  if (!is_identity(t.mapping)) {
    json m = json::array();
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m.push_back(r < 3 ? t.mapping.m[r][c] : (c == 3 ? 1.0f : 0.0f));
    j["matrix"] = m;
  }
  json p = {{"type", kPatternTypes[int(t.kind)]}, {"seed", t.seed}};
  if (t.kind != PatternKind::Voronoi) {
    const FractalParams& f = t.fractal;
    p.update({{"fractal", kFractalKinds[int(f.kind)]},
              {"detail", f.detail},
              {"roughness", f.roughness},
              {"lacunarity", f.lacunarity},
              {"distortion", f.distortion}});
    if (f.kind == FractalKind::Ridged) p.update({{"offset", f.offset}, {"gain", f.gain}});
  }
  if (t.kind == PatternKind::Voronoi)
    p.update({{"feature", kFeatures[int(t.voronoi.feature)]},
              {"metric", kMetrics[int(t.voronoi.metric)]},
              {"randomness", t.voronoi.randomness},
              {"output", kVoronoiOutputs[int(t.voronoi_output)]}});
  if (t.kind == PatternKind::Wave)
    p.update({{"wave", kWaveTypes[int(t.wave.type)]},
              {"axis", kAxes[std::clamp(t.wave.axis, 0, 2)]},
              {"profile", kProfiles[int(t.wave.profile)]},
              {"phaseDistortion", t.wave.distortion}});
  j["pattern"] = p;
  if (t.drives_base_color) {
    json ramp = json::array();
    for (const RampStop& s : t.base_color.stops)
      ramp.push_back({{"position", s.position}, {"color", {s.color.x, s.color.y, s.color.z}}});
    j["baseColor"] = {{"ramp", ramp},
                      {"interpolation", kInterpolations[int(t.base_color.interpolation)]},
                      {"compose", kComposes[int(t.base_color_compose)]}};
  }
  const auto drive = [&](const char* key, const ScalarDrive& d) {
    if (d.enabled) j[key] = {{"range", {d.min, d.max}}, {"compose", kComposes[int(d.compose)]}};
  };
  drive("roughness", t.roughness);
  drive("metallic", t.metallic);
  drive("emissiveStrength", t.emission_strength);
  if (t.bump_height != 0) j["bump"] = {{"height", t.bump_height}};
  return j;
}

void attach_procedurals(Scene& scene, std::vector<MaterialProcedural>& procedurals) {
  for (MaterialProcedural& p : procedurals) {
    scene.materials[size_t(p.material)].procedural = int(scene.procedurals.size());
    scene.procedurals.push_back(std::move(p.texture));
  }
}

}  // namespace penumbra::gltf
