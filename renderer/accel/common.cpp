// Shared pieces of the reference structures: gathering primitives into one packed array.
#include "renderer/accel/common.h"

namespace penumbra {

std::vector<PrimitiveRecord> gather_primitives(std::span<const GeometryView> views,
                                               std::vector<Shape>& shapes) {
  size_t n = 0;
  for (const auto& m : views) n += m.shape ? 1 : m.indices.size() / 3;
  std::vector<PrimitiveRecord> records;
  records.reserve(n);
  for (uint32_t g = 0; g < views.size(); ++g) {
    const auto& m = views[g];
    if (m.shape) {
      const Bounds3f b = shape_bounds(*m.shape);
      if (b.empty() || !is_finite(b.lo) || !is_finite(b.hi)) continue;
      records.push_back({b.lo, b.hi, Vec3f{}, g, kShapeBit | uint32_t(shapes.size())});
      shapes.push_back(*m.shape);
      continue;
    }
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
      PrimitiveRecord t{m.positions[m.indices[i]], m.positions[m.indices[i + 1]],
                        m.positions[m.indices[i + 2]], g, uint32_t(i / 3)};
      if (is_finite(t.a) && is_finite(t.b) && is_finite(t.c)) records.push_back(t);
    }
  }
  return records;
}

}  // namespace penumbra
