// Batch job files: reading and checking the JSON, and splitting the shots into work units.
#include "io/farm/job_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "io/files/error.h"
#include "io/files/file_checks.h"
#include "io/gltf/json_reader.h"
#include "io/gltf/loader.h"

namespace penumbra {

namespace fs = std::filesystem;
using nlohmann::json;

std::optional<std::string> control_character(std::string_view text) {
  for (const char c : text) {
    const auto b = static_cast<unsigned char>(c);
    if (b < 0x20 || b == 0x7f) {
      char hex[3];
      std::snprintf(hex, sizeof hex, "%02x", b);
      return std::string(hex);
    }
  }
  return std::nullopt;
}

std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (const auto bad = control_character(std::string_view(&c, 1)))
      out += "\\x" + *bad;
    else
      out += c;
  }
  return out;
}

namespace {

constexpr const char* kTopKeys[] = {"version", "defaults", "output_root", "shots"};
constexpr const char* kShotKeys[] = {"name",       "scene", "camera", "frames",      "output",  "png",
                                     "stats_json", "tiles", "deep",   "tile_frames", "settings"};
/// Largest scene file the job's up-front check accepts (the loader applies its own limits).
constexpr uint64_t kMaxSceneFileBytes = uint64_t(1) << 40;

/// The reader of one job file; every error names the file and the element.
class JobReader {
 public:
  explicit JobReader(const std::string& file) : m_file(file), m_json(file) {}

  [[noreturn]] void fail(const std::string& where, const std::string& message) const {
    m_json.fail(where, message);
  }
  void check_keys(const json& obj, const std::string& where, const std::string& what,
                  std::span<const char* const> keys) const {
    m_json.require_object(obj, where, what);
    m_json.check_keys(obj, where, what, keys, {}, {});
  }

  std::string string(const json& v, const std::string& where) const {
    if (!v.is_string()) fail(where, "must be a string (got " + gltf::shown(v) + ")");
    return v.get<std::string>();
  }
  std::string string_or(const json& obj, const char* key, const std::string& where) const {
    const json* v = gltf::JsonReader::find(obj, key);
    return v ? string(*v, where + "." + key) : std::string();
  }
  std::string required_string(const json& obj, const char* key, const std::string& where) const {
    const json* v = gltf::JsonReader::find(obj, key);
    if (!v) fail(where, "has no \"" + std::string(key) + "\"");
    const std::string s = string(*v, where + "." + key);
    if (s.empty()) fail(where + "." + key, "is empty");
    return s;
  }
  /// A path relative to the job file's folder. Control characters are refused: paths reach the
  /// unit list (a line per unit) and the scripts `submit slurm` generates.
  fs::path path(const std::string& text, const std::string& where) const {
    if (const auto bad = control_character(text))
      fail(where, "contains the control character 0x" + *bad +
                      " (paths may not hold newlines, tabs or other control characters)");
    const fs::path p(text);
    return (p.is_absolute() ? p : fs::absolute(m_file).parent_path() / p).lexically_normal();
  }
  /// "A-B[:STEP]" or an integer frame number.
  FrameRange frames(const json& v, const std::string& where) const {
    std::string text;
    if (v.is_number_integer())
      text = std::to_string(v.get<int64_t>());
    else if (v.is_string())
      text = v.get<std::string>();
    else
      fail(where, "must be a frame range \"A-B[:STEP]\" or a frame number (got " + gltf::shown(v) + ")");
    try {
      return parse_frame_range(text);
    } catch (const std::invalid_argument& e) {
      std::string message = e.what();
      const std::string prefix = "--frames: ";
      if (message.rfind(prefix, 0) == 0) message = message.substr(prefix.size());
      fail(where, message);
    }
  }
  std::vector<JobSetting> settings(const json& obj, const std::string& where) const {
    m_json.require_object(obj, where, "the settings");
    std::vector<JobSetting> out;
    for (const auto& [key, value] : obj.items()) {
      JobSetting s{key, {}, false, true, where + "." + key};
      if (key.empty() || key[0] == '-') fail(s.where, "a setting is a flag's name without the leading '--'");
      if (value.is_boolean()) {
        s.flag = true;
        s.enabled = value.get<bool>();
      } else if (value.is_array()) {
        if (value.empty()) fail(s.where, "is an empty array");
        for (size_t i = 0; i < value.size(); ++i) s.values.push_back(scalar(value[i], s.where, i));
      } else {
        s.values.push_back(scalar(value, s.where, -1));
      }
      out.push_back(std::move(s));
    }
    return out;
  }

