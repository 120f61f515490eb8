// Traversal of a wide BVH (accel/bvh_wide.h) for one SIMD width. This file has no include
// guard on purpose: accel/bvh.cpp includes it twice, once with PENUMBRA_BVH_WIDTH 4 in namespace
// wide4 (SSE, every x86-64 CPU) and once with PENUMBRA_BVH_WIDTH 8 in namespace wide8 under
// `#pragma GCC target("avx2")` (with clang, an attribute pragma giving every function that
// target), so the 8-wide code is compiled for AVX2 and called only when cpu_has_avx2() says so.
// Everything here is a template or inline and local to that namespace.
//
// Closest hit: the W child boxes are slab-tested at once; the children met are pushed far to
// near with their entry distance, and entries beyond `best` are skipped when popped. Leaves sit
// on the stack like nodes, so blocks are tested front to back. The box test is the slab test
// (common.h) in SIMD, the entry and exit distances scaled outward by kSlabPad; on an axis the
// ray is parallel to, NaN distances drop out of the max and min (see BoxRay).
// Occlusion (AnyHit): the leaves met are tested at once, before any node is pushed, and nothing
// is sorted: the first hit ends the query, wherever it is.

#if PENUMBRA_BVH_WIDTH == 8
constexpr int kWidth = 8;
using Vf = __m256;
inline Vf vset(float x) {
  return _mm256_set1_ps(x);
}
inline Vf vload(const float* p) {
  return _mm256_load_ps(p);
}
inline Vf vsub(Vf a, Vf b) {
  return _mm256_sub_ps(a, b);
}
inline Vf vadd(Vf a, Vf b) {
  return _mm256_add_ps(a, b);
}
inline Vf vmul(Vf a, Vf b) {
  return _mm256_mul_ps(a, b);
}
inline Vf vmin(Vf a, Vf b) {
  return _mm256_min_ps(a, b);
}
inline Vf vmax(Vf a, Vf b) {
  return _mm256_max_ps(a, b);
}
inline int vle_mask(Vf a, Vf b) {
  return _mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LE_OQ));
}
inline void vstore(float* p, Vf a) {
  _mm256_store_ps(p, a);
}
/// Byte offset within a node of the children's lower (hi = false) or upper planes on axis k.
inline uint32_t plane_offset(int k, bool hi) {
  return uint32_t(hi ? offsetof(QuantizedNode8, qhi) : offsetof(QuantizedNode8, qlo)) + 8 * uint32_t(k);
}
/// The planes of the eight children at byte offset `off` (plane_offset) on axis k, decoded as
/// QuantizedNode8::dequantize does (the same float operations).
inline Vf load_planes(const QuantizedNode8& n, int k, uint32_t off) {
  const __m128i bytes =
      _mm_loadl_epi64(reinterpret_cast<const __m128i*>(reinterpret_cast<const char*>(&n) + off));
  return _mm256_add_ps(
      _mm256_set1_ps(n.origin[k]),
      _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(bytes)), _mm256_set1_ps(n.scale[k])));
}
inline int valid_mask(const QuantizedNode8& n) {
  return n.valid;
}
#else
constexpr int kWidth = 4;
using Vf = __m128;
inline Vf vset(float x) {
  return _mm_set1_ps(x);
}
inline Vf vload(const float* p) {
  return _mm_load_ps(p);
}
inline Vf vsub(Vf a, Vf b) {
  return _mm_sub_ps(a, b);
}
inline Vf vadd(Vf a, Vf b) {
  return _mm_add_ps(a, b);
}
inline Vf vmul(Vf a, Vf b) {
  return _mm_mul_ps(a, b);
}
inline Vf vmin(Vf a, Vf b) {
  return _mm_min_ps(a, b);
}
inline Vf vmax(Vf a, Vf b) {
  return _mm_max_ps(a, b);
}
inline int vle_mask(Vf a, Vf b) {
  return _mm_movemask_ps(_mm_cmple_ps(a, b));
}
inline void vstore(float* p, Vf a) {
  _mm_store_ps(p, a);
}
/// Byte offset within a node of the children's lower (hi = false) or upper planes on axis k.
inline uint32_t plane_offset(int k, bool hi) {
  return uint32_t(hi ? offsetof(Node4, hi) : offsetof(Node4, lo)) + 16 * uint32_t(k);
}
/// The planes of the four children at byte offset `off` (plane_offset) on axis k.
inline Vf load_planes(const Node4& n, int, uint32_t off) {
  return vload(reinterpret_cast<const float*>(reinterpret_cast<const char*>(&n) + off));
}
inline int valid_mask(const Node4&) {
  return 0xf;
}
#endif

