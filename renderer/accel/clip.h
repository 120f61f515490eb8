// Pieces of the structures that reference a primitive from every cell it overlaps (kD-tree,
// octree): the bounds of the part of a primitive inside a box, and the per-ray mailbox that
// tests such a primitive once per ray.
#pragma once

#include <cstdint>

#include "renderer/accel/common.h"

namespace penumbra {

/// Bounds of the part of triangle t inside `box` (Sutherland-Hodgman clipping in double),
/// rounded outward to float and intersected with `box`; for a shape, its bounds intersected
/// with `box`. Empty if nothing is inside.
Bounds3f clip_primitive_bounds(const PrimitiveRecord& t, const Bounds3f& box);

/// The triangles a ray tested last (Amanatides & Woo 1987, "mailboxing"; a small per-ray ring
/// as in Havran's thesis, sec. 1.11): a triangle clipped into several leaves along the ray is
/// tested once. Skipping the repeat never changes an answer: the test depends only on the ray
/// and its far limit, which only shrinks, so a triangle that missed misses again and one that
/// hit is already the closest hit or behind it. Shapes are always tested.
struct Mailbox {
  static constexpr int kSize = 8;
  uint64_t keys[kSize] = {~0ull, ~0ull, ~0ull, ~0ull, ~0ull, ~0ull, ~0ull, ~0ull};
  int next = 0;
  /// True if `rec` was tested before; records it otherwise.
  bool seen(const PrimitiveRecord& rec) {
    if (is_shape(rec)) return false;
    const uint64_t key = (uint64_t(rec.geom_id) << 32) | rec.prim_id;
    for (const uint64_t k : keys)
      if (k == key) return true;
    keys[next] = key;
    next = (next + 1) & (kSize - 1);
    return false;
  }
};

}  // namespace penumbra
