// Embree 3 back end. Embree reports errors through a C callback, which only records them;
// the build function converts a recorded error into an exception at this one boundary.
#include "renderer/accel/embree.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <cstring>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "renderer/accel/bvh_build.h"
#include "renderer/accel/bvh_wide.h"
#include "renderer/accel/region_map.h"
#include "renderer/accel/stats.h"

namespace penumbra {
namespace {

struct DeviceErrors {
  std::mutex mutex;
  std::string first;  // first error since the last take(); empty if none
};

DeviceErrors& device_errors() {
  static DeviceErrors errors;
  return errors;
}

void record_error(void*, RTCError code, const char* str) {
  auto& e = device_errors();
  std::lock_guard lock(e.mutex);
  if (e.first.empty()) e.first = "Embree error " + std::to_string(int(code)) + ": " + (str ? str : "");
}

std::string take_error() {
  auto& e = device_errors();
  std::lock_guard lock(e.mutex);
  std::string s;
  std::swap(s, e.first);
  return s;
}

/// Bytes the Embree device holds, kept by its memory monitor callback (called with the size of
/// each allocation, and negated after each free). A scene's footprint is the difference across
/// its build; concurrent builds in one process would blur it (the benchmark builds one at a time).
std::atomic<int64_t>& device_bytes() {
  static std::atomic<int64_t> bytes{0};
  return bytes;
}

bool monitor_memory(void*, ssize_t bytes, bool) {
  device_bytes() += int64_t(bytes);
  return true;  // never refuse an allocation
}

/// The device's configuration: deforming triangles go to Embree's motion-blur BVH with their
/// vertices at both ends of each time segment stored in the leaves (triangle4vmb) rather than
/// indices into the vertex buffers (triangle4imb, Embree's default), which spares every
/// triangle test the gathers of its vertices at two steps; 8-wide nodes where the CPU has
/// AVX2, as Embree's default picks.
const char* device_config() {
  return __builtin_cpu_supports("avx2") ? "tri_accel_mb=bvh8.triangle4vmb" : "tri_accel_mb=bvh4.triangle4vmb";
}

RTCDevice device() {
  static RTCDevice dev = [] {
    RTCDevice d = rtcNewDevice(device_config());
    if (!d) throw std::runtime_error("embree: cannot create device (rtcNewDevice failed)");
    rtcSetDeviceErrorFunction(d, record_error, nullptr);
    rtcSetDeviceMemoryMonitorFunction(d, monitor_memory, nullptr);
    return d;
  }();
  return dev;
}

void throw_if_error(const char* what) {
  std::string e = take_error();
  if (!e.empty()) throw std::runtime_error(std::string("embree: ") + what + ": " + e);
}

/// Throws std::invalid_argument naming the mesh if a deforming mesh's steps do not hold all its
/// vertices at every step, or if it has more steps than Embree takes (129). Called before any
/// Embree object is made, so that nothing is left behind.
void check_motion_steps(std::span<const GeometryView> meshes) {
  for (size_t g = 0; g < meshes.size(); ++g) {
    const GeometryView& mesh = meshes[g];
    if (!mesh.deforms()) continue;
    if (mesh.motion_steps > 129 ||
        mesh.motion_positions.size() != size_t(mesh.motion_steps) * mesh.positions.size())
      throw std::invalid_argument("embree: mesh " + std::to_string(g) +
                                  ": a deforming mesh needs 2 to 129 motion steps of all its vertices");
  }
}

/// A new triangle geometry holding a copy of `mesh` (an empty mesh gets one degenerate triangle,
/// which is never hit, so it still occupies its id), committed and attached to `scene` as `id`.
/// A deforming mesh gets one vertex buffer per time step (rtcSetGeometryTimeStepCount), which
/// Embree interpolates linearly at each ray's time.
void attach_triangles(RTCScene scene, const GeometryView& mesh, unsigned id) {
  RTCGeometry geom = rtcNewGeometry(device(), RTC_GEOMETRY_TYPE_TRIANGLE);
  const size_t nv = mesh.positions.size(), nt = mesh.indices.size() / 3;
  const unsigned steps = mesh.deforms() && nv && nt ? mesh.motion_steps : 1;
  if (steps > 1) rtcSetGeometryTimeStepCount(geom, steps);
  bool allocated = true;
  for (unsigned k = 0; k < steps; ++k) {
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, k, RTC_FORMAT_FLOAT3,
                                                          sizeof(float) * 3, nv ? nv : 1));
    allocated = allocated && v;
    if (!v) break;
    if (!nv || !nt)
      std::memset(v, 0, sizeof(float) * 3);
    else
      std::memcpy(v, (steps > 1 ? mesh.motion_positions.data() + k * nv : mesh.positions.data()),
                  nv * sizeof(float) * 3);
  }
  auto* idx = allocated
                  ? static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
                        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, sizeof(uint32_t) * 3, nt ? nt : 1))
                  : nullptr;
  if (!idx) {
    rtcReleaseGeometry(geom);
    throw_if_error("allocating geometry buffers");
    throw std::runtime_error("embree: allocating geometry buffers failed");
  }
  if (nv && nt)
    std::memcpy(idx, mesh.indices.data(), nt * sizeof(uint32_t) * 3);
  else
    std::memset(idx, 0, sizeof(uint32_t) * 3 * (nt ? nt : 1));
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
  throw_if_error("attaching geometry");
}

/// Embree's user-geometry callbacks for an array of Shapes (geometryUserPtr; primitive i is
/// shape i: one for a shape of its own, a curve set's elements), called with one ray at a time
/// (rtcIntersect1 / rtcOccluded1): bounds, closest hit, any hit, each through the shared
/// per-kind shape test. A curve element without finite bounds (a radius not finite) gets an
/// empty box at its first end point (finite: the positions are) and is never tested.
bool has_finite_bounds(const Shape& shape) {
  const Bounds3f b = shape_bounds(shape);
  return !b.empty() && is_finite(b.lo) && is_finite(b.hi);
}

void user_shape_bounds(const RTCBoundsFunctionArguments* args) {
  const Shape& shape = static_cast<const Shape*>(args->geometryUserPtr)[args->primID];
  const Bounds3f b = shape_bounds(shape);
  RTCBounds* o = args->bounds_o;
  if (!has_finite_bounds(shape)) {
    const Vec3f p = is_finite(shape.p0) ? shape.p0 : Vec3f{};
    o->lower_x = o->upper_x = p.x, o->lower_y = o->upper_y = p.y, o->lower_z = o->upper_z = p.z;
    return;
  }
  o->lower_x = b.lo.x, o->lower_y = b.lo.y, o->lower_z = b.lo.z;
  o->upper_x = b.hi.x, o->upper_y = b.hi.y, o->upper_z = b.hi.z;
}