 private:
  /// A string, or a number as the file writes it.
  std::string scalar(const json& v, const std::string& where, long index) const {
    const std::string at = index < 0 ? where : where + "[" + std::to_string(index) + "]";
    if (v.is_string()) return v.get<std::string>();
    // A whole number written as 1e3 or 4.0 reads as a float; an integer flag wants "1000".
    if (v.is_number_float() && std::isfinite(v.get<double>()) &&
        std::trunc(v.get<double>()) == v.get<double>() && std::fabs(v.get<double>()) < 9007199254740992.0)
      return std::to_string(static_cast<long long>(v.get<double>()));
    if (v.is_number()) return v.dump();
    fail(at, "must be a string, a number, a boolean or an array of strings and numbers (got " +
                 gltf::shown(v) + ")");
  }

  const std::string& m_file;
  gltf::JsonReader m_json;
};

json parse_job_json(const fs::path& file) {
  check_input_file(file, "", kMaxJobFileBytes);
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) throw InputError(file.string(), "", "cannot be read");
  const std::string s = text.str();
  if (json_nesting_depth(s, 32) > 32)
    throw InputError(file.string(), "", "JSON nested deeper than 32 levels");
  try {
    return json::parse(s);
  } catch (const json::parse_error& e) {
    throw InputError(file.string(), "", std::string("is not valid JSON: ") + e.what());
  }
}

/// The shot's settings after the job's defaults: a key the shot gives replaces the default's.
std::vector<JobSetting> merge_settings(const std::vector<JobSetting>& defaults, std::vector<JobSetting> own) {
  std::vector<JobSetting> out;
  for (const JobSetting& d : defaults) {
    bool replaced = false;
    for (const JobSetting& s : own) replaced = replaced || s.key == d.key;
    if (!replaced) out.push_back(d);
  }
  for (JobSetting& s : own) out.push_back(std::move(s));
  return out;
}

bool valid_shot_name(const std::string& name) {
  if (name.empty() || name.size() > 128) return false;
  for (const char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') return false;
  return true;
}

JobShot read_shot(const JobReader& r, const json& j, size_t index, const std::vector<JobSetting>& defaults) {
  const std::string at = "shots[" + std::to_string(index) + "]";
  r.check_keys(j, at, "a shot", kShotKeys);
  JobShot shot;
  shot.name = r.required_string(j, "name", at);
  if (!valid_shot_name(shot.name))
    r.fail(at + ".name", "'" + shot.name + "' must be 1 to 128 letters, digits, '.', '_' or '-'");
  shot.where = at + " (" + shot.name + ")";
  shot.scene = r.path(r.required_string(j, "scene", shot.where), shot.where + ".scene");
  try {
    check_input_file(shot.scene, "", kMaxSceneFileBytes);
  } catch (const InputError& e) {
    r.fail(shot.where + ".scene", e.what());
  }
  shot.output = r.path(r.required_string(j, "output", shot.where), shot.where + ".output").string();
  if (const std::string png = r.string_or(j, "png", shot.where); !png.empty())
    shot.png = r.path(png, shot.where + ".png").string();
  if (const std::string deep = r.string_or(j, "deep", shot.where); !deep.empty())
    shot.deep = r.path(deep, shot.where + ".deep").string();
  if (const std::string st = r.string_or(j, "stats_json", shot.where); !st.empty())
    shot.stats_json = r.path(st, shot.where + ".stats_json").string();
  if (const json* cam = gltf::JsonReader::find(j, "camera")) {
    if (cam->is_number_unsigned())
      shot.camera = std::to_string(cam->get<uint64_t>());
    else
      shot.camera = r.string(*cam, shot.where + ".camera");
  }
  if (const json* f = gltf::JsonReader::find(j, "frames")) {
    shot.frames = r.frames(*f, shot.where + ".frames");
    shot.frames_text = std::to_string(shot.frames->first) + "-" + std::to_string(shot.frames->last) + ":" +
                       std::to_string(shot.frames->step);
  }
  if (const json* t = gltf::JsonReader::find(j, "tiles")) {
    if (!t->is_number_integer() || t->get<int64_t>() < 1 || t->get<int64_t>() > kMaxJobTiles)
      r.fail(shot.where + ".tiles", "must be an integer from 1 to " + std::to_string(kMaxJobTiles) +
                                        " (got " + gltf::shown(*t) + ")");
    shot.tiles = int(t->get<int64_t>());
  }
  if (const json* tf = gltf::JsonReader::find(j, "tile_frames")) {
    if (!shot.frames) r.fail(shot.where + ".tile_frames", "needs \"frames\"");
    shot.tile_frames = r.frames(*tf, shot.where + ".tile_frames");
  }
  std::vector<JobSetting> own;
  if (const json* s = gltf::JsonReader::find(j, "settings")) own = r.settings(*s, shot.where + ".settings");
  shot.settings = merge_settings(defaults, std::move(own));
  return shot;
}

bool in_range(const FrameRange& r, int64_t f) {
  return f >= r.first && f <= r.last && (f - r.first) % r.step == 0;
}

}  // namespace

