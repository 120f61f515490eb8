// Mapping a query region through an instance's affine map conservatively: how much the map can
// stretch a length, and how much rounding a mapped point can carry. Shared by the back ends that
// carry region queries into object space (the two-level wrapper, Embree's instances).
#pragma once

#include <algorithm>
#include <cmath>

#include "renderer/core/math.h"

namespace penumbra {

/// An upper bound on the square of the most that `a`'s linear part L stretches a length (its
/// largest singular value): the largest row sum of |L^T L| (Gershgorin's bound on the largest
/// eigenvalue), in double; tight for a rotation with a uniform scale.
inline double stretch2(const Affine3f& a) {
  double bound = 0;
  for (int i = 0; i < 3; ++i) {
    double row = 0;
    for (int j = 0; j < 3; ++j) {
      double g = 0;
      for (int k = 0; k < 3; ++k) g += double(a.m[k][i]) * double(a.m[k][j]);
      row += std::fabs(g);
    }
    bound = std::max(bound, row);
  }
  return bound;
}

/// An allowance for the rounding of points mapped by an affine map (the float map, and the
/// float inverse it was rounded from): `per_unit` times the point's largest coordinate plus
/// `offset`, a share of the magnitudes of the terms.
struct MapRounding {
  double per_unit = 0, offset = 0;
  double at(double magnitude) const { return per_unit * magnitude + offset; }
};

inline MapRounding map_rounding(const Affine3f& a) {
  MapRounding r;
  for (const auto& row : a.m) {
    const double linear = std::fabs(double(row[0])) + std::fabs(double(row[1])) + std::fabs(double(row[2]));
    r.per_unit = std::max(r.per_unit, 4e-6 * linear);
    r.offset = std::max(r.offset, 4e-6 * std::fabs(double(row[3])));
  }
  return r;
}

}  // namespace penumbra
