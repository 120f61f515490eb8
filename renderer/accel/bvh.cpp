// Penumbra's reference BVH: the binned-SAH build of accel/bvh_build.cpp, flattened into binary
// nodes (width 2, the scalar reference) or collapsed into 4-wide (SSE) or 8-wide (AVX2) nodes
// whose leaves are blocks of four triangles tested at once (accel/bvh_wide.h). The collapse
// opens the child of largest surface area first (Wald, Benthin & Boulos, "Getting Rid of
// Packets", IEEE RT 2008). The width is chosen at run time from the CPU unless configured.
#include "renderer/accel/bvh.h"

#include <immintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/accel/bvh_build.h"
#include "renderer/accel/bvh_wide.h"
#include "renderer/accel/common.h"
#include "renderer/accel/stats.h"

namespace penumbra {

namespace wide4 {
#define PENUMBRA_BVH_WIDTH 4
#include "renderer/accel/bvh_traverse.inl"
#undef PENUMBRA_BVH_WIDTH
}  // namespace wide4

// The 8-wide code for AVX2: GCC's target pragma, clang's attribute pragma (clang ignores GCC's).
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace wide8 {
#define PENUMBRA_BVH_WIDTH 8
#include "renderer/accel/bvh_traverse.inl"
#undef PENUMBRA_BVH_WIDTH
}  // namespace wide8
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

bool cpu_has_avx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}

void set_child_boxes(Node4& node, const Bounds3f* boxes, int n) {
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) {
      node.lo[k][i] = i < n ? boxes[i].lo[k] : kInfinity;
      node.hi[k][i] = i < n ? boxes[i].hi[k] : -kInfinity;
    }
}

void set_child_boxes(QuantizedNode8& node, const Bounds3f* boxes, int n) {
  Bounds3f all;
  for (int i = 0; i < n; ++i) all = merge(all, boxes[i]);
  node.valid = uint8_t((1u << n) - 1);
  for (int k = 0; k < 3; ++k) {
    // The step: the extent over 255 steps, grown until the last step reaches the top.
    node.origin[k] = all.lo[k];
    // At least FLT_MIN (no subnormal steps, which growing by a relative factor could not move).
    float step = std::max((all.hi[k] - all.lo[k]) / 255.0f, std::numeric_limits<float>::min());
    if (!std::isfinite(step)) step = std::numeric_limits<float>::max() / 256;  // grown to inf below
    node.scale[k] = step;
    while (node.dequantize(k, 255) < all.hi[k])
      node.scale[k] = step = std::max(step * (1 + 0x1p-10f), std::nextafter(step, kInfinity));
    for (int i = 0; i < 8; ++i) {
      if (i >= n) {
        node.qlo[k][i] = 255, node.qhi[k][i] = 0;
        continue;
      }
      // Round outward, then step further out until the decoded bound contains the box.
      // Clamped in float before the conversion (a non-finite quotient has no int value).
      const auto level = [](float q) { return int(std::clamp(q, 0.0f, 255.0f)); };
      int lo = level(std::floor((boxes[i].lo[k] - all.lo[k]) / step));
      int hi = level(std::ceil((boxes[i].hi[k] - all.lo[k]) / step));
      while (lo > 0 && node.dequantize(k, uint8_t(lo)) > boxes[i].lo[k]) --lo;
      while (hi < 255 && node.dequantize(k, uint8_t(hi)) < boxes[i].hi[k]) ++hi;
      node.qlo[k][i] = uint8_t(lo);
      node.qhi[k][i] = uint8_t(hi);
    }
  }
}

