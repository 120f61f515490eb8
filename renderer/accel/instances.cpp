// Two-level instancing: top-level BVH over instance boxes, object-space bottom levels.
#include "renderer/accel/instances.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/accel/bvh_build.h"
#include "renderer/accel/bvh_wide.h"
#include "renderer/accel/common.h"
#include "renderer/accel/deforming.h"
#include "renderer/accel/region_map.h"
#include "renderer/accel/stats.h"

namespace penumbra {
namespace {

class TwoLevelAccelerator final : public Accelerator {
 public:
  TwoLevelAccelerator(const AcceleratorBuilder& build, std::span<const GeometryView> meshes,
                      std::span<const InstanceView> instances, const DeformingConfig& deforming) {
    validate_instances(instances, meshes.size());
    const BuildTimer timer;
    std::vector<GeometryView> world, deforming_world;
    std::vector<int> object_of(meshes.size(), -1), shape_of(meshes.size(), -1);
    for (size_t i = 0; i < instances.size(); ++i) {
      const InstanceView& inst = instances[i];
      m_layout.add(inst);
      const InstanceKind kind = m_layout.kinds.back();
      const bool deforms = meshes[inst.mesh].deforms();
      if (kind == InstanceKind::Identity) {
        // In world space: the back end's world level, or the deforming meshes' own.
        (deforms ? deforming_world : world).push_back(meshes[inst.mesh]);
        (deforms ? m_deforming_ids : m_world_ids).push_back(uint32_t(i));
        continue;
      }
      if (kind == InstanceKind::Singular) continue;  // never hit
      Affine3f to_object;
      inverse(inst.to_world, to_object);
      const uint32_t motion = inst.motion.empty() ? kStill : uint32_t(m_motion.size());
      if (!inst.motion.empty()) m_motion.emplace_back(inst.motion.begin(), inst.motion.end());
      if (const Shape* shape = meshes[inst.mesh].shape) {
        // A placed shape is tested directly in the top level's leaf: a bottom-level structure
        // over its one primitive would only add a traversal.
        int& copy = shape_of[inst.mesh];
        if (copy < 0) {
          copy = int(m_shapes.size());
          m_shapes.push_back(*shape);
          m_shape_mesh.push_back(inst.mesh);
        }
        const Bounds3f b = shape_bounds(*shape);
        if (b.empty() || !is_finite(b.lo) || !is_finite(b.hi)) continue;  // never hit
        m_items.push_back(
            {kShapeLevel, uint32_t(i), to_object, world_box(inst, motion, b), uint32_t(copy), motion});
        ++m_instances;
        continue;
      }
      int& object = object_of[inst.mesh];
      if (object < 0) {
        object = int(m_levels.size());
        // A deforming mesh gets the time-aware structure.
        m_levels.push_back(deforms ? make_deforming_accelerator(meshes.subspan(inst.mesh, 1), deforming)
                                   : build(meshes.subspan(inst.mesh, 1)));
        m_level_mesh.push_back(inst.mesh);
        m_level_deforms.push_back(deforms);
        if (!deforms) m_built_level = true;
      }
      m_items.push_back({uint32_t(object), uint32_t(i), to_object,
                         world_box(inst, motion, m_levels[size_t(object)]->bounds()), 0, motion});
      ++m_instances;
    }
    if (!deforming_world.empty()) {
      m_levels.push_back(make_deforming_accelerator(deforming_world, deforming));
      m_level_mesh.push_back(kWorld);
      m_level_deforms.push_back(1);
      m_items.push_back(
          {uint32_t(m_levels.size() - 1), kDeformingWorld, Affine3f{}, m_levels.back()->bounds()});
    }
    if (!world.empty() || !m_built_level) {  // an empty world level still names the back end
      m_levels.push_back(build(world));
      m_level_mesh.push_back(kWorld);
      m_level_deforms.push_back(0);
      m_items.push_back({uint32_t(m_levels.size() - 1), kWorld, Affine3f{}, m_levels.back()->bounds()});
    }
    for (const auto& level : m_levels) m_stats_bottom.push_back(level->stats());
    build_top();
    m_build_seconds = timer.seconds();
  }

