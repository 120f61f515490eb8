// Shared pieces of the reference structures: gathering primitives into one packed array.
#include "renderer/accel/common.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <stdexcept>

namespace penumbra {

std::vector<PrimitiveRecord> gather_primitives(std::span<const GeometryView> views,
                                               std::vector<Shape>& shapes) {
  // Each view's records start at its offset; triangles are copied in parallel, then those with a
  // non-finite vertex (and shapes without finite bounds) are squeezed out, order kept.
  std::vector<size_t> offset(views.size() + 1, 0);
  for (size_t g = 0; g < views.size(); ++g)
    offset[g + 1] = offset[g] + (views[g].shape                       ? 1
                                 : views[g].curves != CurveKind::None ? views[g].curve_count()
                                                                      : views[g].indices.size() / 3);
  std::vector<PrimitiveRecord> records(offset.back());
  size_t table = shapes.size();  // the shape table's size when every shape and element is in
  for (const GeometryView& v : views) table += v.shape ? 1 : v.curve_count();
  shapes.reserve(table);
  std::vector<uint8_t> keep(records.size(), 1);
  auto add_shape = [&](size_t at, uint32_t g, const Shape& s) {
    const Bounds3f b = shape_bounds(s);
    if (b.empty() || !is_finite(b.lo) || !is_finite(b.hi)) {
      keep[at] = 0;
      return;
    }
    records[at] = {b.lo, b.hi, Vec3f{}, g, kShapeBit | uint32_t(shapes.size())};
    shapes.push_back(s);
  };
  for (uint32_t g = 0; g < views.size(); ++g) {
    const auto& m = views[g];
    if (m.shape) {
      add_shape(offset[g], g, *m.shape);
      continue;
    }
    if (m.curves != CurveKind::None) {
      if (m.radii.size() < m.positions.size()) {  // no radii: nothing to hit
        std::fill(keep.begin() + ptrdiff_t(offset[g]), keep.begin() + ptrdiff_t(offset[g + 1]), 0);
        continue;
      }
      if (shapes.size() + m.curve_count() >= kShapeBit)
        throw std::invalid_argument("more than 2^31 - 1 shapes");
      for (size_t i = 0; i < m.curve_count(); ++i) add_shape(offset[g] + i, g, curve_element(m, i));
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