namespace {

/// The width a build uses: the configured one, or for 0 the widest this CPU runs.
int effective_width(const BvhConfig& c) {
  if (c.width != 0) return c.width;
  return cpu_has_avx2() ? 8 : 4;
}

/// Global triangle numbering of the views (PrimitiveIds::first): view g's triangles start at
/// first[g]. Throws if the triangles do not fit the 31 bits a block lane's id has for them.
std::vector<uint32_t> first_triangles(std::span<const GeometryView> views) {
  std::vector<uint32_t> first(views.size() + 1, 0);
  uint64_t n = 0;
  for (size_t g = 0; g < views.size(); ++g) {
    first[g] = uint32_t(n);
    if (!views[g].shape && views[g].curves == CurveKind::None) n += views[g].indices.size() / 3;
    if (n >= kShapeBit) throw std::invalid_argument("bvh: more than 2^31 - 1 triangles");
  }
  first[views.size()] = uint32_t(n);
  return first;
}

class BvhAccelerator final : public TraversalAccelerator<BvhAccelerator> {
  friend class TraversalAccelerator<BvhAccelerator>;

 public:
  BvhAccelerator(std::span<const GeometryView> meshes, const BvhConfig& config)
      : m_config(config), m_width(effective_width(config)) {
    validate(config);
    if (m_width == 8 && !cpu_has_avx2()) throw std::invalid_argument("bvh: width 8 needs a CPU with AVX2");
    const BuildTimer timer;
    std::vector<PrimitiveRecord> tris = gather_primitives(meshes, m_shapes);
    m_input_triangles = count_input_triangles(meshes);
    if (m_width != 2) {
      m_ids.first = first_triangles(meshes);
      m_ids.shape_geom.resize(m_shapes.size());
      for (const PrimitiveRecord& r : tris)
        if (is_shape(r)) m_ids.shape_geom[r.prim_id & ~kShapeBit] = r.geom_id;
    }
    m_view_prims.reserve(meshes.size());
    for (const GeometryView& v : meshes)
      m_view_prims.push_back(v.shape ? kShapeBit : uint32_t(v.indices.size() / 3));
    m_complete = tris.size() == m_input_triangles + count_input_shapes(meshes);
    if (!tris.empty()) build(std::move(tris));
    m_build_seconds = timer.seconds();
  }

  /// Keeps the tree and its leaves' order; copies the views' new primitives into the leaves and
  /// recomputes every box bottom-up (a primitive cut by spatial splits gets its whole box in each
  /// leaf that holds it, which still contains its parts) and the SAH statistics.
  bool refit(std::span<const GeometryView> views) override {
    if (!m_complete || views.size() != m_view_prims.size()) return false;
    for (const GeometryView& v : views)  // records are one per view or per triangle
      if (v.curves != CurveKind::None) return false;
    std::vector<uint32_t> start(views.size());  // index of view g's first record
    uint32_t n = 0;
    for (size_t g = 0; g < views.size(); ++g) {
      const uint32_t prims = views[g].shape ? kShapeBit : uint32_t(views[g].indices.size() / 3);
      if (prims != m_view_prims[g]) return false;
      start[g] = n;
      n += views[g].shape ? 1 : prims;
    }
    std::vector<Shape> shapes;
    const std::vector<PrimitiveRecord> fresh = gather_primitives(views, shapes);
    if (fresh.size() != n) return false;  // a primitive without finite bounds now
    const auto record = [&](uint32_t geom, uint32_t prim) -> const PrimitiveRecord& {
      return fresh[start[geom] + ((prim & kShapeBit) ? 0 : prim)];
    };
    m_shapes = std::move(shapes);
    m_stats.sah_cost = m_stats.sah_node_area = m_stats.sah_leaf_area = 0;
    if (m_width == 2) {
      for (PrimitiveRecord& r : m_tris) r = record(r.geom_id, r.prim_id);
      refit_binary();
    } else if (m_width == 4) {
      m_bounds = refit_wide(m_wide4, record);
    } else {
      m_bounds = refit_wide(m_wide8, record);
    }
    return true;
  }

  /// The region walk of the configured layout (walk_region in accel/bvh_wide.h): nodes and
  /// leaves whose widened (binary, 4-wide) or decoded (8-wide) boxes meet the region, a ball's
  /// nearest first; each primitive of a leaf reached is offered with its Hit ids.
  void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const override {
    if (m_width == 8) return visit_region_wide(m_wide8, region, visitor, cost);
    if (m_width == 4) return visit_region_wide(m_wide4, region, visitor, cost);
    walk_region_binary(m_nodes, region, cost, [&](uint32_t first, uint32_t count) {
      for (uint32_t i = first, e = first + count; i < e; ++i) {
        const PrimitiveRecord& r = m_tris[i];
        visitor.visit(r.geom_id, record_prim_id(r, m_shapes.data()), region);
      }
    });
  }

