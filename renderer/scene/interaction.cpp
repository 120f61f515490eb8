// Hit -> surface reconstruction and ray-differential footprints.
#include "renderer/scene/interaction.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

namespace {

// The ray in the instance's object space (same parameterisation: the direction is mapped, not
// normalised).
Ray to_object_ray(const Instance& inst, const Ray& ray) {
  if (inst.identity) return ray;
  Ray r = ray;
  r.org = apply_point(inst.to_object, ray.org);
  r.dir = apply_vector(inst.to_object, ray.dir);
  return r;
}

// Object-space hit point on the shape, and the world-space tolerance of where it lies.
Vec3f shape_hit_point(const SceneShape& ss, const Instance& inst, const Ray& ray, float t, float& world_tol) {
  const Ray r = to_object_ray(inst, ray);
  const float obj_len = length(r.dir), world_len = length(ray.dir);
  const float tol = shape_hit_tolerance(ss.shape, t, obj_len);
  world_tol = obj_len > 0 ? tol * (world_len / obj_len) : 0;
  return snap_to_shape(ss.shape, r.org + r.dir * t);
}

// Central-difference step for implicit normals: a few hit tolerances, at least 1e-5 of the size.
float normal_step(const Shape& shape, float tol) {
  const Bounds3f b = shape_bounds(shape);
  const float size = b.empty() ? 1.0f : max_component(b.extent());
  return std::max(4 * tol, 1e-5f * size);
}

SurfaceInteraction make_shape_interaction(const Scene& scene, const Instance& inst, const Ray& ray,
                                          const Hit& hit) {
  const SceneShape& ss = scene.shapes[size_t(inst.shape)];
  SurfaceInteraction si;
  si.instance = hit.geom_id;
  si.time = ray.time;
  si.shape = inst.shape;
  si.material = ss.material;
  float world_tol = 0;
  const Vec3f p = shape_hit_point(ss, inst, ray, hit.t, world_tol);
  const Ray obj = to_object_ray(inst, ray);
  const ShapeSurface surf = shape_surface(
      ss.shape, p, normal_step(ss.shape, shape_hit_tolerance(ss.shape, hit.t, length(obj.dir))));
  si.p = inst.identity ? p : apply_point(inst.to_world, p);
  Vec3f n = world_normal(inst, surf.n);
  if (!(dot(n, n) > 0) || !is_finite(n)) n = normalize(-ray.dir);
  si.uv[0] = si.uv[1] = surf.uv;
  // Spawned rays start beyond the tracer's tolerance, and beyond the rounding of mapping the
  // point through the instance and back (a few float ulps of the point and the shape's size):
  // a ray leaving a sphere at a grazing angle from just inside would meet its far side at once.
  // Flat shapes and boxes are snapped onto their planes exactly: only the point's magnitude counts.
  const Bounds3f b = shape_bounds(ss.shape);
  const float obj_len = length(obj.dir), scale = obj_len > 0 ? length(ray.dir) / obj_len : 1.0f;
  const bool curved = ss.shape.kind == ShapeKind::Sphere || ss.shape.kind == ShapeKind::Capsule ||
                      ss.shape.kind == ShapeKind::Implicit;
  const float size = !curved || b.empty() ? 0.0f : max_component(b.extent()) * scale;
  si.spawn_offset = std::max(4 * world_tol, 64 * 0x1p-23f * (max_component(abs(si.p)) + size));
  si.back_face = dot(n, ray.dir) > 0;
  if (si.back_face) n = -n;
  si.ng = si.ns = n;
  return si;
}

// Element `prim` of a rendered point or line set as the Segment shape the structures test.
Shape curve_shape(const Mesh& mesh, uint32_t prim) {
  const uint32_t a = mesh.indices[3 * size_t(prim)], b = mesh.indices[3 * size_t(prim) + 1];
  const float r = mesh.points ? mesh.radii[a] : 0.5f * (mesh.radii[a] + mesh.radii[b]);
  return make_segment_shape(mesh.positions[a], mesh.points ? mesh.positions[a] : mesh.positions[b], r, prim);
}

// A hit on a point's sphere or a segment's capsule: the capsule's normal, the vertex data
// interpolated along the segment at the nearest axis point (a point's own), no tangents.
SurfaceInteraction make_curve_interaction(const Scene& scene, const Instance& inst, const Ray& ray,
                                          const Hit& hit, const WorldTriangle& tri) {
  const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
  const Shape shape = curve_shape(mesh, hit.prim_id);
  SurfaceInteraction si;
  si.instance = hit.geom_id;
  si.time = ray.time;
  si.mesh = uint32_t(inst.mesh);
  si.prim = hit.prim_id;
  si.tri = tri;
  si.material = mesh.material;
  const Ray obj = to_object_ray(inst, ray);
  // A hit from a drawn stand-in (the raster preview's quads and polygons lie on the element's
  // front) moves onto the exact surface where the ray meets it within a diameter.
  float t = hit.t;
  Ray probe = obj;
  probe.tnear = 0;
  probe.tfar = kInfinity;
  ShapeHit exact;
  const float reach = 2 * shape.radius / std::max(length(obj.dir), 1e-30f);
  if (intersect_shape(shape, probe, exact) && std::fabs(exact.t - t) <= reach) t = exact.t;
  const Vec3f p = snap_to_shape(shape, obj.org + obj.dir * t);
  const ShapeSurface surf = shape_surface(shape, p, 1e-4f);
  si.p = inst.identity ? p : apply_point(inst.to_world, p);
  Vec3f n = world_normal(inst, surf.n);
  if (!(dot(n, n) > 0) || !is_finite(n)) n = normalize(-ray.dir);
  const uint32_t a = tri.index[0], b = tri.index[1];
  const float s = mesh.points ? 0.0f : surf.uv.x, w = 1 - s;
  auto lerp2 = [&](const std::vector<Vec2f>& uv) -> Vec2f {
    return {uv[a].x * w + uv[b].x * s, uv[a].y * w + uv[b].y * s};
  };
  if (mesh.uvs.size() == mesh.positions.size()) si.uv[0] = lerp2(mesh.uvs);
  if (mesh.uvs1.size() == mesh.positions.size()) si.uv[1] = lerp2(mesh.uvs1);
  if (mesh.colors.size() == mesh.positions.size()) {
    const Vec4f ca = mesh.colors[a], cb = mesh.colors[b];
    si.color = {ca.x * w + cb.x * s, ca.y * w + cb.y * s, ca.z * w + cb.z * s, ca.w * w + cb.w * s};
  }
  // Rounding of the point and of the capsule's radius (not its length: a long thin segment's
  // offset stays well inside its radius).
  const float obj_len = length(obj.dir), scale = obj_len > 0 ? length(ray.dir) / obj_len : 1.0f;
  si.spawn_offset = 64 * 0x1p-23f * (max_component(abs(si.p)) + 2 * shape.radius * scale);
  si.back_face = dot(n, ray.dir) > 0;
  if (si.back_face) n = -n;
  si.ng = si.ns = n;
  return si;
}

void shape_differentials(const Scene& scene, SurfaceInteraction& si) {
  Instance posed;
  const Instance& inst = instance_at(scene, si.instance, si.time, posed);
  const Shape& shape = scene.shapes[size_t(si.shape)].shape;
  const auto to_obj = [&](Vec3f q) { return inst.identity ? q : apply_point(inst.to_object, q); };
  const Vec3f p = to_obj(si.p);
  const Vec2f uv = shape_surface(shape, p, 1e-4f).uv;
  const Vec2f ux = shape_surface(shape, to_obj(si.p + si.dpdx), 1e-4f).uv;
  const Vec2f uy = shape_surface(shape, to_obj(si.p + si.dpdy), 1e-4f).uv;
  si.duvdx[0] = si.duvdx[1] = shape_uv_delta(shape, uv, ux);
  si.duvdy[0] = si.duvdy[1] = shape_uv_delta(shape, uv, uy);
}

}  // namespace

