// penumbra-bench --queries: the spatial queries other than rays (nearest primitive, k nearest
// points, within a distance, overlapping a box) per structure, with build time and memory,
// every answer of a verified subset compared with brute force, and nanoflann's kD-tree beside
// them for the k nearest points.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "renderer/accel/factory.h"
#include "renderer/scene/scene.h"

namespace penumbra::bench {

/// What --queries measures.
struct QueryBenchConfig {
  std::vector<std::string> kinds{"nearest", "knn", "within", "overlap"};
  std::vector<std::string> accels;
  int count = 20000;   ///< query points per kind
  int k = 8;           ///< neighbours of knn
  int threads = 1;     ///< worker threads (0: all cores)
  int builds = 3;      ///< builds per structure (median)
  int repeats = 3;     ///< timed passes (median)
  int verified = 500;  ///< queries per kind compared with brute force
  uint64_t seed = 1;
  std::string csv;      ///< also write the rows as CSV (atomically)
  std::string svg;      ///< also write a bar chart of the throughput as SVG (atomically)
  std::string caption;  ///< the machine and software, under the chart
};

/// The named scenes' rows, printed as they are measured: triangle scenes answer nearest,
/// within and overlap; knn runs on the scene's point sets, or on its vertices when it has none.
/// Returns 0, or 1 when an answer differed from brute force. Throws std::invalid_argument for
/// an unknown kind.
int run_queries(const std::vector<std::pair<std::string, Scene>>& scenes, const AccelConfig& config,
                const QueryBenchConfig& options);

/// Names --queries accepts.
const std::vector<std::string>& query_kinds();

}  // namespace penumbra::bench
