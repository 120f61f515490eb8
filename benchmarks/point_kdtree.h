// nanoflann's kD-tree (Blanco and Rai, "nanoflann: a C++ header-only fork of FLANN", 2014) over
// a vector of points: the reference the k-nearest-points queries are compared with, in the
// benchmark and the tests. PENUMBRA_HAVE_NANOFLANN is defined when Debian's libnanoflann-dev is
// installed.
#pragma once

#if __has_include(<nanoflann.hpp>)
#include <nanoflann.hpp>
#include <vector>

#include "renderer/core/math.h"

#define PENUMBRA_HAVE_NANOFLANN 1

namespace penumbra::bench {

/// nanoflann's dataset interface over `pts` (which must outlive the tree).
struct PointAdaptor {
  const std::vector<Vec3f>& pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  float kdtree_get_pt(size_t i, size_t d) const { return d == 0 ? pts[i].x : d == 1 ? pts[i].y : pts[i].z; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};

/// The tree: squared Euclidean distances in float, uint32_t indices. Its constructor builds it.
using PointTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointAdaptor>,
                                                      PointAdaptor, 3, uint32_t>;

}  // namespace penumbra::bench
#endif