/// The hit a user geometry offers to the context's filter (through rtcFilterIntersection /
/// rtcFilterOcclusion, which run it): u, v and the normal 0, as a shape's Hit has them.
RTCHit shape_candidate(unsigned geom_id, unsigned prim_id, const RTCIntersectContext* context) {
  RTCHit h;
  h.Ng_x = h.Ng_y = h.Ng_z = 0;
  h.u = h.v = 0;
  h.primID = prim_id;
  h.geomID = geom_id;
  h.instID[0] = context->instID[0];
  return h;
}

/// Offers the shape hit at t to the filters with `tfar` set to t, as Embree does for its own
/// primitives; restores `tfar` and returns whether the hit was accepted.
template <typename Args, typename Invoke>
bool offer_shape_hit(const Args* args, RTCRayN* ray, float& tfar, float t, Invoke&& invoke) {
  if (!args->context->filter) return true;
  RTCHit candidate = shape_candidate(args->geomID, args->primID, args->context);
  int valid = -1;
  const RTCFilterFunctionNArguments fargs{
      &valid, args->geometryUserPtr, args->context, ray, reinterpret_cast<RTCHitN*>(&candidate), 1};
  const float saved = tfar;
  tfar = t;
  invoke(args, &fargs);
  tfar = saved;
  return valid != 0;
}

void user_shape_intersect(const RTCIntersectFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
  const Ray r{{rh->ray.org_x, rh->ray.org_y, rh->ray.org_z},
              rh->ray.tnear,
              {rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z},
              rh->ray.tfar};
  const auto accept = [&](float t) {
    return offer_shape_hit(args, reinterpret_cast<RTCRayN*>(&rh->ray), rh->ray.tfar, t,
                           rtcFilterIntersection);
  };
  ShapeHit sh;
  const Shape& shape = static_cast<const Shape*>(args->geometryUserPtr)[args->primID];
  if (!has_finite_bounds(shape) || !intersect_shape_accepted(shape, r, accept, sh, nullptr)) return;
  rh->ray.tfar = sh.t;
  rh->hit = shape_candidate(args->geomID, args->primID, args->context);
}

void user_shape_occluded(const RTCOccludedFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  auto* ray = reinterpret_cast<RTCRay*>(args->ray);
  const Ray r{
      {ray->org_x, ray->org_y, ray->org_z}, ray->tnear, {ray->dir_x, ray->dir_y, ray->dir_z}, ray->tfar};
  const auto accept = [&](float t) {
    return offer_shape_hit(args, args->ray, ray->tfar, t, rtcFilterOcclusion);
  };
  ShapeHit sh;
  const Shape& shape = static_cast<const Shape*>(args->geometryUserPtr)[args->primID];
  if (has_finite_bounds(shape) && intersect_shape_accepted(shape, r, accept, sh, nullptr))
    ray->tfar = -kInfinity;
}

/// A new user geometry over `count` shapes from `shapes` (which must outlive it; primitive i is
/// shape i), committed and attached to `scene` as `id`. A curve set's elements come this way:
/// Embree 3's own round linear curves join consecutive segments (neighbour flags) and leave out
/// a segment's starting cap, so they would not be the disjoint capsules of a glTF LINES
/// primitive; the user geometry tests them by the one exact test every back end shares.
void attach_shapes(RTCScene scene, const Shape* shapes, size_t count, unsigned id) {
  RTCGeometry geom = rtcNewGeometry(device(), RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geom, unsigned(count));
  rtcSetGeometryUserData(geom, const_cast<Shape*>(shapes));
  rtcSetGeometryBoundsFunction(geom, user_shape_bounds, nullptr);
  rtcSetGeometryIntersectFunction(geom, user_shape_intersect);
  rtcSetGeometryOccludedFunction(geom, user_shape_occluded);
  rtcCommitGeometry(geom);
  rtcAttachGeometryByID(scene, geom, id);
  rtcReleaseGeometry(geom);
  throw_if_error("attaching a shape");
}

/// How much a world-space point query's radius must exceed a ball's so that Embree's query
/// inside an instance with world-to-object map `to_object` covers the ball's image; 1 when
/// Embree's own radius is enough. Embree 3 (similarityTransform in its affinespace.h) takes a
/// map whose columns are orthogonal and of equal squared length to within an absolute 1e-5 for
/// a similarity of scale D (its first column's length); it then culls the instance's nodes with
/// the world radius R itself and its primitives with R D, where the ball's image needs
/// R sigma (sigma the map's largest stretch, more than D for a small map with unequal
/// columns): so R must be max(sigma, sigma / D) times the ball's radius. Other maps it bounds
/// by the box of the radius's cube, which covers the ball. The tests here are looser (1e-4,
/// absolute and relative), so that no map Embree's rounding of the inverse makes pass is missed.
double similarity_radius_scale(const Affine3f& to_object) {
  Vec3f c[3];
  for (int j = 0; j < 3; ++j) c[j] = {to_object.m[0][j], to_object.m[1][j], to_object.m[2][j]};
  const auto dot_d = [](Vec3f a, Vec3f b) {
    return double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z;
  };
  const double d[3] = {dot_d(c[0], c[0]), dot_d(c[1], c[1]), dot_d(c[2], c[2])};
  const double tol = 1e-4 * (1 + std::max(d[0], std::max(d[1], d[2])));
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (std::fabs(dot_d(c[i], c[j])) > tol || std::fabs(d[i] - d[j]) > tol) return 1;
  }
  const double sigma = std::sqrt(stretch2(to_object));
  return d[0] > 0 ? std::max(1.0, std::max(sigma, sigma / std::sqrt(d[0]))) : kInfinity;
}

/// The largest factor by which visit_region() widens Embree's query radius for the instances
/// Embree queries itself (similarity_radius_scale); instances needing more are queried apart,
/// in their own scene.
constexpr double kMaxQueryScale = 1.001;

/// The largest origin or direction coordinate handed to Embree, object-space rays included:
/// under Embree's FLT_LARGE (1.8e18) with room for the rounding of its instance transforms.
constexpr double kEmbreeRayLimit = 1e18;

