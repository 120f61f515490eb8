// `penumbra batch JOB.json`: the shots of a job file rendered locally, listed as work units
// (shot x frame x tile, one per line) for a farm, one unit rendered (`--unit N`), or the tiled
// frames merged (`--merge`). The job and every unit's render flags are checked before anything
// renders; every render is `--reproducible`, so a frame rendered whole, or in stripes on a farm
// and merged, is the same file.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "apps/penumbra/render_options.h"
#include "io/farm/job_file.h"

namespace penumbra::cli {

struct BatchArgs {
  std::string job_file;
  bool list = false;            ///< print the work units
  std::optional<int64_t> unit;  ///< render this unit only
  bool merge = false;           ///< merge every tiled frame whose stripes are complete
  int tiles = 1;                ///< stripes per frame for shots that give no "tiles"
  bool skip_existing = false;   ///< keep complete outputs (the farm's re-runs)
  bool quiet = false;
  std::string progress = "auto";  ///< `render --progress` for every render (auto, text, json, none)
  int threads = 0;                ///< `render --threads` for shots whose settings give none; 0 = none
  std::string max_memory;         ///< `render --max-memory` for shots whose settings give none
  std::string output_root;        ///< the folder every output must be in; empty: the job file's
};

/// A checked job: the file, its units, and each shot's `render` flags for a whole range.
struct PreparedJob {
  Job job;
  JobUnits units;
  std::vector<RenderArgs> shot_args;  ///< per shot: every frame, whole, into its outputs
  int threads = 0;                    ///< BatchArgs' defaults
  std::string max_memory;
  std::vector<std::filesystem::path> made_folders;  ///< output folders prepare_job created, parents first
};

/// Reads the job, maps every shot's settings onto `render`'s flags and checks them as `render` would (a
/// shot's first and last frame in full, a tiled frame's stripes, no more stripes than the rows where the
/// settings give the height), that every file the units write lies in the output root
/// (BatchArgs::output_root, or the job file's folder; the job's "output_root" narrows it) and that no two
/// units write one file (frames, stripes, display images, statistics, resume states, Cryptomatte sidecars).
/// With `create_folders` the folders the outputs go into are made (after the root check: a farm's output tree
/// need not exist). Throws InputError naming the job file, the shot and the key; a refused job leaves no
/// folder behind.
PreparedJob prepare_job(const BatchArgs& args, bool create_folders);

/// Removes the folders prepare_job created while they are still empty (after a check that
/// writes nothing: --list, --dry-run).
void remove_made_folders(PreparedJob& job);

/// The `render` flags of unit `n`: its frame, and for a stripe `--tile i/N` into
/// tile_part_path() without display image or statistics.
RenderArgs unit_render_args(const PreparedJob& job, size_t n);

/// True when unit `n` needs no render: its frame's EXR is complete, or (a stripe) its part is.
bool unit_complete(const PreparedJob& job, size_t n);

/// Runs `batch`. Returns the exit code; throws for bad input.
int run_batch(const BatchArgs& args);

}  // namespace penumbra::cli
