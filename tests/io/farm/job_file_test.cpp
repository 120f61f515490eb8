// Tests for io/job_file: job files written to a temporary folder and read back (paths against
// the job's folder, defaults merged with each shot's settings, settings as text, frames and
// tiles), their work units and outputs, and every refusal naming the file and the element.
#include "io/farm/job_file.h"

#include <catch2/catch.hpp>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/files/error.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

/// A temporary folder holding a scene file (any readable file passes the job's check).
struct JobDir {
  fs::path dir;
  explicit JobDir(const std::string& name) : dir(test::temp_dir("job_file-" + name)) {
    fs::create_directories(dir / "scenes");
    fs::copy_file(test::source_dir() / "scenes" / "default.gltf", dir / "scenes" / "a.gltf");
  }
  ~JobDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  /// Writes `text` as NAME.json in the folder and returns its path.
  fs::path write(const std::string& text, const std::string& name = "job") const {
    const fs::path p = dir / (name + ".json");
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  Job read(const std::string& text) const { return read_job_file(write(text)); }
};

/// A job of the given shots (JSON objects, comma-separated) with scene and output filled in by
/// the caller.
std::string job_of(const std::string& shots, const std::string& extra = "") {
  return "{\"version\": 1" + extra + ", \"shots\": [" + shots + "]}";
}

const JobSetting* find_setting(const JobShot& shot, const std::string& key) {
  for (const JobSetting& s : shot.settings)
    if (s.key == key) return &s;
  return nullptr;
}

/// The message of the InputError read_job_file throws for `text` ("" when none is thrown).
std::string read_error(const JobDir& d, const std::string& text) {
  try {
    read_job_file(d.write(text));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("read_job_file resolves relative paths against the job file's folder", "[io][job]") {
  const JobDir d("paths");
  fs::create_directories(d.dir / "sub");
  const fs::path file = d.dir / "sub" / "job.json";
  std::ofstream(file) << R"({"shots": [{"name": "sh010", "scene": "../scenes/a.gltf",
    "output": "out/sh010.####.exr", "png": "png/sh010.####.png", "stats_json": "st/sh010.json",
    "frames": "1-2", "camera": 1},
    {"name": "abs", "scene": ")" +
                             (d.dir / "scenes" / "a.gltf").string() + R"(", "output": "/tmp/abs.exr",
     "camera": "Cam"}]})";
  const Job job = read_job_file(file);
  CHECK(job.file.is_absolute());
  CHECK(job.file == fs::absolute(file).lexically_normal());
  REQUIRE(job.shots.size() == 2);
  const JobShot& s = job.shots[0];
  CHECK(s.name == "sh010");
  CHECK(s.where == "shots[0] (sh010)");
  CHECK(s.scene == (d.dir / "scenes" / "a.gltf").lexically_normal());
  CHECK(s.output == (d.dir / "sub" / "out" / "sh010.####.exr").lexically_normal().string());
  CHECK(s.png == (d.dir / "sub" / "png" / "sh010.####.png").lexically_normal().string());
  CHECK(s.stats_json == (d.dir / "sub" / "st" / "sh010.json").lexically_normal().string());
  CHECK(s.camera == "1");
  CHECK(job.shots[1].scene == d.dir / "scenes" / "a.gltf");
  CHECK(job.shots[1].output == "/tmp/abs.exr");
  CHECK(job.shots[1].camera == "Cam");
  CHECK(job.shots[1].png.empty());
  CHECK(job.shots[1].stats_json.empty());
  CHECK_FALSE(job.shots[1].frames);
}

