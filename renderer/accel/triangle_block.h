// Leaf storage of the wide BVH: four primitives in one structure-of-arrays block, and the SSE
// filter that runs the float part of the watertight test (Woop, Benthin & Wald, JCGT 2013) on
// all four triangles at once. The filter only discards: a lane it keeps is handed to the one
// scalar test of triangle.h, so every hit, t, u and v equals what brute force reports.
#pragma once

// The filter repeats intersect_triangle_watertight's float operations in the same order (no
// fused multiply-add: the project compiles with -ffp-contract=off), so its sign decisions are
// the scalar test's. Lanes with an edge function of exactly 0 (where the scalar test falls back
// to double) are always kept, and the distance early-out uses twice the scalar error bound, so
// no triangle the scalar test accepts is discarded.

#include <emmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "renderer/accel/common.h"
#include "renderer/accel/triangle.h"

namespace penumbra {

/// Four primitives of a leaf, 160 bytes. Lane l is a triangle with vertices
/// (v[0][*][l], v[1][*][l], v[2][*][l]) when id[l] has no kShapeBit; a shape (id[l] =
/// kShapeBit | shape table index, vertices 0) otherwise; or empty (id[l] == kEmptyLane).
/// A triangle's id is its global index: the triangles of the views before its own, plus its
/// index in its mesh (see PrimitiveIds).
struct alignas(16) TriangleBlock4 {
  float v[3][3][4];  // 144 bytes: v[vertex][axis][lane]
  uint32_t id[4];    //  16 bytes
};
static_assert(sizeof(TriangleBlock4) == 160);

inline constexpr uint32_t kEmptyLane = 0xffffffffu;

/// Lanes holding triangles (bit l for lane l).
inline int triangle_lanes(const TriangleBlock4& b) {
  const __m128i id = _mm_load_si128(reinterpret_cast<const __m128i*>(b.id));
  return ~_mm_movemask_ps(_mm_castsi128_ps(id)) & 0xf;  // kShapeBit is the sign bit
}

/// Lanes holding shapes: a sign bit (kShapeBit) that is not an empty lane's.
inline int shape_lanes(const TriangleBlock4& b) {
  const __m128i id = _mm_load_si128(reinterpret_cast<const __m128i*>(b.id));
  const int flagged = _mm_movemask_ps(_mm_castsi128_ps(id));
  if (flagged == 0) return 0;
  const __m128i empty = _mm_cmpeq_epi32(id, _mm_set1_epi32(int(kEmptyLane)));
  return flagged & ~_mm_movemask_ps(_mm_castsi128_ps(empty));
}

/// Maps a block lane's id back to the ids a Hit reports: the view (geom_id) and the triangle
/// within it (prim_id), or for a shape its view and kShapeBit | its table index.
struct PrimitiveIds {
  std::vector<uint32_t> first;       ///< first[g]: global index of view g's first triangle; size views + 1
  std::vector<uint32_t> shape_geom;  ///< view of each shape in the shape table

  /// Global index of triangle `prim` of view `geom`.
  uint32_t global(uint32_t geom, uint32_t prim) const { return first[geom] + prim; }

  /// The record a leaf visitor sees for lane l of `b` (a shape's vertices are unused).
  PrimitiveRecord record(const TriangleBlock4& b, int l) const {
    PrimitiveRecord r;
    r.a = {b.v[0][0][l], b.v[0][1][l], b.v[0][2][l]};
    r.b = {b.v[1][0][l], b.v[1][1][l], b.v[1][2][l]};
    r.c = {b.v[2][0][l], b.v[2][1][l], b.v[2][2][l]};
    const uint32_t id = b.id[l];
    if (id & kShapeBit) {
      r.geom_id = shape_geom[id & ~kShapeBit];
      r.prim_id = id;
      return r;
    }
    // The last view whose first triangle is <= id (views without triangles share a start and
    // come before the one holding it).
    const uint32_t lo = uint32_t(std::upper_bound(first.begin(), first.end(), id) - first.begin()) - 1;
    r.geom_id = lo;
    r.prim_id = id - first[lo];
    return r;
  }
};

/// Per-ray constants of the block filter: the watertight shear in SSE registers, the origin
/// and the axis permutation (block rows are picked by axis, so the permutation costs nothing).
struct BlockRay {
  __m128 org[3];
  __m128 sx, sy, sz, tnear;
  int kx, ky, kz;
};

[[gnu::always_inline]] inline BlockRay prepare_block_ray(const Ray& ray, const WatertightRay& w) {
  BlockRay r;
  r.org[0] = _mm_set1_ps(ray.org.x);
  r.org[1] = _mm_set1_ps(ray.org.y);
  r.org[2] = _mm_set1_ps(ray.org.z);
  r.sx = _mm_set1_ps(w.sx);
  r.sy = _mm_set1_ps(w.sy);
  r.sz = _mm_set1_ps(w.sz);
  r.tnear = _mm_set1_ps(w.tnear);
  r.kx = w.kx, r.ky = w.ky, r.kz = w.kz;
  return r;
}

namespace block_detail {
inline __m128 abs4(__m128 x) {
  return _mm_and_ps(x, _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff)));
}
inline __m128 load_row(const TriangleBlock4& b, int vertex, int axis) {
  return _mm_load_ps(b.v[vertex][axis]);
}
}  // namespace block_detail