/// A query's ray as handed to Embree, and how Embree's t maps back to the query's.
struct TraceRay {
  struct Units {
    double start = 0;  ///< where Embree's ray starts, in its own (unit-direction) t
    double scale = 1;  ///< query t per Embree t
    float query_t(float t) const { return start == 0 && scale == 1 ? t : float((start + double(t)) * scale); }
  };
  Ray ray;
  Units units;
  bool ok = true;  ///< false: the ray cannot be traced (it misses)
};

class EmbreeAccelerator final : public Accelerator {
 public:
  /// Identity instances become triangle (or user) geometries of the top scene; every other
  /// instance is an Embree instance of a per-geometry scene. Geometry id in the top scene ==
  /// instance index. Shapes with empty or non-finite bounds keep their id but are never hit.
  EmbreeAccelerator(std::span<const GeometryView> meshes, std::span<const InstanceView> instances,
                    const EmbreeConfig& config)
      : m_config(config) {
    validate(config);
    check_motion_steps(meshes);
    note_mesh_regions(meshes);
    const BuildTimer timer;
    const int64_t bytes_before = device_bytes();
    take_error();
    m_scene = new_scene();
    std::vector<RTCScene> objects(meshes.size(), nullptr);
    // The identity placements' own scene, when asked for and there are placed instances too.
    const auto kind_in = [&](InstanceKind k) {
      return std::any_of(instances.begin(), instances.end(),
                         [&](const InstanceView& i) { return instance_kind(i) == k; });
    };
    RTCScene world = m_scene;
    if (config.world_apart && kind_in(InstanceKind::Identity) && kind_in(InstanceKind::Placed)) {
      world = new_scene();
      m_objects.push_back(world);
      m_world_id = unsigned(instances.size());
    }
    for (size_t i = 0; i < instances.size(); ++i) {
      const InstanceView& inst = instances[i];
      const GeometryView& mesh = meshes[inst.mesh];
      const unsigned id = unsigned(i);
      m_layout.add(inst);
      const InstanceKind kind = m_layout.kinds.back();
      Affine3f inverse_map;
      if (kind == InstanceKind::Identity) {
        const unsigned world_id = world == m_scene ? id : unsigned(m_world_ids.size());
        attach_geometry(world, mesh, world_id);
        keep_buffers(world, world_id, inst.mesh);
        if (world != m_scene) m_world_ids.push_back(id);
        continue;
      }
      if (kind == InstanceKind::Singular) {  // an empty mesh keeps the id
        attach_triangles(m_scene, GeometryView{}, id);
        continue;
      }
      note_inverses(inst);
      RTCScene& object = objects[inst.mesh];
      if (!object) {
        object = new_scene();
        m_objects.push_back(object);
        attach_geometry(object, mesh, 0);
        keep_buffers(object, 0, inst.mesh);
        m_mesh_regions[inst.mesh].object = object;
        rtcCommitScene(object);
        throw_if_error("building an instanced mesh (rtcCommitScene)");
      }
      attach_instance(object, inst.to_world, id, inst.motion);
      ++m_instances;
    }
    if (world != m_scene) {
      rtcCommitScene(world);
      throw_if_error("building the identity placements (rtcCommitScene)");
      attach_instance(world, Affine3f{}, m_world_id);
    }
    rtcCommitScene(m_scene);
    throw_if_error("building the scene (rtcCommitScene)");
    m_bytes = uint64_t(std::max<int64_t>(0, device_bytes() - bytes_before));
    read_bounds();
    index_regions(instances);
    m_build_seconds = timer.seconds();
  }

  ~EmbreeAccelerator() override {
    if (m_scene) rtcReleaseScene(m_scene);
    for (RTCScene object : m_objects) rtcReleaseScene(object);
  }
  EmbreeAccelerator(const EmbreeAccelerator&) = delete;
  EmbreeAccelerator& operator=(const EmbreeAccelerator&) = delete;

  bool intersect(const Ray& ray, Hit& hit) const override {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    return closest(ray, hit, ctx);
  }

  bool intersect(const Ray& ray, Hit& hit, const HitFilter& filter) const override {
    FilterContext ctx(*this, ray, filter);
    return closest(ray, hit, ctx.rtc, &ctx.units);
  }

  bool occluded(const Ray& ray) const override {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    return any_hit(ray, ctx);
  }

  bool occluded(const Ray& ray, const HitFilter& filter) const override {
    FilterContext ctx(*this, ray, filter);
    return any_hit(ray, ctx.rtc, &ctx.units);
  }

  /// Embree's point query (rtcPointQuery at time 0) over the whole scene, whose callback
  /// offers each primitive it reaches (not the placeholders of empty meshes and singular
  /// instances) and narrows Embree's radius as the visitor shrinks a ball; then the instances
  /// Embree's query may miss (RegionItem), through the BVH over their world boxes (nearer first
  /// for a ball, the ball read again at each node). Embree's radius is the ball's padded by
  /// kRegionPad, scaled by m_query_scale and widened by m_query_rounding; a box, or a ball
  /// centred too far out for Embree, is queried by the ball around its part within the scene's
  /// bounds (offering a superset). Embree's own nodes are not counted; the BVH's are.
  void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const override {
    PointQueryState state{this, &region, &visitor, nullptr, 0, false};
    RTCPointQuery query;
    if (point_query(state, query)) {
      RTCPointQueryContext context;
      rtcInitPointQueryContext(&context);
      rtcPointQuery(m_scene, &query, &context, &EmbreeAccelerator::offer_point_query, &state);
    }
    if (m_region_nodes.empty()) return;
    walk_region_binary(m_region_nodes, region, cost, [&](uint32_t first, uint32_t count) {
      for (uint32_t i = first; i < first + count; ++i) visit_item(m_region_items[i], region, visitor);
    });
  }

  Bounds3f bounds() const override { return m_bounds; }

  /// New transforms on the instance geometries, then the top scene committed again: the
  /// instanced meshes' scenes are kept as they are.
  bool update_instances(std::span<const InstanceView> instances) override {
    if (!m_layout.matches(instances)) return false;
    const BuildTimer timer;
    take_error();
    for (size_t i = 0; i < instances.size(); ++i) {
      if (m_layout.kinds[i] != InstanceKind::Placed) continue;
      RTCGeometry geom = rtcGetGeometry(m_scene, unsigned(i));
      set_instance_motion(geom, instances[i].to_world, instances[i].motion);
      rtcCommitGeometry(geom);
    }
    throw_if_error("moving the instances");
    m_inverse_scale = 1;
    m_inverse_offset = 0;
    for (size_t i = 0; i < instances.size(); ++i)
      if (m_layout.kinds[i] == InstanceKind::Placed) note_inverses(instances[i]);
    rtcCommitScene(m_scene);
    throw_if_error("rebuilding the top level (rtcCommitScene)");
    read_bounds();
    index_regions(instances);
    m_build_seconds = timer.seconds();
    return true;
  }