  bool intersect(const Ray& ray, Hit& hit) const override { return closest(ray, hit, nullptr, nullptr); }
  bool intersect(const Ray& ray, Hit& hit, const HitFilter& filter) const override {
    return closest(ray, hit, nullptr, &filter);
  }
  bool intersect_counted(const Ray& ray, Hit& hit, TraversalCost& cost) const override {
    return closest(ray, hit, &cost, nullptr);
  }
  bool counts_traversal() const override {
    return std::all_of(m_levels.begin(), m_levels.end(), [](const auto& l) { return l->counts_traversal(); });
  }

  bool occluded(const Ray& ray) const override {
    return walk(ray, ray.tfar, nullptr, [&](const Item& item, const Ray& local) {
      if (item.level != kShapeLevel) return m_levels[item.level]->occluded(local);
      ShapeHit sh;
      return intersect_shape(m_shapes[item.shape], local, sh);
    });
  }

  bool occluded(const Ray& ray, const HitFilter& filter) const override {
    return walk(ray, ray.tfar, nullptr, [&](const Item& item, const Ray& local) {
      if (item.level != kShapeLevel) {
        const ItemFilter seen{filter, ray, *this, item.instance};
        return m_levels[item.level]->occluded(local, seen.filter());
      }
      ShapeHit sh;
      const auto accept = [&](float t) { return filter(ray, Hit{t, 0, 0, item.instance, 0}); };
      return intersect_shape_accepted(m_shapes[item.shape], local, accept, sh, nullptr);
    });
  }

  /// Depth-first walk over the top level's boxes (those over the whole shutter) that meet the
  /// region (read again at each node, as the visitor may shrink a ball), nearer child first for a
  /// ball; each item met offers its placed shape, or runs its bottom level's visit_region with
  /// the region in the item's space (ItemRegion).
  void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const override {
    if (m_nodes.empty()) return;
    walk_region_binary(m_nodes, region, cost, [&](uint32_t first, uint32_t count) {
      for (uint32_t i = first; i < first + count; ++i) visit_item(m_items[i], region, visitor, cost);
    });
  }

  Bounds3f bounds() const override { return m_bounds; }

  /// New maps for the placed items; the bottom levels and the world level stay, the top level
  /// is built again from the items in the order the constructor made them (instance order, the
  /// world level last), so its tree is the one a fresh build makes.
  bool update_instances(std::span<const InstanceView> instances) override {
    if (!m_layout.matches(instances)) return false;
    const BuildTimer timer;
    for (Item& item : m_items) {
      if (in_world(item.instance)) continue;
      const InstanceView& inst = instances[item.instance];
      if ((item.motion == kStill) != inst.motion.empty()) return false;  // checked before any change
    }
    for (Item& item : m_items) {
      if (in_world(item.instance)) continue;
      const InstanceView& inst = instances[item.instance];
      inverse(inst.to_world, item.to_object);
      if (item.motion != kStill) m_motion[item.motion].assign(inst.motion.begin(), inst.motion.end());
      item.box = world_box(inst, item.motion, object_box(item));
    }
    std::sort(m_items.begin(), m_items.end(),
              [](const Item& a, const Item& b) { return a.instance < b.instance; });
    m_nodes.clear();
    m_time_nodes.clear();
    m_bounds = Bounds3f{};
    m_top_depth = 0;
    m_sah_cost = 0;
    build_top();
    m_build_seconds = timer.seconds();
    return true;
  }

  /// Refits every bottom level to its mesh's new views (the world level to the identity
  /// instances' views), copies the placed shapes anew, then moves the instances as
  /// update_instances() does. A bottom level that cannot refit leaves the levels before it
  /// refitted: the caller discards the structure on false, as the interface says.
  bool refit_instances(std::span<const GeometryView> meshes,
                       std::span<const InstanceView> instances) override {
    if (!m_layout.matches(instances)) return false;
    for (const uint8_t deforms : m_level_deforms)
      if (deforms) return false;  // a deforming level is rebuilt for its new steps, never refitted
    for (const uint32_t mesh : m_shape_mesh) {
      if (mesh >= meshes.size() || !meshes[mesh].shape) return false;
      const Bounds3f b = shape_bounds(*meshes[mesh].shape);
      if (b.empty() || !is_finite(b.lo) || !is_finite(b.hi)) return false;
    }
    std::vector<GeometryView> world;
    for (const uint32_t id : m_world_ids) world.push_back(meshes[instances[id].mesh]);
    for (size_t l = 0; l < m_levels.size(); ++l) {
      const uint32_t mesh = m_level_mesh[l];
      if (mesh != kWorld && (mesh >= meshes.size() || meshes[mesh].shape)) return false;
      if (!(mesh == kWorld ? m_levels[l]->refit(world) : m_levels[l]->refit(meshes.subspan(mesh, 1))))
        return false;
      m_stats_bottom[l] = m_levels[l]->stats();
    }
    for (size_t k = 0; k < m_shapes.size(); ++k) m_shapes[k] = *meshes[m_shape_mesh[k]].shape;
    for (Item& item : m_items)
      if (item.instance == kWorld) item.box = m_levels[item.level]->bounds();
    return update_instances(instances);
  }