Vec3f spawn_origin(const SurfaceInteraction& si, Vec3f dir) {
  const Vec3f o = offset_ray_origin(si.p, si.ng, dir);
  if (si.spawn_offset == 0) return o;
  return o + si.ng * (dot(si.ng, dir) >= 0 ? si.spawn_offset : -si.spawn_offset);
}

Vec3f hit_front_normal(const Scene& scene, const Ray& ray, const Hit& hit) {
  Instance posed;
  const Instance& inst = instance_at(scene, hit.geom_id, ray.time, posed);
  if (inst.shape < 0 && renders_as_curves(scene.meshes[size_t(inst.mesh)])) {
    const Shape shape = curve_shape(scene.meshes[size_t(inst.mesh)], hit.prim_id);
    const Ray obj = to_object_ray(inst, ray);
    return normalize(world_normal(inst, shape_surface(shape, obj.org + obj.dir * hit.t, 1e-4f).n));
  }
  if (inst.shape < 0) return world_triangle(scene, inst, hit.prim_id, ray.time).ng;
  const SceneShape& ss = scene.shapes[size_t(inst.shape)];
  float world_tol = 0;
  const Vec3f p = shape_hit_point(ss, inst, ray, hit.t, world_tol);
  const float tol = shape_hit_tolerance(ss.shape, hit.t, length(to_object_ray(inst, ray).dir));
  return normalize(world_normal(inst, shape_surface(ss.shape, p, normal_step(ss.shape, tol)).n));
}

