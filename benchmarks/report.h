// What penumbra-bench reports per scene x structure x ray kind: the result row, the text table
// (SAH under the one set of constants of benchmarks/sah.h, "n/a" where a structure has none) and
// the bar chart of throughput and build time with their spreads and a caption naming the machine
// and the settings. Measuring is bench.cpp's; this only formats.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "benchmarks/chart.h"
#include "benchmarks/sah.h"

namespace penumbra::bench {

/// Throughput at one thread count: Mrays/s over the timed passes.
struct ThreadResult {
  int threads = 1;
  Spread mrays;
};

/// One table row: a structure on one scene's rays of one kind.
struct Row {
  std::string scene, accel, kind, config;
  uint64_t triangles = 0, shapes = 0, rays = 0, hits = 0, bytes = 0, mismatches = 0, ties = 0;
  double evals = -1;                ///< SDF evaluations per ray (sphere-tracing steps); -1: not counted
  Spread build_s;                   ///< build seconds over the builds
  std::optional<double> sah;        ///< SAH under kSahConstants (measure_structure_sah); nullopt: n/a
  double builder_sah = 0;           ///< AccelStats::sah_cost, the builder's own constants (0: none)
  std::vector<ThreadResult> mrays;  ///< one per thread count, in the run's order
  std::vector<double> vs_embree;    ///< median throughput over Embree's on the same rays, per thread count
};

/// The table's SAH cell: "n/a" without a value, else two decimals.
std::string format_sah(const std::optional<double>& sah);

/// The line printed once above the table: what the SAH column is and its constants.
std::string sah_legend(const SahConstants& c = kSahConstants);

/// The table's header line (with its newline) for these thread counts (each >= 1).
std::string table_header(std::span<const int> threads);

/// One row of the table (with its newline), aligned with table_header().
std::string table_row(const Row& r);

/// How the rows were measured, for the chart's caption.
struct RunSettings {
  int width = 0, height = 0;    ///< primary rays per row and column (one per pixel centre)
  int builds = 0, repeats = 0;  ///< builds per structure; timed passes per ray set
  int build_threads = 0;        ///< threads the builds ran on
  std::vector<int> threads;     ///< thread counts of the throughput panels (each >= 1)
  std::string machine;          ///< describe(read_machine_info())
  std::string software;         ///< versions, compiler and build type, one line
};

/// The bar chart of `rows`: one row of panels per scene, one panel per thread count (Mrays/s per
/// ray kind, one bar per structure) and one of build time (ms), each bar the median with its
/// min-max as an error bar, and a caption with the machine, the software, the settings and the
/// scenes.
BarChart results_chart(const std::vector<Row>& rows, const RunSettings& settings);

}  // namespace penumbra::bench