TEST_CASE("read_job_file merges the defaults with each shot's settings", "[io][job]") {
  const JobDir d("settings");
  const Job job = d.read(R"({"version": 1,
    "defaults": {"spp": 16, "width": 64, "exposure": 0.25, "integrator": "path", "float": true},
    "shots": [
      {"name": "a", "scene": "scenes/a.gltf", "output": "a.exr",
       "settings": {"spp": 4, "aov": ["depth", "normal"], "denoise": false, "bias": -3}},
      {"name": "b", "scene": "scenes/a.gltf", "output": "b.exr"}]})");
  REQUIRE(job.shots.size() == 2);
  const JobShot& a = job.shots[0];
  // The shot's key replaces the default's: one "spp", the shot's value.
  int spp_count = 0;
  for (const JobSetting& s : a.settings) spp_count += s.key == "spp" ? 1 : 0;
  CHECK(spp_count == 1);
  const JobSetting* spp = find_setting(a, "spp");
  REQUIRE(spp);
  CHECK(spp->values == std::vector<std::string>{"4"});
  CHECK(spp->where == "shots[0] (a).settings.spp");
  CHECK_FALSE(spp->flag);
  // The defaults the shot does not give stay, with their JSON path.
  const JobSetting* width = find_setting(a, "width");
  REQUIRE(width);
  CHECK(width->values == std::vector<std::string>{"64"});
  CHECK(width->where == "defaults.width");
  // Numbers as written, strings as they are, arrays as repeated values, booleans as flags.
  REQUIRE(find_setting(a, "exposure"));
  CHECK(find_setting(a, "exposure")->values == std::vector<std::string>{"0.25"});
  REQUIRE(find_setting(a, "bias"));
  CHECK(find_setting(a, "bias")->values == std::vector<std::string>{"-3"});
  REQUIRE(find_setting(a, "integrator"));
  CHECK(find_setting(a, "integrator")->values == std::vector<std::string>{"path"});
  const JobSetting* aov = find_setting(a, "aov");
  REQUIRE(aov);
  CHECK(aov->values == std::vector<std::string>{"depth", "normal"});
  const JobSetting* fl = find_setting(a, "float");
  REQUIRE(fl);
  CHECK((fl->flag && fl->enabled && fl->values.empty()));
  const JobSetting* dn = find_setting(a, "denoise");
  REQUIRE(dn);
  CHECK((dn->flag && !dn->enabled));
  // The defaults come first, then the shot's own.
  CHECK(a.settings.front().where.rfind("defaults.", 0) == 0);
  CHECK(a.settings.back().where.rfind("shots[0] (a).settings.", 0) == 0);
  // A shot without settings has exactly the defaults.
  const JobShot& b = job.shots[1];
  CHECK(b.settings.size() == 5);
  REQUIRE(find_setting(b, "spp"));
  CHECK(find_setting(b, "spp")->values == std::vector<std::string>{"16"});
}

