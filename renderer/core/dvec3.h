// A point or vector in double precision and its arithmetic, for geometry that single precision
// would round too coarsely (polytopes, the raster preview's stand-ins).
#pragma once

#include <cmath>

#include "renderer/core/math.h"

namespace penumbra {

/// A point or vector in double precision. Trivially constructible (uninitialised by default, so
/// that scratch arrays of points cost nothing): write DVec3{} for zero.
struct DVec3 {
  double x, y, z;
};

inline DVec3 operator+(DVec3 a, DVec3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline DVec3 operator-(DVec3 a, DVec3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline DVec3 operator*(DVec3 a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
inline double dot(DVec3 a, DVec3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline double length(DVec3 a) {
  return std::sqrt(dot(a, a));
}

inline DVec3 cross(DVec3 a, DVec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline DVec3 to_dvec(Vec3f v) {
  return {v.x, v.y, v.z};
}

}  // namespace penumbra