  AccelStats stats() const override {
    AccelStats s;
    s.name = "embree";
    s.config = std::string("robust ") + (m_config.robust ? "1" : "0") + ", quality " +
               (m_config.quality == 0   ? "low"
                : m_config.quality == 1 ? "medium"
                                        : "high") +
               (m_world_id != RTC_INVALID_GEOMETRY_ID ? ", identity placements apart" : "");
    s.triangles = m_triangles;
    s.shapes = m_shapes.size() + m_curve_count;
    s.instances = m_instances;
    s.bytes = m_bytes;
    s.build_seconds = m_build_seconds;
    return s;
  }

 private:
  /// An intersection context whose filter function (RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION)
  /// offers Embree's candidate hits to a HitFilter. `rtc` comes first, so the callback finds the
  /// rest from the context pointer Embree passes it.
  struct FilterContext {
    RTCIntersectContext rtc;
    const EmbreeAccelerator* self;
    const Ray* ray;  // the query's world-space ray (Embree passes instanced hits the object-space one)
    const HitFilter* filter;
    TraceRay::Units units;  // how Embree's t maps to the query's (set by closest / any_hit)

    FilterContext(const EmbreeAccelerator& s, const Ray& r, const HitFilter& f)
        : self(&s), ray(&r), filter(&f) {
      rtcInitIntersectContext(&rtc);
      rtc.filter = &FilterContext::run;
    }

    static void run(const RTCFilterFunctionNArguments* args) {
      const auto& c = *reinterpret_cast<const FilterContext*>(args->context);
      for (unsigned i = 0; i < args->N; ++i) {
        if (!args->valid[i]) continue;
        Hit h;
        h.t = c.units.query_t(RTCRayN_tfar(args->ray, args->N, i));
        h.u = RTCHitN_u(args->hit, args->N, i);
        h.v = RTCHitN_v(args->hit, args->N, i);
        h.geom_id = c.self->instance_of(RTCHitN_geomID(args->hit, args->N, i),
                                        RTCHitN_instID(args->hit, args->N, i, 0));
        h.prim_id = RTCHitN_primID(args->hit, args->N, i);
        if (!(*c.filter)(*c.ray, h)) args->valid[i] = 0;
      }
    }
  };
  static_assert(std::is_standard_layout_v<FilterContext>);

  /// What region queries know of a view: its primitives (0 when Embree holds a placeholder for
  /// it: no triangles, or a shape without finite bounds), its box over every time step, the
  /// Embree scene its placements instance (null if none), and for a deforming mesh the index
  /// buffer and per-step vertex buffers of one of its Embree geometries (keep_buffers()).
  struct MeshRegion {
    uint32_t prims = 0;
    uint32_t steps = 0;  // motion steps of a deforming mesh; 0 otherwise
    Bounds3f box;        // finite vertices (or the shape's bounds), every step
    RTCScene object = nullptr;
    const uint32_t* indices = nullptr;
    std::vector<const float*> vertices;  // per step, 3 floats per vertex
  };

  /// An instance whose primitives Embree's query of the whole scene may miss, and how
  /// visit_region() reaches them instead:
  ///  - Moving: a placement that moves (the query sees one time): every primitive, while the
  ///    region meets its box over the shutter;
  ///  - Deforming: a deforming mesh (likewise): each triangle whose box over every step
  ///    (mapped by `map`, its to_world, when placed) meets the region;
  ///  - Nested: a still placement whose map Embree would need too wide a radius for
  ///    (similarity_radius_scale): a point query in the mesh's own scene with the region mapped
  ///    by `map`, its to_object.
  struct RegionItem {
    enum Kind : uint8_t { Moving, Deforming, Nested };
    uint32_t instance = 0;
    Kind kind = Moving;
    bool placed = false;  // Deforming: under `map` (else in world space)
    Affine3f map;
    double stretch = 1;    // Nested: the map's largest stretch, bounded above (stretch2)
    MapRounding rounding;  // Deforming (placed), Nested: of points mapped by `map`
    float pad = 0;         // Deforming (placed): rounding at the mesh's coordinates
    Bounds3f box;          // world bounds over the shutter
  };

  /// One point query's state for its callback (rtcPointQuery's user pointer).
  struct PointQueryState {
    const EmbreeAccelerator* self;
    QueryRegion* region;  // the caller's, in world space
    RegionVisitor* visitor;
    const RegionItem* item;  // a Nested instance's query in its own scene; null: the whole scene
    double magnitude;        // the world ball's largest centre coordinate (rounding allowances)
    bool shrinks;            // a ball queried as it is: Embree's radius follows radius2 down
  };

  /// The point queries' callback: offers the primitive with the ids intersect() reports, and
  /// returns true when it narrowed Embree's radius (in the queried scene's space) to a shrunk
  /// ball.
  static bool offer_point_query(RTCPointQueryFunctionArguments* args) {
    const PointQueryState& state = *static_cast<const PointQueryState*>(args->userPtr);
    const EmbreeAccelerator& self = *state.self;
    const RTCPointQueryContext& context = *args->context;
    const uint32_t id =
        state.item ? state.item->instance
                   : self.instance_of(args->geomID, context.instStackSize > 0 ? context.instID[0]
                                                                              : RTC_INVALID_GEOMETRY_ID);
    if (id >= self.m_layout.kinds.size() || args->primID >= self.prims_of(id)) return false;
    QueryRegion& region = *state.region;
    const float before = region.radius2;
    state.visitor->visit(id, args->primID, region);
    if (!state.shrinks || !(region.radius2 < before)) return false;
    const float radius = self.query_radius(state, region.radius2);
    if (!(radius < args->query->radius)) return false;
    args->query->radius = radius;
    return true;
  }

  /// The primitives of instance `id` as built (0 for a singular one).
  uint32_t prims_of(uint32_t id) const {
    return m_layout.kinds[id] == InstanceKind::Singular ? 0 : m_mesh_regions[m_layout.meshes[id]].prims;
  }