using Node = WideNode<kWidth>;

/// Per-ray constants of the box test, broadcast to all lanes. On an axis the ray is parallel to
/// (1/d infinite) the distances are +-inf, or NaN (0 * inf) where the origin lies exactly on a
/// plane: the max and min of hit_children take a NaN as their first operand and then return the
/// second (MAXPS/MINPS return the second operand when one is NaN), so such a plane drops out,
/// which is the slab test's answer for an origin inside the slab, faces included.
struct BoxRay {
  Vf org[3], inv[3];
  Vf down, up, tnear;
  uint32_t near_off[3], far_off[3];  ///< plane_offset of the near and far planes, by the octant
};

[[gnu::always_inline]] inline BoxRay prepare(const RayBoxQuery& q, float tnear) {
  BoxRay r;
  for (int k = 0; k < 3; ++k) {
    r.org[k] = vset(q.org[k]);
    r.inv[k] = vset(q.inv_dir[k]);
    // Near is the lower plane where the direction is positive (by the sign, not min/max, so an
    // unused slot's inverted box gives an empty interval).
    r.near_off[k] = plane_offset(k, q.dir_neg[k]);
    r.far_off[k] = plane_offset(k, !q.dir_neg[k]);
  }
  r.down = vset(2.0f - kSlabPad);
  r.up = vset(kSlabPad);
  r.tnear = vset(tnear);
  return r;
}

/// The children of `n` the ray meets within [tnear, best] (bit i for child i); their entry
/// distances in `t_entry`.
[[gnu::always_inline]] inline int hit_children(const Node& n, const BoxRay& r, float best, float* t_entry) {
  // The entry distance is the largest of the three near-plane distances and the exit the
  // smallest far one. Each distance carries a relative rounding error (a difference, then a
  // product), so scaling the entry down and the exit up by kSlabPad covers it whatever their
  // signs: a negative entry moved towards 0 still lies below tnear >= 0, and a negative exit
  // stays negative (behind the ray) as the exact one is.
  Vf tn = vset(-kInfinity), tf = vset(kInfinity);
  for (int k = 0; k < 3; ++k) {
    const Vf near_plane = load_planes(n, k, r.near_off[k]), far_plane = load_planes(n, k, r.far_off[k]);
    const Vf a = vmul(vsub(near_plane, r.org[k]), r.inv[k]);
    const Vf b = vmul(vsub(far_plane, r.org[k]), r.inv[k]);
    tn = vmax(a, tn);  // a NaN `a` leaves tn (see BoxRay)
    tf = vmin(b, tf);
  }
  const Vf t0 = vmax(vmul(tn, r.down), r.tnear), t1 = vmin(vmul(tf, r.up), vset(best));
  vstore(t_entry, t0);
  return vle_mask(t0, t1) & valid_mask(n);
}

inline void prefetch_node(const Node* p) {
  const char* c = reinterpret_cast<const char*>(p);
  for (size_t off = 0; off < sizeof(Node); off += 64) _mm_prefetch(c + off, _MM_HINT_T0);
}

inline void prefetch_blocks(const TriangleBlock4* p, uint32_t count) {
  const char* c = reinterpret_cast<const char*>(p);
  const char* end = c + count * sizeof(TriangleBlock4);
  for (; c < end; c += 64) _mm_prefetch(c, _MM_HINT_T0);
}