/// The triangle lanes of `b` that the scalar watertight test may accept with t in
/// [tnear, tfar] (bit l for lane l); the others it certainly rejects.
[[gnu::always_inline]] inline int block_candidates(const TriangleBlock4& b, const BlockRay& r, float tfar) {
  using namespace block_detail;
  const int lanes = triangle_lanes(b);
  if (lanes == 0) return 0;
  // Vertices minus the origin, per permuted axis, and sheared: x - s_x z, y - s_y z.
  __m128 vx[3], vy[3], vz[3], sxv[3], syv[3];
  for (int i = 0; i < 3; ++i) {
    vx[i] = _mm_sub_ps(load_row(b, i, r.kx), r.org[r.kx]);
    vy[i] = _mm_sub_ps(load_row(b, i, r.ky), r.org[r.ky]);
    vz[i] = _mm_sub_ps(load_row(b, i, r.kz), r.org[r.kz]);
    sxv[i] = _mm_sub_ps(vx[i], _mm_mul_ps(r.sx, vz[i]));
    syv[i] = _mm_sub_ps(vy[i], _mm_mul_ps(r.sy, vz[i]));
  }
  // Edge functions: U = Cx By - Cy Bx, V = Ax Cy - Ay Cx, W = Bx Ay - By Ax.
  const __m128 U = _mm_sub_ps(_mm_mul_ps(sxv[2], syv[1]), _mm_mul_ps(syv[2], sxv[1]));
  const __m128 V = _mm_sub_ps(_mm_mul_ps(sxv[0], syv[2]), _mm_mul_ps(syv[0], sxv[2]));
  const __m128 W = _mm_sub_ps(_mm_mul_ps(sxv[1], syv[0]), _mm_mul_ps(syv[1], sxv[0]));
  const __m128 zero = _mm_setzero_ps();
  const __m128 on_edge =
      _mm_or_ps(_mm_cmpeq_ps(U, zero), _mm_or_ps(_mm_cmpeq_ps(V, zero), _mm_cmpeq_ps(W, zero)));
  const __m128 any_neg =
      _mm_or_ps(_mm_cmplt_ps(U, zero), _mm_or_ps(_mm_cmplt_ps(V, zero), _mm_cmplt_ps(W, zero)));
  const __m128 any_pos =
      _mm_or_ps(_mm_cmpgt_ps(U, zero), _mm_or_ps(_mm_cmpgt_ps(V, zero), _mm_cmpgt_ps(W, zero)));
  const __m128 det = _mm_add_ps(_mm_add_ps(U, V), W);
  __m128 keep = _mm_andnot_ps(_mm_and_ps(any_neg, any_pos), _mm_cmpneq_ps(det, zero));
  const int edge = _mm_movemask_ps(on_edge) & lanes;
  int inside = _mm_movemask_ps(keep) & lanes & ~edge;
  if (inside == 0) return edge;  // the common case: the ray passes beside all four
  // Distance early-out with twice the scalar bound; lanes with a NaN bound are kept.
  __m128 m = zero, s = zero, z = zero, zz[3];
  for (int i = 0; i < 3; ++i) {
    zz[i] = _mm_mul_ps(r.sz, vz[i]);
    m = _mm_max_ps(m, _mm_max_ps(abs4(vx[i]), _mm_max_ps(abs4(vy[i]), abs4(vz[i]))));
    s = _mm_max_ps(s, _mm_max_ps(abs4(sxv[i]), abs4(syv[i])));
    z = _mm_max_ps(z, abs4(zz[i]));
  }
  const __m128 T = _mm_add_ps(_mm_add_ps(_mm_mul_ps(U, zz[0]), _mm_mul_ps(V, zz[1])), _mm_mul_ps(W, zz[2]));
  const __m128 err = _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(_mm_set1_ps(2e-4f), m), s), z);
  const __m128 lo = _mm_div_ps(_mm_sub_ps(T, err), det), hi = _mm_div_ps(_mm_add_ps(T, err), det);
  const __m128 far_end = _mm_max_ps(lo, hi), near_end = _mm_min_ps(lo, hi);
  const __m128 outside = _mm_or_ps(_mm_cmplt_ps(far_end, r.tnear), _mm_cmpgt_ps(near_end, _mm_set1_ps(tfar)));
  const __m128 ordered = _mm_cmpord_ps(lo, hi);
  inside &= ~_mm_movemask_ps(_mm_and_ps(outside, ordered));
  return inside | edge;
}

}  // namespace penumbra