  Bounds3f bounds() const override { return m_bounds; }

  AccelStats stats() const override {
    const uint64_t bytes = m_nodes.size() * sizeof(BvhNode) + m_tris.size() * sizeof(PrimitiveRecord) +
                           m_wide4.nodes.size() * sizeof(Node4) +
                           m_wide8.nodes.size() * sizeof(QuantizedNode8) +
                           (m_wide4.blocks.size() + m_wide8.blocks.size()) * sizeof(TriangleBlock4) +
                           (m_ids.first.size() + m_ids.shape_geom.size()) * sizeof(uint32_t);
    AccelStats s = make_stats(m_stats, "bvh",
                              "width " + std::to_string(m_width) + ", max_leaf_size " +
                                  std::to_string(m_config.max_leaf_size) + ", bin_count " +
                                  std::to_string(m_config.bin_count) + ", traversal_cost " +
                                  format_number(m_config.traversal_cost) + ", intersection_cost " +
                                  format_number(m_config.intersection_cost) + spatial_description(),
                              m_input_triangles, bytes, m_build_seconds);
    const uint64_t interior = m_width == 4 ? m_wide4.nodes.size() : m_wide8.nodes.size();
    s.nodes = m_width == 2 ? m_nodes.size() : interior + m_tally.leaves;
    s.shapes = m_shapes.size();
    return s;
  }

 private:
  /// The spatial-split settings and the references they made, when they are on.
  std::string spatial_description() const {
    if (!(m_config.spatial_alpha > 0)) return "";
    return ", spatial_alpha " + format_number(m_config.spatial_alpha) + ", spatial_budget " +
           format_number(m_config.spatial_budget) + " (" + std::to_string(m_references) + " references)";
  }

  void build(std::vector<PrimitiveRecord> tris) {
    std::vector<BvhBuildRef> refs(tris.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tris.size(), 1 << 14),
                      [&](const tbb::blocked_range<size_t>& rg) {
                        for (size_t i = rg.begin(); i < rg.end(); ++i)
                          refs[i] = {primitive_bounds(tris[i]), uint32_t(i)};
                      });
    const ReferenceClipper clip = [&](const BvhBuildRef& ref, int axis, float pos, Bounds3f& l, Bounds3f& r) {
      const PrimitiveRecord& t = tris[ref.index];
      if (is_shape(t)) return split_box_bounds(ref.box(), axis, pos, l, r);
      const Vec3f v[3] = {t.a, t.b, t.c};
      split_triangle_bounds(v, ref.box(), axis, pos, l, r);
    };
    auto root = build_bvh_tree(refs, m_config, m_width == 2 ? 1 : 4, &clip);
    m_references = refs.size();
    m_bounds = root->box;
    m_sah_root_area = surface_area(root->box);
    // Leaf ranges index `refs`, whose order is the leaves' order.
    if (m_width == 2) {
      m_tris.resize(refs.size());
      for (size_t i = 0; i < refs.size(); ++i) m_tris[i] = tris[refs[i].index];
      flatten_bvh(*root, m_nodes);
      compute_stats(*root, 0);
    } else if (m_width == 4) {
      collapse_tree(m_wide4, tris, refs, *root);
    } else {
      collapse_tree(m_wide8, tris, refs, *root);
    }
    release_bvh_tree(std::move(root));
    m_tally.fill(m_stats);
  }

  /// The traversal of the configured layout. `visit(w, record)` returns true to stop (any-hit);
  /// closest-hit visitors narrow `best`. Returns true iff a visitor stopped it.
  template <typename Visit, typename Counter, bool AnyHit>
  bool traverse(const Ray& ray, const float& best, Visit&& visit, const Counter& counter,
                std::bool_constant<AnyHit>) const {
    if (m_width == 8) return wide8::traverse<AnyHit>(m_wide8, m_ids, ray, best, visit, counter);
    if (m_width == 4) return wide4::traverse<AnyHit>(m_wide4, m_ids, ray, best, visit, counter);
    return traverse2(ray, best, visit, counter);
  }

