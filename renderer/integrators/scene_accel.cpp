// Scene to accelerator views.
#include "renderer/integrators/scene_accel.h"

namespace penumbra {

std::vector<GeometryView> mesh_views(const Scene& scene) {
  std::vector<GeometryView> views;
  views.reserve(scene.meshes.size() + scene.shapes.size());
  for (const auto& m : scene.meshes) {
    views.push_back({m.positions, m.indices});
    if (renders_as_curves(m)) {
      views.back().curves = m.points ? CurveKind::Points : CurveKind::Segments;
      views.back().radii = m.radii;
    }
    if (m.motion_steps >= 2) {
      views.back().motion_positions = m.motion_positions;
      views.back().motion_steps = m.motion_steps;
    }
  }
  for (const auto& s : scene.shapes) views.push_back({{}, {}, &s.shape});
  return views;
}

std::vector<InstanceView> instance_views(const Scene& scene) {
  std::vector<InstanceView> views;
  views.reserve(scene.instances.size());
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    const size_t geometry = inst.shape >= 0 ? scene.meshes.size() + size_t(inst.shape) : size_t(inst.mesh);
    views.push_back({uint32_t(geometry), inst.to_world});
    if (i < scene.instance_motion.size()) views.back().motion = scene.instance_motion[i];
  }
  return views;
}

SplatGeometry splat_geometry(const Scene& scene) {
  SplatGeometry g;
  g.shapes.resize(scene.splat_clouds.size());
  for (size_t c = 0; c < scene.splat_clouds.size(); ++c) {
    const SplatCloud& cloud = scene.splat_clouds[c];
    g.shapes[c].reserve(cloud.positions.size());
    for (size_t i = 0; i < cloud.positions.size(); ++i)
      g.shapes[c].push_back(splat_shape(cloud, i, uint32_t(i)));
  }
  for (const auto& shapes : g.shapes) {
    GeometryView v;
    v.curves = CurveKind::Shapes;
    v.elements = shapes;
    g.views.push_back(v);
  }
  for (const SplatInstance& inst : scene.splat_instances)
    g.instances.push_back({uint32_t(inst.cloud), inst.to_world});
  return g;
}

namespace {
// The surfaces' structure with the splats' beside it; every Accelerator call is the surfaces'.
class SceneAccelerator final : public Accelerator {
 public:
  SceneAccelerator(std::unique_ptr<Accelerator> surfaces, std::unique_ptr<SplatGeometry> geometry,
                   std::unique_ptr<Accelerator> splats)
      : m_surfaces(std::move(surfaces)), m_geometry(std::move(geometry)), m_splats(std::move(splats)) {}

  bool intersect(const Ray& ray, Hit& hit) const override { return m_surfaces->intersect(ray, hit); }
  bool occluded(const Ray& ray) const override { return m_surfaces->occluded(ray); }
  bool intersect(const Ray& ray, Hit& hit, const HitFilter& filter) const override {
    return m_surfaces->intersect(ray, hit, filter);
  }
  bool occluded(const Ray& ray, const HitFilter& filter) const override {
    return m_surfaces->occluded(ray, filter);
  }
  bool intersect_counted(const Ray& ray, Hit& hit, TraversalCost& cost) const override {
    return m_surfaces->intersect_counted(ray, hit, cost);
  }
  bool counts_traversal() const override { return m_surfaces->counts_traversal(); }
  void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const override {
    m_surfaces->visit_region(region, visitor, cost);
  }
  Bounds3f bounds() const override { return m_surfaces->bounds(); }
  AccelStats stats() const override { return m_surfaces->stats(); }
  bool update_instances(std::span<const InstanceView> instances) override {
    return m_surfaces->update_instances(instances);
  }
  bool refit(std::span<const GeometryView> views) override { return m_surfaces->refit(views); }
  bool refit_instances(std::span<const GeometryView> meshes,
                       std::span<const InstanceView> instances) override {
    return m_surfaces->refit_instances(meshes, instances);
  }

  const Accelerator& splats() const { return *m_splats; }
  std::unique_ptr<Accelerator>& surfaces() { return m_surfaces; }

 private:
  std::unique_ptr<Accelerator> m_surfaces;
  std::unique_ptr<SplatGeometry> m_geometry;  // what a brute-force splat structure reads
  std::unique_ptr<Accelerator> m_splats;
};
}  // namespace

namespace {
// The surfaces' structure, with a structure over the scene's splats beside it when it has any.
std::unique_ptr<Accelerator> attach_splats(std::unique_ptr<Accelerator> surfaces, std::string_view name,
                                           const Scene& scene, const AccelConfig& config) {
  if (scene.splat_instances.empty()) return surfaces;
  auto geometry = std::make_unique<SplatGeometry>(splat_geometry(scene));
  std::unique_ptr<Accelerator> splats = make_accelerator(name, geometry->views, geometry->instances, config);
  return std::make_unique<SceneAccelerator>(std::move(surfaces), std::move(geometry), std::move(splats));
}
}  // namespace

std::unique_ptr<Accelerator> make_scene_accelerator(std::string_view name, const Scene& scene,
                                                    const AccelConfig& config) {
  return attach_splats(make_accelerator(name, mesh_views(scene), instance_views(scene), config), name, scene,
                       config);
}

const Accelerator* splat_accelerator(const Accelerator& accel) {
  const auto* s = dynamic_cast<const SceneAccelerator*>(&accel);
  return s ? &s->splats() : nullptr;
}

RefitReport refit_or_rebuild_scene(std::unique_ptr<Accelerator>& accel, double& built_sah,
                                   std::string_view name, const Scene& scene, const AccelConfig& config) {
  // The surfaces refitted or rebuilt by the policy; the splats' structure built anew over the
  // scene's splats as they now are (a scene loaded anew may have moved or changed them).
  if (auto* s = dynamic_cast<SceneAccelerator*>(accel.get())) {
    std::unique_ptr<Accelerator> surfaces = std::move(s->surfaces());
    accel = std::move(surfaces);
  }
  const RefitReport r =
      refit_or_rebuild(accel, built_sah, name, mesh_views(scene), instance_views(scene), config);
  accel = attach_splats(std::move(accel), name, scene, config);
  return r;
}

}  // namespace penumbra