SurfaceInteraction make_interaction(const Scene& scene, const Ray& ray, const Hit& hit) {
  Instance posed;
  const Instance& inst = instance_at(scene, hit.geom_id, ray.time, posed);
  if (inst.shape >= 0) return make_shape_interaction(scene, inst, ray, hit);
  return make_interaction(scene, ray, hit, world_triangle(scene, inst, hit.prim_id, ray.time));
}

SurfaceInteraction make_interaction(const Scene& scene, const Ray& ray, const Hit& hit,
                                    const WorldTriangle& tri) {
  Instance posed;
  const Instance& inst = instance_at(scene, hit.geom_id, ray.time, posed);
  if (inst.shape >= 0) return make_shape_interaction(scene, inst, ray, hit);
  const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
  if (renders_as_curves(mesh)) return make_curve_interaction(scene, inst, ray, hit, tri);
  const uint32_t i0 = tri.index[0], i1 = tri.index[1], i2 = tri.index[2];
  const float w = 1.0f - hit.u - hit.v;
  SurfaceInteraction si;
  si.instance = hit.geom_id;
  si.time = ray.time;
  si.mesh = uint32_t(inst.mesh);
  si.prim = hit.prim_id;
  si.tri = tri;
  si.p = tri.p[0] * w + tri.p[1] * hit.u + tri.p[2] * hit.v;
  si.material = mesh.material;
  si.ng = tri.ng;
  if (!(dot(si.ng, si.ng) > 0)) si.ng = normalize(-ray.dir);
  Vec3f ns = si.ng;
  if (!mesh.normals.empty()) {
    const float t = ray.time;
    ns = normalize(world_normal(inst, mesh_normal(mesh, i0, t)) * w +
                   world_normal(inst, mesh_normal(mesh, i1, t)) * hit.u +
                   world_normal(inst, mesh_normal(mesh, i2, t)) * hit.v);
    if (!(dot(ns, ns) > 0)) ns = si.ng;
  }
  auto lerp2 = [&](const std::vector<Vec2f>& t) -> Vec2f {
    return {t[i0].x * w + t[i1].x * hit.u + t[i2].x * hit.v, t[i0].y * w + t[i1].y * hit.u + t[i2].y * hit.v};
  };
  auto lerp4 = [&](const std::vector<Vec4f>& t) -> Vec4f {
    return {t[i0].x * w + t[i1].x * hit.u + t[i2].x * hit.v, t[i0].y * w + t[i1].y * hit.u + t[i2].y * hit.v,
            t[i0].z * w + t[i1].z * hit.u + t[i2].z * hit.v, t[i0].w * w + t[i1].w * hit.u + t[i2].w * hit.v};
  };
  if (!mesh.uvs.empty()) si.uv[0] = lerp2(mesh.uvs);
  if (!mesh.uvs1.empty()) si.uv[1] = lerp2(mesh.uvs1);
  if (!mesh.colors.empty()) si.color = lerp4(mesh.colors);
  if (!mesh.tangents.empty()) {
    si.tangent = lerp4(mesh.tangents);
    // The bitangent sign is a sign, not an interpolant; a mirroring placement flips it.
    si.tangent.w = (mesh.tangents[i0].w < 0) != inst.mirrored ? -1.0f : 1.0f;
    if (!inst.identity) {
      const Vec3f t = normalize(apply_vector(inst.to_world, {si.tangent.x, si.tangent.y, si.tangent.z}));
      si.tangent = {t.x, t.y, t.z, si.tangent.w};
    }
  }
  // Face-forward: both normals towards the viewer, so back faces shade like front faces.
  si.back_face = dot(si.ng, ray.dir) > 0;
  if (si.back_face) {
    si.ng = -si.ng;
    ns = -ns;
  }
  if (dot(ns, si.ng) < 0) ns = si.ng;  // interpolated normal flipped by the geometry
  si.ns = ns;
  return si;
}

namespace {
// The derivatives of si's UVs and normal from those of its barycentrics (u, v) along x and y.
void barycentric_derivatives(const Scene& scene, SurfaceInteraction& si, Vec2f bx, Vec2f by);
}  // namespace