  /// Binary traversal: depth first, nearer child first (by the sign of the ray direction along
  /// the node's split axis), culling boxes beyond `best`.
  template <typename Visit, typename Counter>
  bool traverse2(const Ray& ray, const float& best, Visit& visit, const Counter& counter) const {
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid) return false;
    return walk_bvh(
        m_nodes, prepare_box_query(ray), w.tnear, best, [&] { counter.node(); },
        [&](uint32_t first, uint32_t count) {
          for (uint32_t i = first, e = first + count; i < e; ++i)
            if (visit(w, m_tris[i])) return true;
          return false;
        });
  }

  /// visit_region over a wide layout: leaves sit on the stack like nodes (as in the ray
  /// traversal), each child's box taken from its parent's slot.
  template <int W>
  void visit_region_wide(const WideBvh<W>& bvh, QueryRegion& region, RegionVisitor& visitor,
                         TraversalCost* cost) const {
    if (bvh.nodes.empty()) return;
    const auto expand = [&](const RegionEntry& e, RegionEntry* kids, Bounds3f* boxes) {
      if (e.count > 0) {
        visit_region_blocks(bvh.blocks, e.index, e.count, region, visitor);
        return 0;
      }
      const WideNode<W>& node = bvh.nodes[e.index];
      for (int i = 0; i < W; ++i) {
        kids[i] = {node.child[i], node.count[i], 0};
        boxes[i] = child_box(node, i);  // empty for an unused slot, which is then dropped
      }
      return W;
    };
    walk_region<W>(region, cost, RegionEntry{}, expand);
  }

  /// Offers the primitives of blocks [first, first + count) to `visitor`, with their Hit ids
  /// (prim_id 0 for a shape).
  void visit_region_blocks(const BlockArray& blocks, uint32_t first, uint32_t count, QueryRegion& region,
                           RegionVisitor& visitor) const {
    for (uint32_t k = first, e = first + count; k < e; ++k)
      for (int l = 0; l < 4; ++l) {
        if (blocks[k].id[l] == kEmptyLane) continue;
        const PrimitiveRecord r = m_ids.record(blocks[k], l);
        visitor.visit(r.geom_id, record_prim_id(r, m_shapes.data()), region);
      }
  }

  /// Writes the blocks of leaf `b` from `out` (the records tris[refs[i].index] for i in [first,
  /// first + count), four per block, the last one padded with empty lanes).
  void write_leaf_blocks(TriangleBlock4* out, const std::vector<PrimitiveRecord>& tris,
                         const std::vector<BvhBuildRef>& refs, const BvhBuildNode& b) const {
    for (uint32_t i = 0; i < b.count; i += 4) {
      TriangleBlock4 blk{};
      for (uint32_t l = 0; l < 4; ++l) {
        if (i + l >= b.count) {
          blk.id[l] = kEmptyLane;
          continue;
        }
        const size_t at = b.first + i + l;
        // The records are read in leaf order, scattered over the array: fetch ahead.
        if (at + kGatherAhead < refs.size()) {
          const char* ahead = reinterpret_cast<const char*>(&tris[refs[at + kGatherAhead].index]);
          _mm_prefetch(ahead, _MM_HINT_T0);
          _mm_prefetch(ahead + sizeof(PrimitiveRecord) - 1, _MM_HINT_T0);
        }
        const PrimitiveRecord& r = tris[refs[at].index];
        if (is_shape(r)) {
          blk.id[l] = r.prim_id;
          continue;
        }
        const Vec3f v[3] = {r.a, r.b, r.c};
        for (int k = 0; k < 3; ++k)
          for (int a = 0; a < 3; ++a) blk.v[k][a][l] = v[k][a];
        blk.id[l] = m_ids.global(r.geom_id, r.prim_id);
      }
      *out++ = blk;
    }
  }

  static constexpr size_t kGatherAhead = 16;  // records fetched ahead by write_leaf_blocks

  /// Blocks of the leaves below `b`.
  static uint32_t leaf_blocks(const BvhBuildNode& b) {
    if (!b.child[0]) return (b.count + 3) / 4;
    return leaf_blocks(*b.child[0]) + leaf_blocks(*b.child[1]);
  }

  /// The statistics collapse() gathers (depth, SAH cost, leaves) for a part of the tree;
  /// parts are merged in a fixed order, so the totals never depend on scheduling.
  struct CollapseTally {
    uint64_t max_depth = 0;
    double sah_cost = 0, sah_node_area = 0, sah_leaf_area = 0;
    LeafTally leaves;
    void merge(const CollapseTally& o) {
      max_depth = std::max(max_depth, o.max_depth);
      sah_cost += o.sah_cost, sah_node_area += o.sah_node_area, sah_leaf_area += o.sah_leaf_area;
      leaves.leaves += o.leaves.leaves, leaves.empty_leaves += o.leaves.empty_leaves;
      leaves.references += o.leaves.references;
      leaves.max_prims = std::max(leaves.max_prims, o.leaves.max_prims);
    }
  };

  /// A subtree collapsed on its own: its root's wide node goes to slot `slot` of the tree and
  /// the others to `nodes` (local indices, node 0 its root) until appended; its blocks to the
  /// range from `block` reserved for it.
  template <int W>
  struct CollapseJob {
    const BvhBuildNode* node = nullptr;
    uint32_t slot = 0, block = 0;
    uint64_t depth = 0;
    std::vector<WideNode<W>> nodes;
    CollapseTally tally;
  };

  /// Where collapse() writes: the node array of the tree or of a job, the block array (sized
  /// beforehand) and its cursor, the statistics, and the jobs interior children at wide depth
  /// `defer_depth` become (none when `jobs` is null).
  template <int W>
  struct CollapseSink {
    std::vector<WideNode<W>>& nodes;
    TriangleBlock4* blocks;
    uint32_t block;
    CollapseTally& tally;
    std::vector<CollapseJob<W>>* jobs;
    uint64_t defer_depth;
  };

  /// Collapses the binary tree into `bvh`: the top wide levels serially, and for trees of at
  /// least 16 x parallel_threshold references the subtrees below them (kCollapseJobDepth) as
  /// parallel jobs, whose nodes are then appended in a fixed order. Blocks are in depth-first
  /// leaf order either way, each job's range reserved in advance.
  template <int W>
  void collapse_tree(WideBvh<W>& bvh, const std::vector<PrimitiveRecord>& tris,
                     const std::vector<BvhBuildRef>& refs, const BvhBuildNode& root) {
    constexpr uint64_t kCollapseJobDepth = 2;  // up to W^2 jobs
    bvh.blocks.resize(leaf_blocks(root));
    bvh.nodes.emplace_back();
    std::vector<CollapseJob<W>> jobs;
    CollapseTally top;
    const bool parallel = refs.size() / 16 >= m_config.parallel_threshold;  // no overflow for any threshold
    CollapseSink<W> sink{bvh.nodes, bvh.blocks.data(), 0, top, parallel ? &jobs : nullptr, kCollapseJobDepth};
    collapse(sink, tris, refs, root, 0, 0);
    tbb::parallel_for(size_t(0), jobs.size(), [&](size_t j) {
      CollapseJob<W>& job = jobs[j];
      job.nodes.emplace_back();
      CollapseSink<W> js{job.nodes, bvh.blocks.data(), job.block, job.tally, nullptr, 0};
      collapse(js, tris, refs, *job.node, job.depth, 0);
    });
    for (CollapseJob<W>& job : jobs) {
      const uint32_t offset = uint32_t(bvh.nodes.size()) - 1;  // local index i >= 1 goes to offset + i
      for (WideNode<W>& n : job.nodes)
        for (int i = 0; i < W; ++i)
          if (n.count[i] == 0 && n.child[i] != UINT32_MAX) n.child[i] += offset;
      bvh.nodes[job.slot] = job.nodes[0];
      bvh.nodes.insert(bvh.nodes.end(), job.nodes.begin() + 1, job.nodes.end());
      top.merge(job.tally);
    }
    m_stats.max_depth = top.max_depth;
    m_stats.sah_cost = top.sah_cost;
    m_stats.sah_node_area = top.sah_node_area;
    m_stats.sah_leaf_area = top.sah_leaf_area;
    m_tally = top.leaves;
  }

  /// Emits the W-wide node for interior binary node `b` into node `idx` of the sink: its
  /// children, with the interior child of largest surface area replaced by its two children
  /// until there are W (or only leaves) (Wald, Benthin & Boulos 2008). Fills the statistics as
  /// it goes (leaves, depth, SAH cost of the wide tree). A node's interior children are stored
  /// next to each other (one block per parent), so siblings share pages and the hardware
  /// prefetcher's adjacent lines.
  template <int W>
  void collapse(CollapseSink<W>& sink, const std::vector<PrimitiveRecord>& tris,
                const std::vector<BvhBuildRef>& refs, const BvhBuildNode& b, uint64_t depth, uint32_t idx) {
    CollapseTally& tally = sink.tally;
    tally.max_depth = std::max(tally.max_depth, depth);
    const double rel = m_sah_root_area > 0 ? surface_area(b.box) / m_sah_root_area : 1.0;
    tally.sah_cost += rel * m_config.traversal_cost;
    tally.sah_node_area += rel;
    const BvhBuildNode* kids[W];
    int n = 0;
    if (!b.child[0]) {
      kids[n++] = &b;  // the root is a leaf: one slot
    } else {
      kids[n++] = b.child[0].get();
      kids[n++] = b.child[1].get();
    }
    while (n < W) {
      int open = -1;
      float area = -1;
      for (int i = 0; i < n; ++i)
        if (kids[i]->child[0] && surface_area(kids[i]->box) > area) {
          area = surface_area(kids[i]->box);
          open = i;
        }
      if (open < 0) break;
      const BvhBuildNode* o = kids[open];
      kids[open] = o->child[0].get();
      kids[n++] = o->child[1].get();
    }
    uint32_t child[W] = {};
    uint8_t count[W] = {};
    uint32_t next = uint32_t(sink.nodes.size());  // the block of this node's interior children
    for (int i = 0; i < n; ++i)
      if (kids[i]->child[0]) child[i] = next++;
    sink.nodes.resize(next);
    for (int i = 0; i < n; ++i) {
      if (kids[i]->child[0]) {
        if (sink.jobs && depth + 1 >= sink.defer_depth) {
          sink.jobs->push_back({kids[i], child[i], sink.block, depth + 1, {}, {}});
          sink.block += leaf_blocks(*kids[i]);
          continue;
        }
        collapse(sink, tris, refs, *kids[i], depth + 1, child[i]);
        continue;
      }
      child[i] = sink.block;
      write_leaf_blocks(sink.blocks + sink.block, tris, refs, *kids[i]);
      count[i] = uint8_t((kids[i]->count + 3) / 4);
      sink.block += count[i];
      tally.leaves.add(kids[i]->count);
      tally.max_depth = std::max(tally.max_depth, depth + 1);
      const double lrel = m_sah_root_area > 0 ? surface_area(kids[i]->box) / m_sah_root_area : 1.0;
      tally.sah_cost += lrel * m_config.intersection_cost * count[i];
      tally.sah_leaf_area += lrel * kids[i]->count;
    }
    WideNode<W>& node = sink.nodes[idx];  // after the recursion: resize may have moved it
    Bounds3f boxes[W];
    for (int i = 0; i < n; ++i) boxes[i] = widen_for_rounding(kids[i]->box);
    set_child_boxes(node, boxes, n);
    for (int i = 0; i < W; ++i) {
      node.child[i] = i < n ? child[i] : UINT32_MAX;  // never followed: the slot is unused
      node.count[i] = count[i];
    }
  }

  /// Refits the binary nodes: children follow their parent in depth-first order, so one
  /// backward pass sees every child before its parent. Then recomputes the SAH statistics.
  void refit_binary() {
    if (m_nodes.empty()) return;
    std::vector<Bounds3f> exact(m_nodes.size());
    for (size_t i = m_nodes.size(); i-- > 0;) {
      const BvhNode& node = m_nodes[i];
      Bounds3f b;
      if (node.count == 0) {
        b = merge(exact[i + 1], exact[node.offset]);
      } else {
        for (uint32_t k = node.offset, e = node.offset + node.count; k < e; ++k)
          b = merge(b, primitive_bounds(m_tris[k]));
      }
      exact[i] = b;
      const Bounds3f w = widen_for_rounding(b);
      m_nodes[i].lo = w.lo;
      m_nodes[i].hi = w.hi;
    }
    m_bounds = exact[0];
    m_sah_root_area = surface_area(m_bounds);
    for (size_t i = 0; i < m_nodes.size(); ++i) {
      const double rel = m_sah_root_area > 0 ? surface_area(exact[i]) / m_sah_root_area : 1.0;
      const uint32_t count = m_nodes[i].count;
      add_sah(rel, count == 0, count, count);
    }
  }

  /// Adds one node to the SAH statistics: an interior node, or a leaf of `prims` primitives
  /// charged `units` intersection costs (blocks in the wide layouts).
  void add_sah(double rel, bool interior, uint32_t prims, uint32_t units) {
    if (interior) {
      m_stats.sah_cost += rel * m_config.traversal_cost;
      m_stats.sah_node_area += rel;
      return;
    }
    m_stats.sah_cost += rel * m_config.intersection_cost * units;
    m_stats.sah_leaf_area += rel * prims;
  }

  /// One node of a refitted tree for the SAH statistics: its exact area, and for a leaf its
  /// primitives and blocks.
  struct RefitNode {
    double area = 0;
    bool interior = true;
    uint32_t prims = 0, blocks = 0;
  };

  /// Refits the wide tree: blocks rewritten from `record(geom, prim)`, child boxes recomputed
  /// from the leaves up, and the SAH statistics as collapse() counts them. Returns the exact
  /// bounds of the tree.
  template <int W, typename Record>
  Bounds3f refit_wide(WideBvh<W>& bvh, const Record& record) {
    if (bvh.nodes.empty()) return {};
    std::vector<RefitNode> sah;
    const Bounds3f root = refit_wide_node(bvh, record, 0, sah);
    m_sah_root_area = surface_area(root);
    for (const RefitNode& r : sah)
      add_sah(m_sah_root_area > 0 ? r.area / m_sah_root_area : 1.0, r.interior, r.prims, r.blocks);
    return root;
  }

  /// Refits wide node `idx` and its subtree; returns its exact bounds.
  template <int W, typename Record>
  Bounds3f refit_wide_node(WideBvh<W>& bvh, const Record& record, uint32_t idx, std::vector<RefitNode>& sah) {
    Bounds3f boxes[W];
    int n = 0;
    for (; n < W && slot_used(bvh.nodes[idx], n); ++n) {
      const uint32_t child = bvh.nodes[idx].child[n], blocks = bvh.nodes[idx].count[n];
      if (blocks == 0) {
        boxes[n] = refit_wide_node(bvh, record, child, sah);
        continue;
      }
      RefitNode leaf{0, false, 0, blocks};
      for (uint32_t k = child; k < child + blocks; ++k) {
        TriangleBlock4& blk = bvh.blocks[k];
        for (int l = 0; l < 4; ++l) {
          if (blk.id[l] == kEmptyLane) continue;
          ++leaf.prims;
          if (blk.id[l] & kShapeBit) {
            boxes[n] = merge(boxes[n], shape_bounds(m_shapes[blk.id[l] & ~kShapeBit]));
            continue;
          }
          const PrimitiveRecord old = m_ids.record(blk, l);
          const PrimitiveRecord& r = record(old.geom_id, old.prim_id);
          const Vec3f v[3] = {r.a, r.b, r.c};
          for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a) blk.v[c][a][l] = v[c][a];
          boxes[n] = merge(boxes[n], primitive_bounds(r));
        }
      }
      leaf.area = surface_area(boxes[n]);
      sah.push_back(leaf);
    }
    Bounds3f all, widened[W];
    for (int i = 0; i < n; ++i) {
      all = merge(all, boxes[i]);
      widened[i] = widen_for_rounding(boxes[i]);
    }
    set_child_boxes(bvh.nodes[idx], widened, n);  // children and counts stay
    sah.push_back({surface_area(all), true, 0, 0});
    return all;
  }

  static bool slot_used(const Node4& node, int i) { return node.lo[0][i] <= node.hi[0][i]; }
  static bool slot_used(const QuantizedNode8& node, int i) { return (node.valid >> i) & 1; }

  void compute_stats(const BvhBuildNode& b, uint64_t depth) {
    m_stats.max_depth = std::max(m_stats.max_depth, depth);
    const double rel = m_sah_root_area > 0 ? surface_area(b.box) / m_sah_root_area : 1.0;
    if (!b.child[0]) {
      m_tally.add(b.count);
      m_stats.sah_cost += rel * m_config.intersection_cost * b.count;
      m_stats.sah_leaf_area += rel * b.count;
      return;
    }
    m_stats.sah_cost += rel * m_config.traversal_cost;
    m_stats.sah_node_area += rel;
    compute_stats(*b.child[0], depth + 1);
    compute_stats(*b.child[1], depth + 1);
  }

  BvhConfig m_config;
  int m_width;                          // 2, 4 or 8: the layout built
  std::vector<BvhNode> m_nodes;         // width 2: depth-first; node 0 is the root; boxes widened
  std::vector<PrimitiveRecord> m_tris;  // width 2: reordered so leaves are contiguous
  WideBvh<4> m_wide4;                   // width 4; boxes widened
  WideBvh<8> m_wide8;                   // width 8; boxes widened
  PrimitiveIds m_ids;                   // widths 4 and 8: block lane ids to hit ids
  Bounds3f m_bounds;                    // exact bounds of the primitives
  uint64_t m_input_triangles = 0;
  uint64_t m_references = 0;  // leaf entries: the primitives plus the spatial splits' duplicates
  double m_sah_root_area = 0;
  LeafTally m_tally;
  AccelStats m_stats;
  double m_build_seconds = 0;
  std::vector<uint32_t> m_view_prims;  // per view: its triangle count, or kShapeBit for a shape
  bool m_complete = false;             // the build kept every primitive (none non-finite)
};

}  // namespace