Job read_job_file(const fs::path& file) {
  Job job;
  job.file = fs::absolute(file).lexically_normal();
  const std::string name = file.string();
  if (const auto bad = control_character(job.file.string()))
    throw InputError(printable(name), "",
                     "the job file's path contains the control character 0x" + *bad +
                         " (it would reach the unit list and generated scripts)");
  const json j = parse_job_json(file);
  const JobReader r(name);
  r.check_keys(j, "", "the job", kTopKeys);
  if (const json* v = gltf::JsonReader::find(j, "version"))
    if (!v->is_number_integer() || v->get<int64_t>() != 1)
      r.fail("version", "must be 1 (got " + gltf::shown(*v) + ")");
  if (const std::string root = r.string_or(j, "output_root", ""); !root.empty())
    job.output_root = r.path(root, "output_root");
  std::vector<JobSetting> defaults;
  if (const json* d = gltf::JsonReader::find(j, "defaults")) defaults = r.settings(*d, "defaults");
  const json* shots = gltf::JsonReader::find(j, "shots");
  if (!shots || !shots->is_array() || shots->empty()) r.fail("shots", "must be a non-empty array of shots");
  std::map<std::string, size_t> names;
  for (size_t i = 0; i < shots->size(); ++i) {
    JobShot shot = read_shot(r, (*shots)[i], i, defaults);
    const auto [it, fresh] = names.emplace(shot.name, i);
    if (!fresh)
      r.fail(shot.where + ".name",
             "'" + shot.name + "' is also the name of shots[" + std::to_string(it->second) + "]");
    job.shots.push_back(std::move(shot));
  }
  return job;
}

std::vector<WorkUnit> job_units(const Job& job, int default_tiles) {
  std::vector<WorkUnit> units;
  for (size_t s = 0; s < job.shots.size(); ++s) {
    const JobShot& shot = job.shots[s];
    const int tiles = shot.tiles > 0 ? shot.tiles : default_tiles;
    if (tiles < 1 || tiles > kMaxJobTiles)
      throw InputError(job.file.string(), shot.where,
                       std::to_string(tiles) + " tiles per frame; from 1 to " + std::to_string(kMaxJobTiles));
    const int64_t count = shot.frames ? shot.frames->count() : 1;
    for (int64_t k = 0; k < count; ++k) {
      WorkUnit u{s, std::nullopt, 0, 1};
      if (shot.frames) u.frame = shot.frames->first + k * shot.frames->step;
      const bool tiled =
          tiles > 1 && (!shot.tile_frames || (u.frame && in_range(*shot.tile_frames, *u.frame)));
      u.tiles = tiled ? tiles : 1;
      if (units.size() + size_t(u.tiles) > kMaxJobUnits)
        throw InputError(job.file.string(), shot.where,
                         "the job splits into more than " + std::to_string(kMaxJobUnits) + " work units");
      for (int t = 0; t < u.tiles; ++t) {
        u.tile = t;
        units.push_back(u);
      }
    }
  }
  return units;
}

