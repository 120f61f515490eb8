// Batch job files: the shots a farm renders (scene, camera, frames, tiles, outputs and render
// settings) read from JSON with every key checked, and the work units (shot x frame x tile) they
// split into, numbered so that any scheduler can run unit N on its own. The settings stay text:
// apps/ maps them onto `render`'s flags.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/farm/frame_outputs.h"

namespace penumbra {

/// Largest job file read.
inline constexpr uint64_t kMaxJobFileBytes = uint64_t(16) << 20;
/// Most work units one job may split into.
inline constexpr uint64_t kMaxJobUnits = 1000000;
/// Most tiles one frame may be split into.
inline constexpr int kMaxJobTiles = 4096;

/// One render setting: `render`'s flag `--key` with its values (one per occurrence; several for
/// an array). A JSON boolean is a flag: true gives it without a value, false leaves it out.
struct JobSetting {
  std::string key;  ///< the flag's long name without "--"
  std::vector<std::string>
      values;           ///< numbers in JSON's notation (whole ones as integers), strings as they are
  bool flag = false;    ///< a JSON boolean
  bool enabled = true;  ///< the boolean's value
  std::string where;    ///< its JSON path, for messages
};

struct JobShot {
  std::string name;   ///< unique in the job; letters, digits, '.', '_' and '-'
  std::string where;  ///< "shots[i] (name)", for messages
  std::filesystem::path scene;
  std::string camera;                     ///< empty: render's default
  std::optional<FrameRange> frames;       ///< none: one still at the file's static pose
  std::string frames_text;                ///< as written, normalised to "A-B:STEP"
  std::string output, png, stats_json;    ///< paths, '#' patterns kept; png/stats empty = none
  std::string deep;                       ///< the deep EXR's path ('#' kept); empty = none
  int tiles = 0;                          ///< stripes per frame; 0 = not given (the job's default)
  std::optional<FrameRange> tile_frames;  ///< the frames that are tiled; none = every frame
  std::vector<JobSetting> settings;       ///< the job's defaults, then the shot's own (a key
                                          ///< given in both keeps the shot's)
};

/// A job file as read: relative paths resolved against the file's folder.
struct Job {
  std::filesystem::path file;         ///< absolute
  std::filesystem::path output_root;  ///< "output_root" (absolute); empty: not given
  std::vector<JobShot> shots;
};

/// The first control character (a byte below 0x20, or 0x7f) of `text` as two hex digits, or none.
/// Paths with one are refused wherever they would reach a line-based output or a script.
std::optional<std::string> control_character(std::string_view text);

/// `text` with each control character shown as \xNN, for messages.
std::string printable(std::string_view text);

/// Reads and checks `file`: top-level keys `version` (1), `defaults` (settings for every
/// shot), `output_root` (a folder every output must lie in) and `shots` (a non-empty array); per shot `name`,
/// `scene`, `output` (required), `camera`, `frames`, `png`, `deep`, `stats_json`, `tiles`, `tile_frames` and
/// `settings`. A setting is a string, a number, a boolean or an array of strings and numbers. Throws
/// InputError naming the file and the element (`shots[1] (sh020).tiles: ...`) for malformed JSON, unknown
/// keys, wrong types, duplicate names, bad frame ranges, a path (the job file's own included) with a control
/// character or a scene that is not a readable file.
Job read_job_file(const std::filesystem::path& file);

/// One piece of work: a frame of a shot, or one stripe of it.
struct WorkUnit {
  size_t shot = 0;
  std::optional<int64_t> frame;  ///< none for a still
  int tile = 0;                  ///< stripe index when tiles > 1
  int tiles = 1;                 ///< stripes of this frame
};

/// Every unit of `job` in order: shots as listed, frames ascending, stripes top first. A shot
/// without `tiles` splits its frames into `default_tiles` stripes (>= 1); `tile_frames`
/// restricts tiling to those frames. Throws InputError naming the job file when a shot asks
/// for more stripes than kMaxJobTiles or the job would exceed kMaxJobUnits units.
std::vector<WorkUnit> job_units(const Job& job, int default_tiles = 1);

/// The work units of a job as job_units() lists them, each computed from its index (shot by a
/// binary search over the shots' first units, frame and stripe by arithmetic), so that a job of
/// kMaxJobUnits units is listed, checked and submitted in memory that grows with the shots,
/// not the units. Keeps what it needs of the job (a copy of each shot's ranges).
class JobUnits {
 public:
  JobUnits() = default;
  /// Throws InputError as job_units() does.
  JobUnits(const Job& job, int default_tiles);
  size_t size() const { return m_size; }
  bool empty() const { return m_size == 0; }
  /// Unit `n` (< size()): what job_units(job, default_tiles)[n] is.
  WorkUnit operator[](size_t n) const;
  /// operator[] after a range check; throws std::out_of_range.
  WorkUnit at(size_t n) const;
  /// The index of the first unit of shot `s` and how many units it has.
  size_t first_of_shot(size_t s) const { return m_shots.at(s).first; }
  size_t units_of_shot(size_t s) const { return m_shots.at(s).count; }

 private:
  struct Shot {
    size_t first = 0, count = 0;             ///< its units' indices
    int64_t frames = 1;                      ///< frames (1 for a still)
    int tiles = 1;                           ///< stripes of a tiled frame
    std::optional<FrameRange> range, tiled;  ///< the shot's frames and tile_frames
  };
  /// Units of shot `s` before its k-th frame.
  size_t units_before(size_t s, int64_t k) const;
  /// True when the k-th frame of shot `s` is tiled.
  bool tiled(size_t s, int64_t k) const;

  std::vector<Shot> m_shots;
  size_t m_size = 0;
};

/// The final EXR of a unit's frame: the shot's output with its '#' run replaced by the frame.
std::string unit_output(const Job& job, const WorkUnit& unit);

/// Where stripe `tile` of `tiles` of `output` is rendered before the merge: beside it, as
/// "NAME.tile-I-of-N.exr" (for "NAME.exr").
std::filesystem::path tile_part_path(const std::filesystem::path& output, int tile, int tiles);

}  // namespace penumbra