void validate(const BvhConfig& c) {
  if (c.max_leaf_size < 1 || c.max_leaf_size > 255)
    throw std::invalid_argument("bvh: max_leaf_size must be in [1, 255], got " +
                                std::to_string(c.max_leaf_size));
  if (c.bin_count < 2 || c.bin_count > 256)
    throw std::invalid_argument("bvh: bin_count must be in [2, 256], got " + std::to_string(c.bin_count));
  if (c.width != 0 && c.width != 2 && c.width != 4 && c.width != 8)
    throw std::invalid_argument("bvh: width must be 0 (the CPU's widest), 2, 4 or 8, got " +
                                std::to_string(c.width));
  if (!(c.traversal_cost > 0) || !(c.intersection_cost > 0))
    throw std::invalid_argument("bvh: traversal_cost and intersection_cost must be > 0");
  if (!(c.spatial_alpha >= 0 && c.spatial_alpha <= 1))
    throw std::invalid_argument("bvh: spatial_alpha must be in [0, 1], got " +
                                format_number(c.spatial_alpha));
  if (!(c.spatial_budget >= 0 && c.spatial_budget <= 4))
    throw std::invalid_argument("bvh: spatial_budget must be in [0, 4], got " +
                                format_number(c.spatial_budget));
  if (!(c.refit_max_growth == 0 || (c.refit_max_growth >= 1 && c.refit_max_growth <= 1000)))
    throw std::invalid_argument("bvh: refit_max_growth must be 0 or in [1, 1000], got " +
                                format_number(c.refit_max_growth));
}

std::unique_ptr<Accelerator> make_bvh_accelerator(std::span<const GeometryView> meshes,
                                                  const BvhConfig& config) {
  return std::make_unique<BvhAccelerator>(meshes, config);
}

}  // namespace penumbra