  /// Embree's radius for a world ball of squared radius `radius2`, padded by kRegionPad and
  /// rounded up: in the whole scene scaled by m_query_scale and widened by m_query_rounding; in
  /// a Nested instance's scene stretched by its map and widened by the map's rounding.
  float query_radius(const PointQueryState& state, float radius2) const {
    const double r = std::sqrt(double(radius2) * double(kRegionPad));
    const RegionItem* item = state.item;
    const double radius = item ? r * item->stretch + item->rounding.at(state.magnitude)
                               : r * m_query_scale + m_query_rounding.at(state.magnitude);
    return float(radius * (1 + 1e-6));
  }

  /// Fills `q` for the query of the whole scene (state.item null) or of a Nested instance's
  /// scene; false when nothing there can be in the region. A ball whose centre Embree can take
  /// (mapped into every instance) is queried as it is, setting state.shrinks; otherwise the
  /// part of the region's box within the queried scene's bounds, by its circumscribed ball.
  bool point_query(PointQueryState& state, RTCPointQuery& q) const {
    const QueryRegion& region = *state.region;
    const RegionItem* item = state.item;
    q.time = 0;
    state.shrinks = false;
    Bounds3f b = region.box;
    if (!region.is_box) {
      const Vec3f c = region.centre;
      if (std::isnan(c.x) || std::isnan(c.y) || std::isnan(c.z)) return false;  // no point is near
      state.magnitude = max_component(abs(c));
      const Vec3f p = item ? apply_point(item->map, c) : c;
      const double reach =
          item ? max_component(abs(p)) : m_inverse_scale * state.magnitude + m_inverse_offset;
      if (is_finite(c) && is_finite(p) && reach <= kEmbreeRayLimit) {
        q.x = p.x, q.y = p.y, q.z = p.z;
        q.radius = query_radius(state, region.radius2);
        state.shrinks = true;
        return true;
      }
      const float r = float(std::sqrt(double(region.radius2) * double(kRegionPad)) * (1 + 1e-6));
      b = std::isinf(r) ? m_bounds : Bounds3f{c - Vec3f{r, r, r}, c + Vec3f{r, r, r}};
    }
    Bounds3f scene = m_bounds;
    if (item) {  // the box in the instance's space, widened by the mapping's rounding
      b = penumbra::intersect(b, item->box);
      if (!(b.lo.x <= b.hi.x && b.lo.y <= b.hi.y && b.lo.z <= b.hi.z)) return false;
      const float pad = float(item->rounding.at(max_component(max(abs(b.lo), abs(b.hi)))));
      b = transform_bounds(item->map, b);
      b = {b.lo - Vec3f{pad, pad, pad}, b.hi + Vec3f{pad, pad, pad}};
      scene = m_mesh_regions[m_layout.meshes[item->instance]].box;
    }
    b = penumbra::intersect(b, scene);
    if (!(b.lo.x <= b.hi.x && b.lo.y <= b.hi.y && b.lo.z <= b.hi.z)) return false;  // also NaN
    const Vec3f c = b.center();
    double r2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = std::max(double(c[k]) - b.lo[k], double(b.hi[k]) - c[k]);
      r2 += d * d;
    }
    q.x = c.x, q.y = c.y, q.z = c.z;
    const double r = std::sqrt(r2) * (1 + 1e-5);
    q.radius = float(item ? r : r * m_query_scale + m_query_rounding.at(max_component(abs(c))));
    return true;
  }

  /// The part of visit_region() for one RegionItem whose box meets the region.
  void visit_item(const RegionItem& item, QueryRegion& region, RegionVisitor& visitor) const {
    if (!region_meets(region, item.box)) return;
    const MeshRegion& mesh = m_mesh_regions[m_layout.meshes[item.instance]];
    if (item.kind == RegionItem::Nested) {
      PointQueryState state{this, &region, &visitor, &item, 0, false};
      RTCPointQuery query;
      if (!mesh.object || !point_query(state, query)) return;
      RTCPointQueryContext context;
      rtcInitPointQueryContext(&context);
      rtcPointQuery(mesh.object, &query, &context, &EmbreeAccelerator::offer_point_query, &state);
      return;
    }
    if (item.kind == RegionItem::Moving || mesh.vertices.empty()) {
      for (uint32_t p = 0; p < mesh.prims && region_meets(region, item.box); ++p)
        visitor.visit(item.instance, p, region);
      return;
    }
    for (uint32_t p = 0; p < mesh.prims; ++p) {
      Bounds3f b;
      for (const float* v : mesh.vertices)
        for (size_t k = 0; k < 3; ++k) {
          const float* x = v + 3 * size_t(mesh.indices[3 * size_t(p) + k]);
          b = merge(b, Vec3f{x[0], x[1], x[2]});
        }
      if (item.placed) {
        b = transform_bounds(item.map, b);
        b = {b.lo - Vec3f{item.pad, item.pad, item.pad}, b.hi + Vec3f{item.pad, item.pad, item.pad}};
      }
      if (region_meets(region, b)) visitor.visit(item.instance, p, region);
    }
  }

  /// m_mesh_regions from the views (before any geometry is attached).
  void note_mesh_regions(std::span<const GeometryView> meshes) {
    m_mesh_regions.assign(meshes.size(), MeshRegion{});
    for (size_t g = 0; g < meshes.size(); ++g) {
      const GeometryView& view = meshes[g];
      MeshRegion& mesh = m_mesh_regions[g];
      if (view.shape) {
        const Bounds3f b = shape_bounds(*view.shape);
        if (!b.empty() && is_finite(b.lo) && is_finite(b.hi)) mesh.prims = 1, mesh.box = b;
        continue;
      }
      if (view.curves != CurveKind::None) {
        if (view.radii.size() < view.positions.size() || view.curve_count() == 0) continue;
        mesh.prims = uint32_t(view.curve_count());
        for (size_t i = 0; i < view.curve_count(); ++i) {
          const Bounds3f b = shape_bounds(curve_element(view, i));
          if (!b.empty() && is_finite(b.lo) && is_finite(b.hi)) mesh.box = merge(mesh.box, b);
        }
        continue;
      }
      const size_t triangles = view.indices.size() / 3;
      if (view.positions.empty() || triangles == 0) continue;
      mesh.prims = uint32_t(triangles);
      if (view.deforms()) mesh.steps = view.motion_steps;
      for (const Vec3f p : view.deforms() ? view.motion_positions : view.positions)
        if (is_finite(p)) mesh.box = merge(mesh.box, p);
    }
  }

  /// Keeps the buffers of a deforming mesh's first Embree geometry (`id` in `scene`), which
  /// visit_item() reads (the scene keeps the geometry alive).
  void keep_buffers(RTCScene scene, unsigned id, uint32_t mesh) {
    MeshRegion& m = m_mesh_regions[mesh];
    if (m.steps == 0 || m.prims == 0 || !m.vertices.empty()) return;
    RTCGeometry geom = rtcGetGeometry(scene, id);
    m.indices = static_cast<const uint32_t*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_INDEX, 0));
    for (unsigned k = 0; k < m.steps; ++k)
      m.vertices.push_back(
          static_cast<const float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, k)));
    throw_if_error("reading a deforming mesh's buffers");
  }

  /// The RegionItem of instance `i` under its current placement `inst`, if it needs one; else
  /// widens m_query_scale and m_query_rounding for Embree's query inside it (placed instances).
  bool region_item(uint32_t i, const InstanceView& inst, RegionItem& item) {
    const MeshRegion& mesh = m_mesh_regions[m_layout.meshes[i]];
    const InstanceKind kind = m_layout.kinds[i];
    if (kind == InstanceKind::Singular || mesh.prims == 0) return false;
    item.instance = i;
    if (kind == InstanceKind::Identity) {
      item.kind = RegionItem::Deforming;
      item.box = mesh.box;
      return mesh.steps > 0;
    }
    if (!inst.motion.empty()) {
      item.box = motion_bounds(inst.motion, mesh.box);
      return true;
    }
    Affine3f to_object;
    if (!inverse(inst.to_world, to_object)) return false;
    if (mesh.steps > 0) {
      item.kind = RegionItem::Deforming;
      item.placed = true;
      item.map = inst.to_world;
      item.rounding = map_rounding(inst.to_world);
      item.pad = float(item.rounding.at(max_component(max(abs(mesh.box.lo), abs(mesh.box.hi)))));
      const Bounds3f b = transform_bounds(inst.to_world, mesh.box);
      item.box = {b.lo - Vec3f{item.pad, item.pad, item.pad}, b.hi + Vec3f{item.pad, item.pad, item.pad}};
      return true;
    }
    const double scale = similarity_radius_scale(to_object);
    if (scale > kMaxQueryScale) {
      item.kind = RegionItem::Nested;
      item.map = to_object;
      item.stretch = std::sqrt(stretch2(to_object));
      item.rounding = map_rounding(to_object);
      item.box = transform_bounds(inst.to_world, mesh.box);
      return true;
    }
    m_query_scale = std::max(m_query_scale, scale * (1 + 1e-4));  // with room for Embree's rounding
    // Embree maps the query point into the instance with an error within map_rounding(to_object),
    // which to_world stretches by at most sqrt(stretch2(to_world)) back in world units.
    const double stretch = std::sqrt(stretch2(inst.to_world));
    const MapRounding r = map_rounding(to_object);
    m_query_rounding.per_unit = std::max(m_query_rounding.per_unit, stretch * r.per_unit);
    m_query_rounding.offset = std::max(m_query_rounding.offset, stretch * r.offset);
    return false;
  }

  /// m_region_items and their BVH, m_query_scale and m_query_rounding for the instances'
  /// current placements. An item whose world box is not finite (its mesh mapped past the float
  /// range) is left out.
  void index_regions(std::span<const InstanceView> instances) {
    m_query_scale = 1;
    m_query_rounding = {};
    std::vector<RegionItem> items;
    for (uint32_t i = 0; i < instances.size(); ++i)
      if (RegionItem item; region_item(i, instances[i], item)) {
        item.box = widen_for_rounding(item.box);  // as rounding may place a mapped point outside
        items.push_back(item);
      }
    m_region_items.clear();
    m_region_nodes.clear();
    std::vector<BvhBuildRef> refs;
    for (uint32_t i = 0; i < items.size(); ++i)
      if (!items[i].box.empty() && is_finite(items[i].box.lo) && is_finite(items[i].box.hi))
        refs.emplace_back(items[i].box, i);
    if (refs.empty()) return;
    BvhConfig config;
    config.max_leaf_size = 1;  // an item may cost a whole query of its own
    const auto root = build_bvh_tree(refs, config);
    for (const BvhBuildRef& r : refs) m_region_items.push_back(items[r.index]);
    flatten_bvh(*root, m_region_nodes);
  }

  /// The instance index a hit reports as geom_id, from Embree's geometry and instance ids.
  uint32_t instance_of(unsigned geom_id, unsigned inst_id) const {
    return inst_id == RTC_INVALID_GEOMETRY_ID ? geom_id
           : inst_id == m_world_id            ? m_world_ids[geom_id]
                                              : inst_id;
  }

  bool closest(const Ray& ray, Hit& hit, RTCIntersectContext& ctx, TraceRay::Units* units = nullptr) const {
    hit = Hit{};
    if (!is_valid_query(ray)) return false;
    const TraceRay trace = traceable(ray);
    if (!trace.ok) return false;
    if (units) *units = trace.units;
    assert(embree_safe(trace.ray));  // what Embree's traversal asserts, checked here first
    RTCRayHit rh;
    fill_ray(trace.ray, rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m_scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit.t = std::min(trace.units.query_t(rh.ray.tfar), ray.tfar);
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
    hit.geom_id = instance_of(rh.hit.geomID, rh.hit.instID[0]);
    hit.prim_id = rh.hit.primID;
    return true;
  }

  bool any_hit(const Ray& ray, RTCIntersectContext& ctx, TraceRay::Units* units = nullptr) const {
    if (!is_valid_query(ray)) return false;
    const TraceRay trace = traceable(ray);
    if (!trace.ok) return false;
    if (units) *units = trace.units;
    assert(embree_safe(trace.ray));
    RTCRay r;
    fill_ray(trace.ray, r);
    rtcOccluded1(m_scene, &ctx, &r);
    return r.tfar < 0;  // Embree sets tfar = -inf on occlusion
  }

  /// An Embree instance of `object` placed by `to_world`, attached to the top scene as `id`; a
  /// moving one (`motion` not empty) gets one time step per key, each as Embree's quaternion
  /// decomposition (which Embree slerps between steps as interpolate_motion does).
  void attach_instance(RTCScene object, const Affine3f& to_world, unsigned id,
                       std::span<const MotionKey> motion = {}) {
    RTCGeometry geom = rtcNewGeometry(device(), RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(geom, object);
    set_instance_motion(geom, to_world, motion);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(m_scene, geom, id);
    rtcReleaseGeometry(geom);
    throw_if_error("attaching an instance");
  }

  /// The instance geometry's transform: one step, or one quaternion decomposition per key.
  static void set_instance_motion(RTCGeometry geom, const Affine3f& to_world,
                                  std::span<const MotionKey> motion) {
    if (motion.empty()) {
      rtcSetGeometryTimeStepCount(geom, 1);
      rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &to_world.m[0][0]);
      return;
    }
    rtcSetGeometryTimeStepCount(geom, unsigned(motion.size()));
    for (size_t k = 0; k < motion.size(); ++k) {
      const MotionKey& key = motion[k];
      RTCQuaternionDecomposition q;
      rtcInitQuaternionDecomposition(&q);
      q.scale_x = key.u[0];
      q.skew_xy = key.u[1];
      q.skew_xz = key.u[2];
      q.scale_y = key.u[3];
      q.skew_yz = key.u[4];
      q.scale_z = key.u[5];
      q.translation_x = key.translation.x;
      q.translation_y = key.translation.y;
      q.translation_z = key.translation.z;
      q.quaternion_r = float(key.rotation.w);
      q.quaternion_i = float(key.rotation.x);
      q.quaternion_j = float(key.rotation.y);
      q.quaternion_k = float(key.rotation.z);
      rtcSetGeometryTransformQuaternion(geom, unsigned(k), &q);
    }
  }

  /// note_inverse() of the instance's map, or of every key's map for a moving instance.
  void note_inverses(const InstanceView& inst) {
    Affine3f inverse_map;
    if (inst.motion.empty()) {
      if (inverse(inst.to_world, inverse_map)) note_inverse(inverse_map);
      return;
    }
    for (const MotionKey& k : inst.motion)
      if (inverse(compose_motion(k), inverse_map)) note_inverse(inverse_map);
  }

  /// m_bounds from the committed top scene (empty without triangles or shapes).
  void read_bounds() {
    RTCBounds b;
    rtcGetSceneBounds(m_scene, &b);
    m_bounds = Bounds3f{};
    if (m_triangles + m_shapes.size() + m_curve_count > 0)
      m_bounds = {{b.lower_x, b.lower_y, b.lower_z}, {b.upper_x, b.upper_y, b.upper_z}};
  }

  /// Attaches a view as triangles, or its shape (copied) as user geometry.
  void attach_geometry(RTCScene scene, const GeometryView& view, unsigned id) {
    if (view.curves != CurveKind::None && !view.shape) {
      if (view.radii.size() < view.positions.size() || view.curve_count() == 0) {
        attach_triangles(scene, GeometryView{}, id);
        return;
      }
      auto elements = std::make_unique<std::vector<Shape>>();
      elements->reserve(view.curve_count());
      for (size_t i = 0; i < view.curve_count(); ++i) elements->push_back(curve_element(view, i));
      m_curve_count += elements->size();
      attach_shapes(scene, elements->data(), elements->size(), id);
      m_curve_sets.push_back(std::move(elements));
      return;
    }
    if (!view.shape) {
      attach_triangles(scene, view, id);
      m_triangles += view.indices.size() / 3;
      return;
    }
    m_shapes.push_back(std::make_unique<Shape>(*view.shape));
    const Bounds3f b = shape_bounds(*m_shapes.back());
    if (b.empty() || !is_finite(b.lo) || !is_finite(b.hi)) {
      attach_triangles(scene, GeometryView{}, id);
      return;
    }
    attach_shapes(scene, m_shapes.back().get(), 1, id);
  }

  /// Adds a placed instance's world-to-object map to the reach of Embree's instanced rays.
  void note_inverse(const Affine3f& to_object) {
    for (int r = 0; r < 3; ++r) {
      double row = 0;
      for (int c = 0; c < 3; ++c) row += std::fabs(double(to_object.m[size_t(r)][size_t(c)]));
      m_inverse_scale = std::max(m_inverse_scale, row);
      m_inverse_offset = std::max(m_inverse_offset, std::fabs(double(to_object.m[size_t(r)][3])));
    }
  }

  /// True when every object-space version of `r` (each instance's to_object applied to it, and
  /// the world ray itself) has origin and direction coordinates within kEmbreeRayLimit.
  bool embree_safe(const Ray& r) const {
    const double org = max_component(abs(r.org)), dir = max_component(abs(r.dir));
    return m_inverse_scale * org + m_inverse_offset <= kEmbreeRayLimit &&
           m_inverse_scale * dir <= kEmbreeRayLimit;
  }

  /// `ray` as Embree may be given it. Embree asserts (and aborts the process) when a ray it
  /// traverses, an instance's object-space ray included, has a coordinate beyond 1.8e18
  /// (FLT_LARGE): an origin far from the scene, or an instance scaled by 1e-16, gets there.
  /// Every ordinary ray is passed as it is; one that would not be is restarted where it enters
  /// the scene's bounds with a unit direction (t mapped back by `units`), and one that still
  /// would not be (or that misses the bounds) is not traced: it misses.
  TraceRay traceable(const Ray& ray) const {
    TraceRay out;
    out.ray = ray;
    if (embree_safe(ray)) return out;
    out.ok = false;
    if (m_bounds.empty()) return out;
    const double len = std::sqrt(double(ray.dir.x) * ray.dir.x + double(ray.dir.y) * ray.dir.y +
                                 double(ray.dir.z) * ray.dir.z);
    if (!(len > 0) || !std::isfinite(len)) return out;
    // The unit ray's interval inside the bounds (slabs in double precision).
    double t0 = std::max(double(ray.tnear), 0.0) * len, t1 = double(ray.tfar) * len;
    for (int k = 0; k < 3; ++k) {
      const double o = ray.org[k], d = ray.dir[k] / len;
      const double lo = m_bounds.lo[k], hi = m_bounds.hi[k];
      if (d == 0) {
        if (o < lo || o > hi) return out;
        continue;
      }
      double a = (lo - o) / d, b = (hi - o) / d;
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
    if (!(t0 <= t1)) return out;
    // Start a little before the entry, so that a surface on the bounds is still in range: by a
    // share of the path through the bounds, and by more than the rounding of the new origin.
    const double extent = std::max(max_component(abs(m_bounds.lo)), max_component(abs(m_bounds.hi)));
    const double margin = std::max(1e-3 * (t1 - t0), 1e-5 * extent);
    const double start = std::max(std::max(double(ray.tnear), 0.0) * len, t0 - margin);
    Ray r;
    for (int k = 0; k < 3; ++k) {
      r.dir[k] = float(ray.dir[k] / len);
      r.org[k] = float(ray.org[k] + r.dir[k] * start);
    }
    r.tnear = float(std::max(double(ray.tnear) * len - start, 0.0));
    // Rounded down, so that no hit lies beyond the query's tfar.
    r.tfar =
        std::isinf(ray.tfar) ? ray.tfar : std::nextafter(float(double(ray.tfar) * len - start), -kInfinity);
    if (!embree_safe(r) || !(r.tnear <= r.tfar)) return out;
    out.ray = r;
    out.units = {start, 1 / len};
    out.ok = true;
    return out;
  }

  static void fill_ray(const Ray& in, RTCRay& r) {
    r.org_x = in.org.x;
    r.org_y = in.org.y;
    r.org_z = in.org.z;
    r.tnear = std::max(in.tnear, 0.0f);
    r.dir_x = in.dir.x;
    r.dir_y = in.dir.y;
    r.dir_z = in.dir.z;
    r.time = in.time;
    r.tfar = in.tfar;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
  }

  /// A new scene with the configured flags and build quality (objects and the top level alike).
  RTCScene new_scene() const {
    RTCScene scene = rtcNewScene(device());
    throw_if_error("rtcNewScene");
    // Every scene, instanced ones included, runs the context's filter when a query sets one.
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION |
                                (m_config.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE));
    const RTCBuildQuality quality[] = {RTC_BUILD_QUALITY_LOW, RTC_BUILD_QUALITY_MEDIUM,
                                       RTC_BUILD_QUALITY_HIGH};
    rtcSetSceneBuildQuality(scene, quality[m_config.quality]);
    return scene;
  }

  EmbreeConfig m_config;
  RTCScene m_scene = nullptr;
  std::vector<RTCScene> m_objects;                // per-geometry scenes of the instances (and the world's)
  unsigned m_world_id = RTC_INVALID_GEOMETRY_ID;  // the world scene's instance in the top scene, if any
  std::vector<uint32_t> m_world_ids;              // world scene geometry id -> instance index
  std::vector<std::unique_ptr<Shape>> m_shapes;   // the user geometries' shapes (stable addresses)
  std::vector<std::unique_ptr<std::vector<Shape>>> m_curve_sets;  // curve sets' elements, likewise
  uint64_t m_curve_count = 0;                                     // elements of the curve sets
  InstanceLayout m_layout;                                        // every instance's mesh and kind, as built
  std::vector<MeshRegion> m_mesh_regions;                         // per view: what region queries need of it
  std::vector<RegionItem> m_region_items;  // instances Embree's query may miss, in BVH leaf order
  std::vector<BvhNode> m_region_nodes;     // BVH over their world boxes (index_regions)
  double m_query_scale = 1;                // Embree's query radius per ball radius (similarity_radius_scale)
  MapRounding m_query_rounding;            // Embree's mapping of the point into instances, in world units
  Bounds3f m_bounds;
  double m_inverse_scale = 1;   // largest row sum of |to_object| over placed instances (1: the world)
  double m_inverse_offset = 0;  // largest |translation| of a placed instance's to_object
  uint64_t m_triangles = 0;
  uint64_t m_instances = 0;
  uint64_t m_bytes = 0;
  double m_build_seconds = 0;
};

}  // namespace

