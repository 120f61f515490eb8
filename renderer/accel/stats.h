// Build statistics shared by every back end: the build timer, the leaf-size tally and the one
// function that completes an AccelStats with the fields every stats() reports alike (name,
// parameters, input triangles, bytes, build time).
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// Wall-clock time since construction, for AccelStats::build_seconds.
struct BuildTimer {
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
};

/// A number as printf's %g would print it (for the human-readable AccelStats::config).
inline std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// Summary of a leaf-size histogram, filled by each structure's statistics pass.
struct LeafTally {
  uint64_t leaves = 0, empty_leaves = 0, references = 0, max_prims = 0;
  void add(uint64_t n) {
    ++leaves;
    empty_leaves += n == 0;
    references += n;
    max_prims = std::max(max_prims, n);
  }
  void fill(AccelStats& s) const {
    s.leaves = leaves;
    s.empty_leaves = empty_leaves;
    s.references = references;
    s.max_leaf_prims = max_prims;
    s.avg_leaf_prims = leaves > empty_leaves ? double(references) / double(leaves - empty_leaves) : 0;
  }
};

/// `tree` (the statistics a build gathered: nodes, leaves, depth, SAH cost) completed with
/// the back end's name, its parameters, the triangles it was given, the bytes it holds and
/// its build time.
inline AccelStats make_stats(AccelStats tree, std::string name, std::string config, uint64_t triangles,
                             uint64_t bytes, double build_seconds) {
  tree.name = std::move(name);
  tree.config = std::move(config);
  tree.triangles = triangles;
  tree.bytes = bytes;
  tree.build_seconds = build_seconds;
  return tree;
}

}  // namespace penumbra