  AccelStats stats() const override {
    AccelStats s;
    for (size_t l = 0; l < m_levels.size(); ++l)
      if (!m_level_deforms[l]) {  // the back end's own levels name it
        s.name = m_stats_bottom[l].name;
        s.config = m_stats_bottom[l].config;
        break;
      }
    s.instances = m_instances;
    s.shapes = m_shapes.size();  // placed shapes; the levels add the world's
    uint64_t bottom_depth = 0;
    for (const AccelStats& b : m_stats_bottom) {
      s.triangles += b.triangles;
      s.shapes += b.shapes;
      s.nodes += b.nodes;
      s.leaves += b.leaves;
      s.empty_leaves += b.empty_leaves;
      s.references += b.references;
      s.max_leaf_prims = std::max(s.max_leaf_prims, b.max_leaf_prims);
      bottom_depth = std::max(bottom_depth, b.max_depth);
      s.bytes += b.bytes;
    }
    s.avg_leaf_prims =
        s.leaves > s.empty_leaves ? double(s.references) / double(s.leaves - s.empty_leaves) : 0;
    s.nodes += m_nodes.size();
    s.max_depth = m_top_depth + bottom_depth;
    s.sah_cost = m_sah_cost;
    s.bytes += (m_nodes.size() * (1 + m_time_nodes.size())) * sizeof(BvhNode) + m_items.size() * sizeof(Item);
    s.build_seconds = m_build_seconds;
    return s;
  }

 private:
  static constexpr uint32_t kWorld = 0xffffffffu;             // Item::instance of the world-space level
  static constexpr uint32_t kDeformingWorld = 0xfffffffeu;    // ... of the world's deforming meshes
  static constexpr uint32_t kShapeLevel = 0xffffffffu;        // Item::level of a placed shape
  static constexpr uint32_t kStill = 0xffffffffu;             // Item::motion of an item that stays put
  static constexpr uint32_t kTimeSegments = 8;                // time segments of the moving top level
  static constexpr size_t kTimeNodeBytes = size_t(32) << 20;  // most memory its per-segment nodes take

  struct Item {
    uint32_t level;     // index into m_levels, or kShapeLevel
    uint32_t instance;  // the instance index reported in hits, or kWorld
    Affine3f to_object;
    Bounds3f box;              // world bounds (over the shutter for a moving item)
    uint32_t shape = 0;        // index into m_shapes when level == kShapeLevel
    uint32_t motion = kStill;  // index into m_motion: the item's keys
  };

  /// The world box of object-space box `b` under the instance's map, or every map its motion
  /// takes.
  Bounds3f world_box(const InstanceView& inst, uint32_t motion, const Bounds3f& b) const {
    return motion == kStill ? transform_bounds(inst.to_world, b) : motion_bounds(m_motion[motion], b);
  }

  /// The object-space box an item's map places: its shape's or its bottom level's.
  Bounds3f object_box(const Item& item) const {
    return item.level == kShapeLevel ? shape_bounds(m_shapes[item.shape]) : m_levels[item.level]->bounds();
  }

