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

  /// The Hit ids (view, and triangle within it) of global triangle index `id`.
  void triangle_ids(uint32_t id, uint32_t& geom, uint32_t& prim) const {
    // The last view whose first triangle is <= id (views without triangles share a start and
    // come before the one holding it).
    geom = uint32_t(std::upper_bound(first.begin(), first.end(), id) - first.begin()) - 1;
    prim = id - first[geom];
  }

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
    triangle_ids(id, r.geom_id, r.prim_id);
    return r;
  }
};

/// Per-ray constants of the block filter: the watertight shear in SSE registers, the origin
/// and the axis permutation (block rows are picked by axis, so the permutation costs nothing).
struct BlockRay {
  __m128 org[3];
  __m128 sx, sy, sz, tnear;
  __m128d dorg[3];        ///< the origin in double, per axis (block_confirm)
  __m128d dsx, dsy, dsz;  ///< the shear in double (WatertightRay::dsx ...)
  double dtnear;
  int kx, ky, kz;
};

[[gnu::always_inline]] inline BlockRay prepare_block_ray(const Ray& ray, const WatertightRay& w) {
  BlockRay r;
  for (int k = 0; k < 3; ++k) {
    r.org[k] = _mm_set1_ps(component(ray.org, k));
    r.dorg[k] = _mm_set1_pd(component(ray.org, k));
  }
  r.sx = _mm_set1_ps(w.sx);
  r.sy = _mm_set1_ps(w.sy);
  r.sz = _mm_set1_ps(w.sz);
  r.tnear = _mm_set1_ps(w.tnear);
  r.dsx = _mm_set1_pd(w.dsx);
  r.dsy = _mm_set1_pd(w.dsy);
  r.dsz = _mm_set1_pd(w.dsz);
  r.dtnear = w.tnear;
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

/// The lanes of block_candidates (bit l for lane l).
struct BlockCandidates {
  int all = 0;       ///< the triangles the scalar test may accept; it certainly rejects the others
  int settled = 0;   ///< those of `all` block_confirm can finish: edge functions final (none 0,
                     ///< none NaN), distance bound clear of underflow
  int positive = 0;  ///< lanes whose edge functions are all positive (else all negative, if settled)
};

/// The triangle lanes of `b` that the scalar watertight test may accept with t in
/// [tnear, tfar]; of them, the ones block_confirm can finish (the scalar test recomputes edge
/// functions of exactly 0 in double, so those lanes, NaN ones and ones near underflow stay
/// with it).
[[gnu::always_inline]] inline BlockCandidates block_candidates(const TriangleBlock4& b, const BlockRay& r,
                                                               float tfar) {
  using namespace block_detail;
  BlockCandidates out;
  const int lanes = triangle_lanes(b);
  if (lanes == 0) return out;
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
  out.all = edge;
  if (inside == 0) return out;  // the common case: the ray passes beside all four
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
  // The scalar test's own distance early-out (half this bound) only ever rejects what its
  // double-precision t rejects too, so block_confirm can skip it; not near underflow, where
  // subnormal products carry absolute errors the bound does not cover: such lanes (and NaN
  // ones) stay with the scalar test.
  const __m128 nan = _mm_or_ps(_mm_cmpunord_ps(U, V), _mm_cmpunord_ps(W, W));
  const __m128 tiny = _mm_cmplt_ps(err, _mm_set1_ps(0x1p-100f));
  out.all = inside | edge;
  out.settled = inside & ~_mm_movemask_ps(_mm_or_ps(nan, tiny));
  out.positive = _mm_movemask_ps(_mm_cmpgt_ps(det, zero));
  return out;
}

/// The double-precision part of intersect_triangle_watertight (t, u, v from the vertices
/// relative to the origin, sheared in double, edge functions clamped to the float decision's
/// sign) for the `lanes` of `b`, two lanes per SSE2 register, in the scalar test's operation
/// order so each lane's results are bit-identical to it. `lanes` must be settled lanes of
/// block_candidates (`positive` its sign mask). Writes t, u = V/det, v = W/det of each lane;
/// returns the lanes with det != 0 and t in [tnear, tfar] (in double; the caller checks the
/// float t as the scalar test does).
struct BlockHits {
  alignas(16) double t[4], u[4], v[4];
};

[[gnu::always_inline]] inline int block_confirm(const TriangleBlock4& b, const BlockRay& r, int lanes,
                                                int positive, float tfar, BlockHits& out) {
  const __m128d zero = _mm_setzero_pd(), tnear = _mm_set1_pd(r.dtnear), tmax = _mm_set1_pd(tfar);
  int hits = 0;
  for (int h = 0; h < 2; ++h) {
    if (((lanes >> (2 * h)) & 3) == 0) continue;
    __m128d x[3], y[3], z[3];
    for (int i = 0; i < 3; ++i) {
      const auto row = [&](int axis) {
        __m128 f = _mm_load_ps(b.v[i][axis]);
        if (h) f = _mm_movehl_ps(f, f);
        return _mm_sub_pd(_mm_cvtps_pd(f), r.dorg[axis]);
      };
      const __m128d px = row(r.kx), py = row(r.ky);
      z[i] = row(r.kz);
      x[i] = _mm_sub_pd(px, _mm_mul_pd(r.dsx, z[i]));
      y[i] = _mm_sub_pd(py, _mm_mul_pd(r.dsy, z[i]));
    }
    __m128d U = _mm_sub_pd(_mm_mul_pd(x[2], y[1]), _mm_mul_pd(y[2], x[1]));
    __m128d V = _mm_sub_pd(_mm_mul_pd(x[0], y[2]), _mm_mul_pd(y[0], x[2]));
    __m128d W = _mm_sub_pd(_mm_mul_pd(x[1], y[0]), _mm_mul_pd(y[1], x[0]));
    // std::max(d, 0.0) is max_pd(0, d) and std::min(d, 0.0) is min_pd(0, d), NaN and -0 alike.
    const __m128d pos = _mm_castsi128_pd(
        _mm_set_epi64x(-int64_t((positive >> (2 * h + 1)) & 1), -int64_t((positive >> (2 * h)) & 1)));
    const auto clamp = [&](__m128d d) {
      return _mm_or_pd(_mm_and_pd(pos, _mm_max_pd(zero, d)), _mm_andnot_pd(pos, _mm_min_pd(zero, d)));
    };
    U = clamp(U), V = clamp(V), W = clamp(W);
    const __m128d det = _mm_add_pd(_mm_add_pd(U, V), W);
    const __m128d T = _mm_mul_pd(
        r.dsz, _mm_add_pd(_mm_add_pd(_mm_mul_pd(U, z[0]), _mm_mul_pd(V, z[1])), _mm_mul_pd(W, z[2])));
    const __m128d t = _mm_div_pd(T, det);
    _mm_store_pd(out.t + 2 * h, t);
    _mm_store_pd(out.u + 2 * h, _mm_div_pd(V, det));
    _mm_store_pd(out.v + 2 * h, _mm_div_pd(W, det));
    const __m128d ok =
        _mm_and_pd(_mm_cmpneq_pd(det, zero), _mm_and_pd(_mm_cmpge_pd(t, tnear), _mm_cmple_pd(t, tmax)));
    hits |= _mm_movemask_pd(ok) << (2 * h);
  }
  return hits & lanes;
}

}  // namespace penumbra
