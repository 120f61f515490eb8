// Traversal of a wide BVH (accel/bvh_wide.h) for one SIMD width. This file has no include
// guard on purpose: accel/bvh.cpp includes it twice, once with PENUMBRA_BVH_WIDTH 4 in namespace
// wide4 (SSE, every x86-64 CPU) and once with PENUMBRA_BVH_WIDTH 8 in namespace wide8 under
// `#pragma GCC target("avx2")`, so the 8-wide code is compiled for AVX2 and called only when
// cpu_has_avx2() says so. Everything here is a template or inline and local to that namespace.
//
// Closest hit: the W child boxes are slab-tested at once; the children met are pushed far to
// near with their entry distance, and entries beyond `best` are skipped when popped. Leaves sit
// on the stack like nodes, so blocks are tested front to back. The box test is the scalar one's
// (common.h) in SIMD, distances padded outward by kSlabPad. On an axis the ray is parallel to
// (1/d infinite) the distances are +-inf, or NaN (0 * inf) when the origin lies exactly on a
// face: such a lane is inside the slab, faces included, so NaN lanes become [-inf, inf].
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
inline Vf vand(Vf a, Vf b) {
  return _mm256_and_ps(a, b);
}
inline Vf vor(Vf a, Vf b) {
  return _mm256_or_ps(a, b);
}
inline Vf vandnot(Vf a, Vf b) {
  return _mm256_andnot_ps(a, b);
}
inline Vf vunord(Vf a, Vf b) {
  return _mm256_cmp_ps(a, b, _CMP_UNORD_Q);
}
inline int vle_mask(Vf a, Vf b) {
  return _mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LE_OQ));
}
inline void vstore(float* p, Vf a) {
  _mm256_store_ps(p, a);
}
inline Vf vabs_mask() {
  return _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
}
/// The near and far planes of the eight children on axis k, decoded as
/// QuantizedNode8::dequantize does (the same float operations).
inline void load_planes(const QuantizedNode8& n, int k, bool neg, Vf& near_plane, Vf& far_plane) {
  const Vf origin = _mm256_set1_ps(n.origin[k]), scale = _mm256_set1_ps(n.scale[k]);
  const auto decode = [&](const uint8_t* q) {
    const __m128i bytes = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(q));
    return _mm256_add_ps(origin, _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(bytes)), scale));
  };
  const Vf lo = decode(n.qlo[k]), hi = decode(n.qhi[k]);
  near_plane = neg ? hi : lo;
  far_plane = neg ? lo : hi;
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
inline Vf vand(Vf a, Vf b) {
  return _mm_and_ps(a, b);
}
inline Vf vor(Vf a, Vf b) {
  return _mm_or_ps(a, b);
}
inline Vf vandnot(Vf a, Vf b) {
  return _mm_andnot_ps(a, b);
}
inline Vf vunord(Vf a, Vf b) {
  return _mm_cmpunord_ps(a, b);
}
inline int vle_mask(Vf a, Vf b) {
  return _mm_movemask_ps(_mm_cmple_ps(a, b));
}
inline void vstore(float* p, Vf a) {
  _mm_store_ps(p, a);
}
inline Vf vabs_mask() {
  return _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
}
/// The near and far planes of the four children on axis k (by the direction's sign, not
/// min/max, so an unused slot's inverted box gives an empty interval).
inline void load_planes(const Node4& n, int k, bool neg, Vf& near_plane, Vf& far_plane) {
  near_plane = vload(neg ? n.hi[k] : n.lo[k]);
  far_plane = vload(neg ? n.lo[k] : n.hi[k]);
}
inline int valid_mask(const Node4&) {
  return 0xf;
}
#endif

using Node = WideNode<kWidth>;

/// Per-ray constants of the box test, broadcast to all lanes.
struct BoxRay {
  Vf org[3], inv[3];
  Vf pad, abs_mask, tnear, neg_inf, pos_inf, max_float;
  bool parallel[3];
  int dir_neg[3];
};

inline BoxRay prepare(const RayBoxQuery& q, float tnear) {
  BoxRay r;
  for (int k = 0; k < 3; ++k) {
    r.org[k] = vset(q.org[k]);
    r.inv[k] = vset(q.inv_dir[k]);
    r.parallel[k] = std::isinf(q.inv_dir[k]);
    r.dir_neg[k] = q.dir_neg[k];
  }
  r.pad = vset(kSlabPad - 1.0f);
  r.abs_mask = vabs_mask();
  r.tnear = vset(tnear);
  r.neg_inf = vset(-kInfinity);
  r.pos_inf = vset(kInfinity);
  r.max_float = vset(std::numeric_limits<float>::max());
  return r;
}

/// The children of `n` the ray meets within [tnear, best] (bit i for child i); their entry
/// distances in `t_entry`.
[[gnu::always_inline]] inline int hit_children(const Node& n, const BoxRay& r, float best, float* t_entry) {
  // The entry distance is the largest of the three near-plane distances and the exit the
  // smallest far one; the padding is monotonic, so it is applied once, after max and min.
  Vf tn = vset(-kInfinity), tf = vset(kInfinity);
  for (int k = 0; k < 3; ++k) {
    Vf near_plane, far_plane;
    load_planes(n, k, r.dir_neg[k], near_plane, far_plane);
    Vf a = vmul(vsub(near_plane, r.org[k]), r.inv[k]);
    Vf b = vmul(vsub(far_plane, r.org[k]), r.inv[k]);
    if (r.parallel[k]) {
      const Vf on_face = vunord(a, b);
      a = vor(vandnot(on_face, a), vand(on_face, r.neg_inf));
      b = vor(vandnot(on_face, b), vand(on_face, r.pos_inf));
    }
    tn = vmax(a, tn);
    tf = vmin(b, tf);
  }
  // The pad is capped at FLT_MAX so an infinite distance stays infinite (inf - inf would be
  // NaN, and an unused slot's box would then count as met).
  tn = vsub(tn, vmin(vmul(vand(tn, r.abs_mask), r.pad), r.max_float));
  tf = vadd(tf, vmin(vmul(vand(tf, r.abs_mask), r.pad), r.max_float));
  const Vf t0 = vmax(tn, r.tnear), t1 = vmin(tf, vset(best));
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

/// Tests the `count` blocks from `first`: the SIMD filter on each block, then `visit` on every
/// lane it keeps and on every shape. Returns true iff a visitor stopped the query. Lanes the
/// filter discards are counted here as triangle tests; the visitor counts its own.
template <typename Visit, typename Counter>
inline bool visit_leaf(const WideBvh<kWidth>& bvh, const PrimitiveIds& ids, uint32_t first, uint32_t count,
                       const BlockRay& br, const WatertightRay& w, const float& best, Visit& visit,
                       const Counter& counter) {
  for (uint32_t i = first, end = first + count; i < end; ++i) {
    const TriangleBlock4& b = bvh.blocks[i];
    const int cand = block_candidates(b, br, best);
    counter.triangles(
        uint32_t(__builtin_popcount(unsigned(triangle_lanes(b))) - __builtin_popcount(unsigned(cand))));
    for (int m = cand; m; m &= m - 1)
      if (visit(w, ids.record(b, __builtin_ctz(unsigned(m))))) return true;
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
      if (visit_leaf(bvh, ids, e.child, e.count, br, w, best, visit, counter)) return true;
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
        if (visit_leaf(bvh, ids, n.child[c], n.count[c], br, w, best, visit, counter)) return true;
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