  /// With moving items, the top level's boxes per time segment: m_time_nodes[k] is m_nodes with
  /// each box bounding its items over the times [k, k + 1] / kTimeSegments only (a moving item by
  /// motion_bounds over that span, a still one by its box), so that a ray tests the boxes of its
  /// own time's segment and not the whole shutter's (Embree's motion-blur BVH bounds nodes over
  /// time segments too, linearly within each). Left empty, and the shutter's boxes used, when
  /// nothing moves or the copies would pass kTimeNodeBytes.
  void build_time_nodes() {
    m_time_nodes.clear();
    if (m_motion.empty() || m_nodes.size() * kTimeSegments * sizeof(BvhNode) > kTimeNodeBytes) return;
    m_time_nodes.assign(kTimeSegments, m_nodes);
    std::vector<Bounds3f> boxes(m_nodes.size());
    for (uint32_t k = 0; k < kTimeSegments; ++k) {
      const float t0 = float(k) / float(kTimeSegments), t1 = float(k + 1) / float(kTimeSegments);
      std::vector<BvhNode>& nodes = m_time_nodes[k];
      for (size_t i = nodes.size(); i-- > 0;) {  // children follow their parent
        BvhNode& node = nodes[i];
        Bounds3f b;
        if (node.count > 0) {
          for (uint32_t j = node.offset, e = node.offset + node.count; j < e; ++j) {
            const Item& item = m_items[j];
            b = merge(b, item.motion == kStill
                             ? item.box
                             : motion_bounds(m_motion[item.motion], object_box(item), t0, t1));
          }
        } else {
          b = merge(boxes[i + 1], boxes[node.offset]);
        }
        boxes[i] = b;
        const Bounds3f w = widen_for_rounding(b);
        node.lo = w.lo;
        node.hi = w.hi;
      }
    }
  }

  /// The top-level nodes a ray at `time` walks: its time segment's, else the shutter's.
  const std::vector<BvhNode>& nodes_at(float time) const {
    if (m_time_nodes.empty()) return m_nodes;
    const float t = time > 0 ? (time < 1 ? time : 1.0f) : 0.0f;  // NaN as 0
    return m_time_nodes[std::min(uint32_t(t * float(kTimeSegments)), kTimeSegments - 1)];
  }

  /// The caller's filter as a bottom level must apply it: to the world ray, with the bottom
  /// level's geom_id replaced by the instance index (Hit's geom_id over instances).
  struct ItemFilter {
    const HitFilter& outer;
    const Ray& world_ray;
    const TwoLevelAccelerator& self;
    uint32_t instance;  // Item::instance: kWorld maps the world level's geom_id

    static bool accept(const void* context, const Ray&, const Hit& hit) {
      const auto& f = *static_cast<const ItemFilter*>(context);
      Hit h = hit;
      h.geom_id = f.self.instance_of(f.instance, hit.geom_id);
      return f.outer(f.world_ray, h);
    }
    HitFilter filter() const { return {&ItemFilter::accept, this}; }
  };

  /// The caller's visitor as an item's bottom level sees it: `local` is the query's region in
  /// the item's space, geom_id is mapped to the instance index, and a ball shrunk by the caller's
  /// visitor (in world space) narrows `local` to match. In the item's space the world region
  /// becomes: itself in the world levels; for a still placement, the ball about to_object(c)
  /// with the radius times the map's largest stretch (stretch2), or the box of the world box's
  /// mapped corners (of its part within the item's box), each widened by the mapping's
  /// rounding; for a moving placement, which has no one map, the bottom level's whole box (so
  /// its every primitive is offered while the world region meets the item's box over the
  /// shutter). Boxes are cut to the bottom level's box, so they stay finite.
  class ItemRegion final : public RegionVisitor {
   public:
    ItemRegion(QueryRegion& world, RegionVisitor& outer, const TwoLevelAccelerator& self, const Item& item,
               const Bounds3f& box)
        : m_world(world), m_outer(outer), m_self(self), m_item(item), m_box(box) {
      m_local = world;
      if (in_world(item.instance)) return;
      const Bounds3f level = self.m_levels[item.level]->bounds();
      if (item.motion != kStill || world.is_box) {
        m_local.is_box = true;
        m_local.box = level;
        if (item.motion == kStill) {  // the part of the box within the item's, mapped
          const Bounds3f part = penumbra::intersect(world.box, box);
          const Bounds3f b = transform_bounds(item.to_object, part);
          const float pad =
              float(map_rounding(item.to_object).at(max_component(max(abs(part.lo), abs(part.hi)))));
          m_local.box =
              penumbra::intersect(level, Bounds3f{b.lo - Vec3f{pad, pad, pad}, b.hi + Vec3f{pad, pad, pad}});
        }
        return;
      }
      m_local.centre = apply_point(item.to_object, world.centre);
      m_stretch = std::sqrt(stretch2(item.to_object));
      m_slack = map_rounding(item.to_object).at(max_component(abs(world.centre)));
      m_local.radius2 = local_radius2(world.radius2);
    }

