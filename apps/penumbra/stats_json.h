// `--stats-json`: the run's statistics as JSON for farm tooling: times per phase, rays by kind,
// samples, passes, threads, peak memory, scene size, and the SHA-256 of every image as this run
// wrote it, so a reader can tell whether the files at those paths are the ones described.
#pragma once

#include <string>
#include <vector>

#include "apps/penumbra/progress.h"

namespace penumbra::cli {

/// Each image as written: the option that named it ("exr", "png", "cost_png"), its path and the
/// SHA-256 of its bytes.
struct WrittenImage {
  std::string key, path, sha256;
};

/// The statistics document (nlohmann::json, two-space indented, newline-terminated).
std::string stats_json_text(const RenderReport& report, const std::vector<WrittenImage>& written);

/// Writes stats_json_text to `path` atomically (or streams it to a device).
void write_stats_json(const RenderReport& report, const std::vector<WrittenImage>& written,
                      const std::string& path);

}  // namespace penumbra::cli