/// Tests the `count` blocks from `first`: the SIMD filter on each block, then on every lane it
/// keeps either the double-precision confirm of the whole block (block_confirm, for visitors
/// without a hit filter) or `visit`, and `visit` on every shape. Lanes are taken in order and a
/// closest hit narrows `best` lane by lane, as the scalar test on each lane would. Returns true
/// iff the query ends here (any hit). Lanes the filter discards are counted here as triangle
/// tests; the visitor counts its own.
template <bool AnyHit, typename Visit, typename Counter>
inline bool visit_leaf(const WideBvh<kWidth>& bvh, const PrimitiveIds& ids, uint32_t first, uint32_t count,
                       const BlockRay& br, const WatertightRay& w, const float& best, Visit& visit,
                       const Counter& counter) {
  for (uint32_t i = first, end = first + count; i < end; ++i) {
    const TriangleBlock4& b = bvh.blocks[i];
    const BlockCandidates cand = block_candidates(b, br, best);
    counter.triangles(
        uint32_t(__builtin_popcount(unsigned(triangle_lanes(b))) - __builtin_popcount(unsigned(cand.all))));
    if constexpr (Visit::kUnfiltered) {
      BlockHits h;
      const int hits = cand.settled ? block_confirm(b, br, cand.settled, cand.positive, best, h) : 0;
      for (int m = cand.all; m; m &= m - 1) {
        const int l = __builtin_ctz(unsigned(m));
        if (!((cand.settled >> l) & 1)) {
          if (visit(w, ids.record(b, l))) return true;
          continue;
        }
        visit.counted();
        // The scalar test's range checks against the current `best`: t in double, then in float.
        if (!((hits >> l) & 1) || !(h.t[l] <= best)) continue;
        const float t = float(h.t[l]);
        if (!(t >= w.tnear && t <= best)) continue;
        if constexpr (AnyHit) return true;
        Hit hit{t, float(h.u[l]), float(h.v[l]), 0, 0};
        ids.triangle_ids(b.id[l], hit.geom_id, hit.prim_id);
        visit.take(hit);
      }
    } else {
      for (int m = cand.all; m; m &= m - 1)
        if (visit(w, ids.record(b, __builtin_ctz(unsigned(m))))) return true;
    }
    for (int m = shape_lanes(b); m; m &= m - 1)
      if (visit(w, ids.record(b, __builtin_ctz(unsigned(m))))) return true;
  }
  return false;
}

/// The traversal (see the top of this file). `visit(w, record)` returns true to stop (any-hit);
/// closest-hit visitors narrow `best`. Returns true iff a visitor stopped it. Never allocates.
template <bool AnyHit, typename Visit, typename Counter>
bool traverse(const WideBvh<kWidth>& bvh, const PrimitiveIds& ids, const Ray& ray, const float& best,
              Visit& visit, const Counter& counter) {
  const WatertightRay w = prepare_watertight(ray);
  if (!w.valid || bvh.nodes.empty()) return false;
  const BlockRay br = prepare_block_ray(ray, w);
  const BoxRay r = prepare(prepare_box_query(ray), w.tnear);
  struct Entry {
    uint32_t child, count;
    float t;
  };
  Entry stack[kWideStackSize<kWidth>];
  int sp = 0;
  stack[sp++] = {0, 0, w.tnear};
  alignas(32) float tn[kWidth];
  while (sp > 0) {
    const Entry e = stack[--sp];
    if (e.t > best) continue;
    counter.node();
    if (e.count > 0) {
      if (visit_leaf<AnyHit>(bvh, ids, e.child, e.count, br, w, best, visit, counter)) return true;
      continue;
    }
    const Node& n = bvh.nodes[e.child];
    int mask = hit_children(n, r, best, tn);
    if (mask == 0) continue;
    if constexpr (AnyHit) {
      for (int m = mask; m; m &= m - 1) {
        const int c = __builtin_ctz(unsigned(m));
        if (n.count[c] == 0) {
          stack[sp++] = {n.child[c], 0, w.tnear};
          prefetch_node(&bvh.nodes[n.child[c]]);
          continue;
        }
        counter.node();
        if (visit_leaf<AnyHit>(bvh, ids, n.child[c], n.count[c], br, w, best, visit, counter)) return true;
      }
      continue;
    }
    // One child met: it is the next entry, without a trip through the stack (the common case
    // for incoherent rays, and its sort and stack stores would cost branch misses).
    const int c0 = __builtin_ctz(unsigned(mask));
    mask &= mask - 1;
    if (mask == 0) {
      stack[sp++] = {n.child[c0], n.count[c0], tn[c0]};
      continue;
    }
    // Two or more: sorted far to near (insertion sort), then pushed; the next pops' nodes and
    // blocks are prefetched (traversal waits on memory on big scenes).
    int order[kWidth], k = 1;
    order[0] = c0;
    for (; mask; mask &= mask - 1) {
      const int c = __builtin_ctz(unsigned(mask));
      int j = k++;
      while (j > 0 && tn[order[j - 1]] < tn[c]) {
        order[j] = order[j - 1];
        --j;
      }
      order[j] = c;
    }
    for (int j = 0; j < k; ++j) {
      const int c = order[j];
      stack[sp++] = {n.child[c], n.count[c], tn[c]};
      if (j == k - 1) break;  // popped next: fetched then
      if (n.count[c] == 0)
        prefetch_node(&bvh.nodes[n.child[c]]);
      else
        prefetch_blocks(&bvh.blocks[n.child[c]], n.count[c]);
    }
  }
  return false;
}