void validate(const EmbreeConfig& c) {
  if (c.quality < 0 || c.quality > 2)
    throw std::invalid_argument("embree: quality must be 0 (low), 1 (medium) or 2 (high), got " +
                                std::to_string(c.quality));
}

std::unique_ptr<Accelerator> make_embree_accelerator(std::span<const GeometryView> meshes,
                                                     const EmbreeConfig& config) {
  std::vector<InstanceView> instances(meshes.size());
  for (size_t i = 0; i < meshes.size(); ++i) instances[i].mesh = uint32_t(i);
  return std::make_unique<EmbreeAccelerator>(meshes, instances, config);
}

std::unique_ptr<Accelerator> make_embree_accelerator(std::span<const GeometryView> meshes,
                                                     std::span<const InstanceView> instances,
                                                     const EmbreeConfig& config) {
  return std::make_unique<EmbreeAccelerator>(meshes, instances, config);
}

namespace {

void box_bounds(const RTCBoundsFunctionArguments* args) {
  const Bounds3f& b = static_cast<const Bounds3f*>(args->geometryUserPtr)[args->primID];
  *args->bounds_o = {b.lo.x, b.lo.y, b.lo.z, 0, b.hi.x, b.hi.y, b.hi.z, 0};
}

// A scene of one user geometry whose primitives are the boxes (kept alive by the caller).
RTCScene box_scene(std::span<const Bounds3f> boxes) {
  RTCScene scene = rtcNewScene(device());
  RTCGeometry geom = rtcNewGeometry(device(), RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geom, unsigned(boxes.size()));
  rtcSetGeometryUserData(geom, const_cast<Bounds3f*>(boxes.data()));
  rtcSetGeometryBoundsFunction(geom, box_bounds, nullptr);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  return scene;
}

struct CollideResult {
  std::mutex mutex;
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
};

void collect(void* user, RTCCollision* collisions, unsigned count) {
  auto* r = static_cast<CollideResult*>(user);
  std::lock_guard<std::mutex> lock(r->mutex);
  for (unsigned i = 0; i < count; ++i) r->pairs.push_back({collisions[i].primID0, collisions[i].primID1});
}

}  // namespace

std::vector<std::pair<uint32_t, uint32_t>> embree_collide(std::span<const Bounds3f> boxes_a,
                                                          std::span<const Bounds3f> boxes_b) {
  if (boxes_a.empty() || boxes_b.empty()) return {};
  RTCScene a = box_scene(boxes_a), b = box_scene(boxes_b);
  CollideResult result;
  rtcCollide(a, b, collect, &result);
  const RTCError error = rtcGetDeviceError(device());
  rtcReleaseScene(a);
  rtcReleaseScene(b);
  if (error != RTC_ERROR_NONE)
    throw std::runtime_error("embree: rtcCollide failed (error " + std::to_string(int(error)) + ")");
  std::sort(result.pairs.begin(), result.pairs.end());
  result.pairs.erase(std::unique(result.pairs.begin(), result.pairs.end()), result.pairs.end());
  return std::move(result.pairs);
}

std::string embree_version() {
  const auto v = rtcGetDeviceProperty(device(), RTC_DEVICE_PROPERTY_VERSION);
  return std::to_string(v / 10000) + "." + std::to_string((v / 100) % 100) + "." + std::to_string(v % 100);
}

}  // namespace penumbra