TEST_CASE("read_job_file reads frames as a range, a stepped range or a number", "[io][job]") {
  const JobDir d("frames");
  const Job job =
      d.read(job_of(R"({"name": "r", "scene": "scenes/a.gltf", "output": "r.#.exr", "frames": "1-3"},
    {"name": "s", "scene": "scenes/a.gltf", "output": "s.#.exr", "frames": "1-9:4"},
    {"name": "n", "scene": "scenes/a.gltf", "output": "n.#.exr", "frames": 7},
    {"name": "still", "scene": "scenes/a.gltf", "output": "still.exr"})"));
  REQUIRE(job.shots.size() == 4);
  REQUIRE(job.shots[0].frames);
  CHECK(
      (job.shots[0].frames->first == 1 && job.shots[0].frames->last == 3 && job.shots[0].frames->step == 1));
  CHECK(job.shots[0].frames_text == "1-3:1");
  REQUIRE(job.shots[1].frames);
  CHECK(
      (job.shots[1].frames->first == 1 && job.shots[1].frames->last == 9 && job.shots[1].frames->step == 4));
  CHECK(job.shots[1].frames->count() == 3);
  CHECK(job.shots[1].frames_text == "1-9:4");
  REQUIRE(job.shots[2].frames);
  CHECK((job.shots[2].frames->first == 7 && job.shots[2].frames->last == 7));
  CHECK(job.shots[2].frames_text == "7-7:1");
  CHECK_FALSE(job.shots[3].frames);

  const std::vector<WorkUnit> units = job_units(job);
  REQUIRE(units.size() == 3 + 3 + 1 + 1);
  const std::vector<int64_t> frames = {1, 2, 3, 1, 5, 9, 7};
  for (size_t i = 0; i < frames.size(); ++i) {
    REQUIRE(units[i].frame);
    CHECK(*units[i].frame == frames[i]);
    CHECK(units[i].tiles == 1);
  }
  CHECK_FALSE(units[7].frame);
  CHECK(units[7].shot == 3);
  CHECK(unit_output(job, units[4]) == (d.dir / "s.5.exr").string());
  CHECK(unit_output(job, units[7]) == (d.dir / "still.exr").string());
}

TEST_CASE("job_units orders shots, frames and stripes; tiles, tile_frames and default tiles", "[io][job]") {
  const JobDir d("units");
  const Job job = d.read(job_of(R"({"name": "t", "scene": "scenes/a.gltf", "output": "t.####.exr",
      "frames": "1-3", "tiles": 2, "tile_frames": 2},
    {"name": "plain", "scene": "scenes/a.gltf", "output": "p.####.exr", "frames": "10-11"},
    {"name": "one", "scene": "scenes/a.gltf", "output": "one.exr", "tiles": 1},
    {"name": "still", "scene": "scenes/a.gltf", "output": "still.exr", "tiles": 3})"));
  REQUIRE(job.shots.size() == 4);
  CHECK(job.shots[0].tiles == 2);
  REQUIRE(job.shots[0].tile_frames);
  CHECK((job.shots[0].tile_frames->first == 2 && job.shots[0].tile_frames->last == 2));
  CHECK(job.shots[1].tiles == 0);  // not given: the job's default

  struct Want {
    size_t shot;
    std::optional<int64_t> frame;
    int tile, tiles;
  };
  const auto check_units = [&](const std::vector<WorkUnit>& got, const std::vector<Want>& want) {
    REQUIRE(got.size() == want.size());
    for (size_t i = 0; i < want.size(); ++i) {
      INFO("unit " << i);
      CHECK(got[i].shot == want[i].shot);
      CHECK(got[i].frame == want[i].frame);
      CHECK(got[i].tile == want[i].tile);
      CHECK(got[i].tiles == want[i].tiles);
    }
  };
  // Default tiles 1: only frame 2 of "t" and the still with "tiles": 3 are split.
  check_units(job_units(job), {{0, 1, 0, 1},
                               {0, 2, 0, 2},
                               {0, 2, 1, 2},
                               {0, 3, 0, 1},
                               {1, 10, 0, 1},
                               {1, 11, 0, 1},
                               {2, std::nullopt, 0, 1},
                               {3, std::nullopt, 0, 3},
                               {3, std::nullopt, 1, 3},
                               {3, std::nullopt, 2, 3}});
  // Default tiles 4 only reach the shot without "tiles".
  check_units(job_units(job, 4), {{0, 1, 0, 1},
                                  {0, 2, 0, 2},
                                  {0, 2, 1, 2},
                                  {0, 3, 0, 1},
                                  {1, 10, 0, 4},
                                  {1, 10, 1, 4},
                                  {1, 10, 2, 4},
                                  {1, 10, 3, 4},
                                  {1, 11, 0, 4},
                                  {1, 11, 1, 4},
                                  {1, 11, 2, 4},
                                  {1, 11, 3, 4},
                                  {2, std::nullopt, 0, 1},
                                  {3, std::nullopt, 0, 3},
                                  {3, std::nullopt, 1, 3},
                                  {3, std::nullopt, 2, 3}});
  CHECK_THROWS_AS(job_units(job, 0), InputError);
  CHECK_THROWS_WITH(job_units(job, kMaxJobTiles + 1), Contains("shots[1] (plain)"));

  const std::vector<WorkUnit> units = job_units(job);
  CHECK(unit_output(job, units[1]) == (d.dir / "t.0002.exr").string());
  CHECK(unit_output(job, units[2]) == (d.dir / "t.0002.exr").string());
  CHECK(unit_output(job, units[5]) == (d.dir / "p.0011.exr").string());
  CHECK(tile_part_path("a/b.0002.exr", 1, 4) == fs::path("a/b.0002.tile-1-of-4.exr"));
  CHECK(tile_part_path("/x/still.exr", 0, 3) == fs::path("/x/still.tile-0-of-3.exr"));
}

TEST_CASE("job_units refuses a job of more than kMaxJobUnits units", "[io][job]") {
  const JobDir d("too_many");
  const Job job = d.read(job_of(R"({"name": "big", "scene": "scenes/a.gltf", "output": "big.######.exr",
      "frames": "1-100000", "tiles": 20})"));
  try {
    job_units(job);
    FAIL("no error for 2000000 units");
  } catch (const InputError& e) {
    CHECK_THAT(std::string(e.what()), Contains(job.file.string()));
    CHECK_THAT(std::string(e.what()), Contains("shots[0] (big)"));
    CHECK_THAT(std::string(e.what()), Contains("more than " + std::to_string(kMaxJobUnits)));
  }
  // Exactly at the limit is fine: 100000 frames x 10 stripes.
  const Job ok = d.read(job_of(R"({"name": "big", "scene": "scenes/a.gltf", "output": "big.######.exr",
      "frames": "1-100000", "tiles": 10})"));
  CHECK(job_units(ok).size() == kMaxJobUnits);
}

TEST_CASE("read_job_file refuses bad job files, naming the file and the element", "[io][job]") {
  const JobDir d("errors");
  const std::string a = R"("name": "a", "scene": "scenes/a.gltf", "output": "a.exr")";
  const std::string b = R"("name": "b", "scene": "scenes/a.gltf", "output": "b.####.exr")";
  const std::string file = (d.dir / "job.json").string();
  struct Case {
    std::string json, element, message;
  };
  const std::vector<Case> cases = {
      {"{\"shots\": [", "", "is not valid JSON"},
      {"", "", "is not valid JSON"},
      {job_of("{" + a + "}", ", \"extra\": 1"), "extra", "unknown key"},
      {job_of("{" + a + ", \"spp\": 4}"), "shots[0].spp", "unknown key"},
      {job_of(R"({"scene": "scenes/a.gltf", "output": "a.exr"})"), "shots[0]", "has no \"name\""},
      {job_of(R"({"name": "a", "output": "a.exr"})"), "shots[0] (a)", "has no \"scene\""},
      {job_of(R"({"name": "a", "scene": "scenes/a.gltf"})"), "shots[0] (a)", "has no \"output\""},
      {job_of(R"({"name": "", "scene": "scenes/a.gltf", "output": "a.exr"})"), "shots[0].name", "is empty"},
      {job_of("{" + a + "}, {" + a + "}"), "shots[1] (a).name", "also the name of shots[0]"},
      {job_of(R"({"name": "a b", "scene": "scenes/a.gltf", "output": "a.exr"})"), "shots[0].name",
       "letters, digits"},
      {job_of(R"({"name": "a/b", "scene": "scenes/a.gltf", "output": "a.exr"})"), "shots[0].name",
       "letters, digits"},
      {job_of(R"({"name": "a", "scene": 3, "output": "a.exr"})"), "shots[0] (a).scene", "must be a string"},
      {job_of("{" + a + "}, {" + b + ", \"tiles\": 0}"), "shots[1] (b).tiles", "from 1 to 4096"},
      {job_of("{" + a + "}, {" + b + ", \"tiles\": 5000}"), "shots[1] (b).tiles", "from 1 to 4096"},
      {job_of("{" + a + "}, {" + b + ", \"tiles\": \"4\"}"), "shots[1] (b).tiles", "from 1 to 4096"},
      {job_of("{" + a + "}, {" + b + ", \"tiles\": 2.5}"), "shots[1] (b).tiles", "from 1 to 4096"},
      {job_of("{" + a + ", \"tile_frames\": 1}"), "shots[0] (a).tile_frames", "needs \"frames\""},
      {job_of("{" + b + ", \"frames\": \"3-1\"}"), "shots[0] (b).frames", "empty"},
      {job_of("{" + b + ", \"frames\": \"x\"}"), "shots[0] (b).frames", "'x' is not a frame range"},
      {job_of("{" + b + ", \"frames\": 1.5}"), "shots[0] (b).frames", "must be a frame range"},
      {job_of("{" + b + ", \"frames\": \"1-3\", \"tile_frames\": \"x\"}"), "shots[0] (b).tile_frames",
       "'x' is not a frame range"},
      {"{\"version\": 2, \"shots\": [{" + a + "}]}", "version", "must be 1 (got 2)"},
      {R"({"version": 1, "shots": []})", "shots", "non-empty array"},
      {R"({"version": 1})", "shots", "non-empty array"},
      {R"({"version": 1, "shots": {}})", "shots", "non-empty array"},
      {R"([1, 2])", "", "must be the job object"},
      {job_of("{" + a + ", \"settings\": {\"spp\": {\"x\": 1}}}"), "shots[0] (a).settings.spp",
       "must be a string, a number, a boolean or an array"},
      {job_of("{" + a + "}", ", \"defaults\": {\"spp\": [1, {}]}"), "defaults.spp[1]",
       "must be a string, a number, a boolean or an array"},
      {job_of("{" + a + "}", ", \"defaults\": {\"aov\": []}"), "defaults.aov", "is an empty array"},
      {job_of("{" + a + "}", ", \"defaults\": {\"spp\": null}"), "defaults.spp", "must be a string"},
      {job_of("{" + a + "}", ", \"defaults\": {\"--spp\": 4}"), "defaults.--spp", "without the leading '--'"},
      {job_of("{" + a + ", \"settings\": [1]}"), "shots[0] (a).settings", "must be the settings object"},
      {job_of("3"), "shots[0]", "must be a shot object"},
  };
  for (const Case& c : cases) {
    INFO(c.json);
    const std::string message = read_error(d, c.json);
    REQUIRE_FALSE(message.empty());
    CHECK_THAT(message, Contains(file));
    if (!c.element.empty()) CHECK_THAT(message, Contains(c.element + ": "));
    CHECK_THAT(message, Contains(c.message));
  }
}

TEST_CASE("read_job_file refuses JSON nested deeper than 32 levels", "[io][job]") {
  const JobDir d("nesting");
  const std::string a = R"({"name": "a", "scene": "scenes/a.gltf", "output": "a.exr"})";
  // 42 levels: refused before the JSON is parsed.
  const std::string deep = std::string(40, '[') + "1" + std::string(40, ']');
  const std::string message = read_error(d, job_of(a, ", \"defaults\": {\"x\": " + deep + "}"));
  CHECK_THAT(message, Contains((d.dir / "job.json").string()));
  CHECK_THAT(message, Contains("nested deeper than 32"));
  // Exactly 32 levels parse (and are then refused for their content, not their depth).
  const std::string ok_depth = std::string(30, '[') + "1" + std::string(30, ']');  // + 2 objects
  const std::string m32 = read_error(d, job_of(a, ", \"defaults\": {\"x\": " + ok_depth + "}"));
  CHECK_THAT(m32, !Contains("nested deeper"));
  CHECK_THAT(m32, Contains("defaults.x[0]"));
}

TEST_CASE("read_job_file refuses a missing scene, naming the job file, the shot and the scene", "[io][job]") {
  const JobDir d("missing_scene");
  fs::create_directories(d.dir / "adir.gltf");
  for (const char* scene : {"scenes/missing.gltf", "adir.gltf"}) {
    INFO(scene);
    const std::string message =
        read_error(d, job_of(R"({"name": "ok", "scene": "scenes/a.gltf", "output": "ok.exr"},
                  {"name": "a", "scene": ")" +
                             std::string(scene) + R"(", "output": "a.exr"})"));
    REQUIRE_FALSE(message.empty());
    CHECK_THAT(message, Contains("shots[1] (a).scene"));
    CHECK_THAT(message, Contains((d.dir / scene).string()));
    CHECK_THAT(message, Contains((d.dir / "job.json").string()));  // which job file, on a farm
  }
}

TEST_CASE("JobUnits computes every unit job_units lists, tile_frames with any steps included", "[io][job]") {
  // Shots with frame ranges and tiled ranges of co-prime, shared and unrelated steps and
  // offsets (negative frames too), against the listed units one by one.
  std::mt19937 rng(7);
  for (int trial = 0; trial < 300; ++trial) {
    Job job;
    job.file = "/tmp/units.json";
    const int shots = 1 + int(rng() % 4);
    for (int s = 0; s < shots; ++s) {
      JobShot shot;
      shot.name = "s" + std::to_string(s);
      shot.where = "shots[" + std::to_string(s) + "]";
      shot.output = "/tmp/s" + std::to_string(s) + ".####.exr";
      if (rng() % 5 != 0) {
        const int64_t first = int64_t(rng() % 41) - 20, step = 1 + int64_t(rng() % 6);
        shot.frames = FrameRange{first, first + int64_t(rng() % 60) * step + int64_t(rng() % step), step};
        if (rng() % 2) {
          const int64_t tf = int64_t(rng() % 61) - 30, ts = 1 + int64_t(rng() % 9);
          shot.tile_frames = FrameRange{tf, tf + int64_t(rng() % 50), ts};
        }
      }
      shot.tiles = int(rng() % 4);  // 0: the default
      job.shots.push_back(shot);
    }
    const int default_tiles = 1 + int(rng() % 3);
    const std::vector<WorkUnit> listed = job_units(job, default_tiles);
    const JobUnits lazy(job, default_tiles);
    REQUIRE(lazy.size() == listed.size());
    for (size_t n = 0; n < listed.size(); ++n) {
      const WorkUnit u = lazy[n];
      INFO("trial " << trial << ", unit " << n);
      REQUIRE(u.shot == listed[n].shot);
      REQUIRE(u.frame == listed[n].frame);
      REQUIRE(u.tile == listed[n].tile);
      REQUIRE(u.tiles == listed[n].tiles);
    }
    CHECK_THROWS_AS(lazy.at(listed.size()), std::out_of_range);
  }
}

TEST_CASE("JobUnits of a job at the unit limit answers any unit without listing them", "[io][job]") {
  Job job;
  job.file = "/tmp/big.json";
  JobShot shot;
  shot.name = "big";
  shot.where = "shots[0] (big)";
  shot.output = "/tmp/big.#######.exr";
  shot.frames = FrameRange{1, 500000, 1};
  shot.tile_frames = FrameRange{2, 1000000, 2};  // every even frame in 3 stripes
  shot.tiles = 3;
  job.shots.push_back(shot);
  const JobUnits units(job, 1);
  // 250000 untiled frames + 250000 tiled frames x 3 stripes.
  REQUIRE(units.size() == 1000000);
  const WorkUnit last = units[units.size() - 1];
  CHECK(*last.frame == 500000);
  CHECK((last.tile == 2 && last.tiles == 3));
  const WorkUnit u = units[4];  // frame 1 (0), frame 2 (1, 2, 3), frame 3 (4)
  CHECK(*u.frame == 3);
  CHECK(u.tiles == 1);
  shot.frames = FrameRange{1, 500001, 1};
  job.shots[0] = shot;
  CHECK_THROWS_WITH(JobUnits(job, 1), Contains("more than " + std::to_string(kMaxJobUnits)));
}
