// Shared pieces of the reference structures: gathering primitives into one packed array.
#include "renderer/accel/common.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace penumbra {

std::vector<PrimitiveRecord> gather_primitives(std::span<const GeometryView> views,
                                               std::vector<Shape>& shapes) {
  // Each view's records start at its offset; triangles are copied in parallel, then those with a
  // non-finite vertex (and shapes without finite bounds) are squeezed out, order kept.
  std::vector<size_t> offset(views.size() + 1, 0);
  for (size_t g = 0; g < views.size(); ++g)
    offset[g + 1] = offset[g] + (views[g].shape ? 1 : views[g].indices.size() / 3);
  std::vector<PrimitiveRecord> records(offset.back());
  std::vector<uint8_t> keep(records.size(), 1);
  for (uint32_t g = 0; g < views.size(); ++g) {
    const auto& m = views[g];
    if (m.shape) {
      const Bounds3f b = shape_bounds(*m.shape);
      if (b.empty() || !is_finite(b.lo) || !is_finite(b.hi)) {
        keep[offset[g]] = 0;
        continue;
      }
      records[offset[g]] = {b.lo, b.hi, Vec3f{}, g, kShapeBit | uint32_t(shapes.size())};
      shapes.push_back(*m.shape);
      continue;
    }
    const size_t n = offset[g + 1] - offset[g];
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        PrimitiveRecord t{m.positions[m.indices[3 * i]], m.positions[m.indices[3 * i + 1]],
                          m.positions[m.indices[3 * i + 2]], g, uint32_t(i)};
        records[offset[g] + i] = t;
        keep[offset[g] + i] = is_finite(t.a) && is_finite(t.b) && is_finite(t.c);
      }
    });
  }
  size_t out = 0;
  for (size_t i = 0; i < records.size(); ++i)
    if (keep[i]) records[out++] = records[i];
  records.resize(out);
  return records;
}

}  // namespace penumbra
