// `--stats-json`: the run's statistics as JSON for farm tooling: times per phase, rays by kind,
// samples, passes, threads, peak memory, scene size, and the SHA-256 of every image as this run
// wrote it, so a reader can tell whether the files at those paths are the ones described.
#pragma once

#include <string>

namespace penumbra::cli {

struct RenderJob;

/// The statistics document (nlohmann::json, two-space indented, newline-terminated).
std::string stats_json_text(const RenderJob& job);

/// Writes stats_json_text(job) to --stats-json's path atomically (or streams it to a device).
void write_stats_json(const RenderJob& job);

}  // namespace penumbra::cli