    /// False when the region in the item's space holds nothing of its bottom level.
    bool reaches_level() const { return !m_local.is_box || !m_local.box.empty(); }

    void visit(uint32_t geom_id, uint32_t prim_id, QueryRegion&) override {
      if (!region_meets(m_world, m_box)) return;  // a ball shrunk away from the item
      const float before = m_world.radius2;
      m_outer.visit(m_self.instance_of(m_item.instance, geom_id), prim_id, m_world);
      if (m_local.is_box || !(m_world.radius2 < before)) return;
      m_local.radius2 = std::min(m_local.radius2, local_radius2(m_world.radius2));
    }

    /// The region in the item's space, for the bottom level's visit_region().
    QueryRegion& local() { return m_local; }

   private:
    /// The squared radius in the item's space of a world ball of squared radius `world_radius2`,
    /// rounded up.
    float local_radius2(float world_radius2) const {
      if (in_world(m_item.instance)) return world_radius2;
      const double r = m_stretch * std::sqrt(double(world_radius2)) + m_slack;
      return float(r * r * (1 + 1e-6));
    }

    QueryRegion& m_world;
    RegionVisitor& m_outer;
    const TwoLevelAccelerator& m_self;
    const Item& m_item;
    const Bounds3f& m_box;  // the item's world box, widened for rounding
    QueryRegion m_local;
    double m_stretch = 1;  // the map's largest stretch, bounded above (still placements)
    double m_slack = 0;    // the mapped centre's rounding
  };