void compute_differentials(const Scene& scene, SurfaceInteraction& si, const RayDifferential& rd) {
  if (!rd.valid) return;
  // Offsets of the auxiliary rays' hits on the tangent plane through si.p.
  const float d = dot(si.ng, si.p);
  const float nx = dot(si.ng, rd.rx_dir), ny = dot(si.ng, rd.ry_dir);
  if (!(std::fabs(nx) > 1e-12f) || !(std::fabs(ny) > 1e-12f)) return;
  const float tx = (d - dot(si.ng, rd.rx_org)) / nx, ty = (d - dot(si.ng, rd.ry_org)) / ny;
  const Vec3f dpdx = rd.rx_org + rd.rx_dir * tx - si.p, dpdy = rd.ry_org + rd.ry_dir * ty - si.p;
  if (!is_finite(dpdx) || !is_finite(dpdy)) return;
  si.dpdx = dpdx;
  si.dpdy = dpdy;
  if (si.shape >= 0) {
    shape_differentials(scene, si);
    return;
  }
  // Barycentric derivatives: least-squares solve of dp = e1 db1 + e2 db2.
  const WorldTriangle& tri = si.tri;
  const Vec3f e1 = tri.p[1] - tri.p[0], e2 = tri.p[2] - tri.p[0];
  const float a11 = dot(e1, e1), a12 = dot(e1, e2), a22 = dot(e2, e2);
  const float det = a11 * a22 - a12 * a12;
  if (!(det > 0) || !std::isfinite(det)) return;
  auto solve = [&](Vec3f dp) -> Vec2f {
    const float r1 = dot(e1, dp), r2 = dot(e2, dp);
    return {(a22 * r1 - a12 * r2) / det, (a11 * r2 - a12 * r1) / det};
  };
  barycentric_derivatives(scene, si, solve(dpdx), solve(dpdy));
}

namespace {
void barycentric_derivatives(const Scene& scene, SurfaceInteraction& si, Vec2f bx, Vec2f by) {
  Instance posed;
  const Instance& inst = instance_at(scene, si.instance, si.time, posed);
  const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
  const WorldTriangle& tri = si.tri;
  const uint32_t i0 = tri.index[0], i1 = tri.index[1], i2 = tri.index[2];
  auto deriv2 = [&](const std::vector<Vec2f>& t, Vec2f db) -> Vec2f {
    const Vec2f d1{t[i1].x - t[i0].x, t[i1].y - t[i0].y}, d2{t[i2].x - t[i0].x, t[i2].y - t[i0].y};
    return {d1.x * db.x + d2.x * db.y, d1.y * db.x + d2.y * db.y};
  };
  if (!mesh.uvs.empty()) {
    si.duvdx[0] = deriv2(mesh.uvs, bx);
    si.duvdy[0] = deriv2(mesh.uvs, by);
  }
  if (!mesh.uvs1.empty()) {
    si.duvdx[1] = deriv2(mesh.uvs1, bx);
    si.duvdy[1] = deriv2(mesh.uvs1, by);
  }
  if (!mesh.normals.empty()) {
    const Vec3f n0 = world_normal(inst, mesh_normal(mesh, i0, si.time));
    const Vec3f n1 = world_normal(inst, mesh_normal(mesh, i1, si.time)) - n0,
                n2 = world_normal(inst, mesh_normal(mesh, i2, si.time)) - n0;
    const float s = si.back_face ? -1.0f : 1.0f;  // si.ns was face-forwarded
    si.dndx = (n1 * bx.x + n2 * bx.y) * s;
    si.dndy = (n1 * by.x + n2 * by.y) * s;
  }
}
}  // namespace

void set_barycentric_differentials(const Scene& scene, SurfaceInteraction& si, Vec2f bx, Vec2f by) {
  if (si.shape >= 0 || !std::isfinite(bx.x + bx.y + by.x + by.y)) return;
  const WorldTriangle& tri = si.tri;
  const Vec3f e1 = tri.p[1] - tri.p[0], e2 = tri.p[2] - tri.p[0];
  si.dpdx = e1 * bx.x + e2 * bx.y;
  si.dpdy = e1 * by.x + e2 * by.y;
  barycentric_derivatives(scene, si, bx, by);
}

RayDifferential reflect_differential(const SurfaceInteraction& si, const RayDifferential& rd, Vec3f wo,
                                     Vec3f n, Vec3f wi) {
  RayDifferential out;
  if (!rd.valid) return out;
  out.valid = true;
  out.rx_org = si.p + si.dpdx;
  out.ry_org = si.p + si.dpdy;
  const Vec3f dwodx = -normalize(rd.rx_dir) - wo, dwody = -normalize(rd.ry_dir) - wo;
  const float ddndx = dot(dwodx, n) + dot(wo, si.dndx);
  const float ddndy = dot(dwody, n) + dot(wo, si.dndy);
  out.rx_dir = wi - dwodx + 2.0f * (dot(wo, n) * si.dndx + ddndx * n);
  out.ry_dir = wi - dwody + 2.0f * (dot(wo, n) * si.dndy + ddndy * n);
  if (!is_finite(out.rx_dir) || !is_finite(out.ry_dir) || !is_finite(out.rx_org) || !is_finite(out.ry_org))
    out.valid = false;
  return out;
}

}  // namespace penumbra