namespace {

/// Exact arithmetic on frame numbers (up to 2^40) times steps.
__extension__ typedef __int128 Wide;

/// floor(a / b) for b > 0.
Wide floor_div(Wide a, Wide b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

/// How many of the frames first + j * step, 0 <= j < k, lie in `tiled` (an arithmetic range
/// too): the j in an interval that solve the congruence j * step = tiled.first - first (mod
/// tiled.step), counted without enumerating them.
int64_t tiled_frames_before(const FrameRange& frames, const FrameRange& tiled, int64_t k) {
  if (k <= 0) return 0;
  const Wide a = frames.first, s = frames.step, b = tiled.first, t = tiled.step;
  // Frames inside [tiled.first, tiled.last]: j from ceil((b - a) / s) to floor((c - a) / s).
  Wide lo = -floor_div(a - b, s), hi = floor_div(Wide(tiled.last) - a, s);
  lo = std::max<Wide>(lo, 0);
  hi = std::min<Wide>(hi, Wide(k) - 1);
  if (lo > hi) return 0;
  // j * s = b - a (mod t): solvable iff gcd(s, t) divides b - a; then j = j0 (mod t / g).
  const int64_t g = std::gcd(int64_t(s), int64_t(t));
  const Wide diff = b - a;
  if (diff % g != 0) return 0;
  const Wide m = t / g;
  Wide j0 = 0;
  if (m > 1) {
    // The inverse of s / g modulo m by the extended Euclidean algorithm.
    Wide r0 = (s / g) % m, r1 = m, x0 = 1, x1 = 0;
    while (r1 != 0) {
      const Wide q = r0 / r1;
      std::swap(r0 -= q * r1, r1);
      std::swap(x0 -= q * x1, x1);
    }
    const Wide inv = ((x0 % m) + m) % m;
    j0 = ((((diff / g) % m) + m) % m) * inv % m;
  }
  return int64_t(floor_div(hi - j0, m) - floor_div(lo - 1 - j0, m));
}

}  // namespace

JobUnits::JobUnits(const Job& job, int default_tiles) {
  for (const JobShot& shot : job.shots) {
    Shot u;
    u.range = shot.frames;
    u.tiled = shot.tile_frames;
    u.first = m_size;
    u.tiles = shot.tiles > 0 ? shot.tiles : default_tiles;
    if (u.tiles < 1 || u.tiles > kMaxJobTiles)
      throw InputError(
          job.file.string(), shot.where,
          std::to_string(u.tiles) + " tiles per frame; from 1 to " + std::to_string(kMaxJobTiles));
    u.frames = shot.frames ? shot.frames->count() : 1;
    int64_t tiled = 0;
    if (u.tiles > 1)
      tiled = shot.tile_frames && shot.frames ? tiled_frames_before(*shot.frames, *shot.tile_frames, u.frames)
                                              : u.frames;
    const Wide count = Wide(u.frames) + Wide(tiled) * (u.tiles - 1);
    if (Wide(m_size) + count > Wide(kMaxJobUnits))
      throw InputError(job.file.string(), shot.where,
                       "the job splits into more than " + std::to_string(kMaxJobUnits) + " work units");
    u.count = size_t(count);
    m_size += u.count;
    m_shots.push_back(u);
  }
}

bool JobUnits::tiled(size_t s, int64_t k) const {
  const Shot& u = m_shots[s];
  if (u.tiles <= 1) return false;
  if (!u.tiled || !u.range) return true;
  return in_range(*u.tiled, u.range->first + k * u.range->step);
}

size_t JobUnits::units_before(size_t s, int64_t k) const {
  const Shot& u = m_shots[s];
  int64_t tiled = 0;
  if (u.tiles > 1) tiled = u.tiled && u.range ? tiled_frames_before(*u.range, *u.tiled, k) : k;
  return size_t(k) + size_t(tiled) * size_t(u.tiles - 1);
}

WorkUnit JobUnits::operator[](size_t n) const {
  // The shot: the last whose first unit is <= n.
  size_t s = size_t(std::upper_bound(m_shots.begin(), m_shots.end(), n,
                                     [](size_t v, const Shot& u) { return v < u.first; }) -
                    m_shots.begin()) -
             1;
  const Shot& shot = m_shots[s];
  const size_t i = n - m_shots[s].first;
  // The frame: the last k with units_before(k) <= i.
  int64_t lo = 0, hi = m_shots[s].frames - 1;
  while (lo < hi) {
    const int64_t mid = lo + (hi - lo + 1) / 2;
    if (units_before(s, mid) <= i)
      lo = mid;
    else
      hi = mid - 1;
  }
  WorkUnit u{s, std::nullopt, 0, 1};
  if (shot.range) u.frame = shot.range->first + lo * shot.range->step;
  if (tiled(s, lo)) {
    u.tiles = shot.tiles;
    u.tile = int(i - units_before(s, lo));
  }
  return u;
}

WorkUnit JobUnits::at(size_t n) const {
  if (n >= m_size)
    throw std::out_of_range("unit " + std::to_string(n) + " of a job of " + std::to_string(m_size));
  return (*this)[n];
}

std::string unit_output(const Job& job, const WorkUnit& unit) {
  const std::string& out = job.shots[unit.shot].output;
  return unit.frame ? substitute_frame(out, *unit.frame) : out;
}

fs::path tile_part_path(const fs::path& output, int tile, int tiles) {
  fs::path p = output;
  p.replace_filename(output.stem().string() + ".tile-" + std::to_string(tile) + "-of-" +
                     std::to_string(tiles) + output.extension().string());
  return p;
}

}  // namespace penumbra