  /// The part of visit_region() for one item of a top-level leaf.
  void visit_item(const Item& item, QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const {
    const Bounds3f box = widen_for_rounding(item.box);  // as the top level's nodes are
    if (!region_meets(region, box)) return;
    if (item.level == kShapeLevel) {
      visitor.visit(item.instance, 0, region);
      return;
    }
    ItemRegion mapped(region, visitor, *this, item, box);
    if (mapped.reaches_level()) m_levels[item.level]->visit_region(mapped.local(), mapped, cost);
  }

  /// The instance index a hit of item `instance`'s bottom level reports as geom_id.
  uint32_t instance_of(uint32_t instance, uint32_t level_geom_id) const {
    if (instance == kWorld) return m_world_ids[level_geom_id];
    return instance == kDeformingWorld ? m_deforming_ids[level_geom_id] : instance;
  }
  static bool in_world(uint32_t instance) { return instance == kWorld || instance == kDeformingWorld; }

  void build_top() {
    std::vector<BvhBuildRef> refs;
    for (uint32_t i = 0; i < m_items.size(); ++i)
      if (!m_items[i].box.empty()) refs.emplace_back(m_items[i].box, i);
    if (refs.empty()) return;
    BvhConfig config;
    config.max_leaf_size = 1;  // an item costs a whole bottom-level query
    const auto root = build_bvh_tree(refs, config);
    std::vector<Item> ordered;
    for (const auto& r : refs) ordered.push_back(m_items[r.index]);
    m_items = std::move(ordered);
    m_bounds = root->box;
    flatten_bvh(*root, m_nodes);
    m_top_depth = depth(*root);
    build_time_nodes();
    // Expected cost of a ray through the root: top nodes at cost 1 each, and per item the
    // probability of entering its box times its bottom level's own SAH cost. Reported only if
    // every bottom level has one.
    const double root_area = surface_area(root->box);
    bool known = root_area > 0;
    double cost = 0;
    for (const BvhNode& n : m_nodes)
      if (n.count == 0) cost += surface_area({n.lo, n.hi}) / root_area;
    for (const Item& item : m_items) {
      const double level_cost = item.level == kShapeLevel ? 1.0 : m_stats_bottom[item.level].sah_cost;
      known = known && level_cost > 0;
      cost += surface_area(item.box) / root_area * level_cost;
    }
    m_sah_cost = known ? cost : 0;
  }

  static uint64_t depth(const BvhBuildNode& n) {
    return n.child[0] ? 1 + std::max(depth(*n.child[0]), depth(*n.child[1])) : 0;
  }

  /// Visits the items whose boxes the ray meets within [tnear, best], nearer subtrees first,
  /// calling query(item, ray in the item's space) until it returns true. `best` may shrink
  /// during the walk (closest-hit queries narrow it).
  template <typename Query>
  bool walk(const Ray& ray, const float& best, TraversalCost* cost, Query&& query) const {
    if (!is_valid_query(ray)) return false;
    return walk_bvh(
        nodes_at(ray.time), prepare_box_query(ray), std::max(ray.tnear, 0.0f), best,
        [&] {
          if (cost) ++cost->nodes;
        },
        [&](uint32_t first, uint32_t count) {
          for (uint32_t i = first, e = first + count; i < e; ++i) {
            const Item& item = m_items[i];
            Ray local = ray;
            local.tfar = best;
            if (item.motion != kStill) {
              Affine3f to_object;
              if (!inverse(interpolate_motion(m_motion[item.motion], ray.time), to_object)) continue;
              local.org = apply_point(to_object, ray.org);
              local.dir = apply_vector(to_object, ray.dir);
            } else if (!in_world(item.instance)) {
              local.org = apply_point(item.to_object, ray.org);
              local.dir = apply_vector(item.to_object, ray.dir);
            }
            if (query(item, local)) return true;
          }
          return false;
        });
  }

  /// The closest hit over the items the ray meets, through `filter` when non-null.
  bool closest(const Ray& ray, Hit& hit, TraversalCost* cost, const HitFilter* filter) const {
    hit = Hit{};
    float best = ray.tfar;
    walk(ray, best, cost, [&](const Item& item, const Ray& local) {
      if (item.level == kShapeLevel) {
        ShapeHit sh;
        const auto accept = [&](float t) {
          return !filter || (*filter)(ray, Hit{t, 0, 0, item.instance, 0});
        };
        if (!intersect_shape_accepted(m_shapes[item.shape], local, accept, sh, cost)) return false;
        best = sh.t;
        hit = {sh.t, 0, 0, item.instance, 0};
        return false;
      }
      Hit h;
      const Accelerator& level = *m_levels[item.level];
      bool found;
      if (filter) {
        const ItemFilter seen{*filter, ray, *this, item.instance};
        found = level.intersect(local, h, seen.filter());
      } else {
        found = cost ? level.intersect_counted(local, h, *cost) : level.intersect(local, h);
      }
      if (!found) return false;
      best = h.t;
      hit = h;
      hit.geom_id = instance_of(item.instance, h.geom_id);
      return false;
    });
    return hit.valid();
  }

  std::vector<std::unique_ptr<Accelerator>> m_levels;  // bottom levels: per mesh, then world
  std::vector<Shape> m_shapes;                         // the placed shapes, one copy per view
  std::vector<uint32_t> m_world_ids;                   // world level's geom_id -> instance index
  std::vector<uint32_t> m_deforming_ids;               // the same for the world's deforming meshes
  std::vector<uint32_t> m_level_mesh;                  // each bottom level's mesh, or kWorld
  std::vector<uint8_t> m_level_deforms;                // each bottom level is a deforming mesh's
  bool m_built_level = false;                          // some bottom level is the back end's own
  std::vector<uint32_t> m_shape_mesh;                  // each placed shape's mesh (view)
  std::vector<Item> m_items;                           // in top-level leaf order
  std::vector<std::vector<MotionKey>> m_motion;        // the moving items' keys
  std::vector<BvhNode> m_nodes;                        // top level, depth first
  std::vector<std::vector<BvhNode>> m_time_nodes;      // the same per time segment (build_time_nodes)
  std::vector<AccelStats> m_stats_bottom;
  InstanceLayout m_layout;  // every instance's mesh and kind, as built
  Bounds3f m_bounds;
  uint64_t m_instances = 0;
  uint64_t m_top_depth = 0;
  double m_sah_cost = 0;
  double m_build_seconds = 0;
};

}  // namespace

void validate_instances(std::span<const InstanceView> instances, size_t mesh_count) {
  for (size_t i = 0; i < instances.size(); ++i)
    if (instances[i].mesh >= mesh_count)
      throw std::invalid_argument("instance " + std::to_string(i) + ": mesh " +
                                  std::to_string(instances[i].mesh) + " out of range (" +
                                  std::to_string(mesh_count) + " meshes)");
}

std::unique_ptr<Accelerator> make_two_level_accelerator(const AcceleratorBuilder& build,
                                                        std::span<const GeometryView> meshes,
                                                        std::span<const InstanceView> instances,
                                                        const DeformingConfig& deforming) {
  return std::make_unique<TwoLevelAccelerator>(build, meshes, instances, deforming);
}

}  // namespace penumbra
