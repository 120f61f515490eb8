// Enclosed volumes; see volume.h.
#include "renderer/scene/volume.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <unordered_map>

namespace penumbra {

namespace {

// A position's bits, for welding equal positions.
struct PositionKey {
  uint32_t x, y, z;
  bool operator==(const PositionKey&) const = default;
};
struct PositionHash {
  size_t operator()(const PositionKey& k) const {
    return (size_t(k.x) * 0x9E3779B97F4A7C15ull) ^ (size_t(k.y) * 0xC2B2AE3D27D4EB4Full) ^
           (size_t(k.z) * 0x165667B19E3779F9ull);
  }
};

PositionKey key_of(Vec3f p) {
  // +0 and -0 weld together.
  const auto bits = [](float v) {
    uint32_t b;
    const float w = v == 0 ? 0.0f : v;
    std::memcpy(&b, &w, 4);
    return b;
  };
  return {bits(p.x), bits(p.y), bits(p.z)};
}

double det3(const Affine3f& a) {
  const auto& m = a.m;
  return double(m[0][0]) * (double(m[1][1]) * m[2][2] - double(m[1][2]) * m[2][1]) -
         double(m[0][1]) * (double(m[1][0]) * m[2][2] - double(m[1][2]) * m[2][0]) +
         double(m[0][2]) * (double(m[1][0]) * m[2][1] - double(m[1][1]) * m[2][0]);
}

ShapeVolume implicit_volume(const Shape& shape, const VolumeConfig& config) {
  ShapeVolume v;
  const Bounds3f& b = shape.sdf_bounds;
  if (b.empty() || !(shape.lipschitz > 0)) return v;
  v.closed = true;
  const Vec3f extent = b.hi - b.lo;
  const double longest = std::max({extent.x, extent.y, extent.z});
  if (!(longest > 0)) return v;
  const int base = std::max(1, config.base_cells);
  const double size0 = longest / base;
  const int n[3] = {std::max(1, int(std::ceil(extent.x / size0))),
                    std::max(1, int(std::ceil(extent.y / size0))),
                    std::max(1, int(std::ceil(extent.z / size0)))};
  struct Corner {
    double x, y, z;
  };
  std::vector<Corner> cells;
  cells.reserve(size_t(n[0]) * size_t(n[1]) * size_t(n[2]));
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        cells.push_back({b.lo.x + i * size0, b.lo.y + j * size0, b.lo.z + k * size0});
  const double lipschitz = shape.lipschitz;
  double inside = 0, boundary = 0;
  std::vector<uint8_t> state;  // 0 outside, 1 inside, 2 the surface may cross it
  for (int level = 0;; ++level) {
    const double size = size0 / double(1ull << level);
    const double half_diagonal = 0.5 * std::sqrt(3.0) * size;
    state.assign(cells.size(), 0);
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, cells.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
          for (size_t c = r.begin(); c < r.end(); ++c) {
            const Corner& lo = cells[c];
            const Vec3f centre{float(lo.x + size / 2), float(lo.y + size / 2), float(lo.z + size / 2)};
            const double f = sdf_eval(shape.sdf, centre);
            // The float centre lies within a rounding of the exact one: a margin of 1e-6 cells.
            state[c] =
                std::fabs(f) / lipschitz > half_diagonal * (1 + 1e-6) + 1e-6 * size ? (f < 0 ? 1 : 0) : 2;
          }
        });
    v.cells += cells.size();
    const double cell_volume = size * size * size;
    std::vector<Corner> crossed;
    for (size_t c = 0; c < cells.size(); ++c) {
      if (state[c] == 1) inside += cell_volume;
      if (state[c] == 2) crossed.push_back(cells[c]);
    }
    if (level >= config.refine_levels || v.cells + 8 * crossed.size() > config.max_cells) {
      boundary = double(crossed.size()) * cell_volume;
      break;
    }
    cells.clear();
    const double h = size / 2;
    for (const Corner& c : crossed)
      for (int o = 0; o < 8; ++o)
        cells.push_back({c.x + (o & 1) * h, c.y + ((o >> 1) & 1) * h, c.z + ((o >> 2) & 1) * h});
  }
  v.volume = inside + boundary / 2;
  v.error = boundary / 2;
  return v;
}

}  // namespace

MeshVolume mesh_volume(std::span<const Vec3f> positions, std::span<const uint32_t> indices) {
  MeshVolume v;
  std::unordered_map<PositionKey, uint32_t, PositionHash> weld;
  std::vector<uint32_t> id(positions.size());
  for (size_t i = 0; i < positions.size(); ++i)
    id[i] = weld.emplace(key_of(positions[i]), uint32_t(weld.size())).first->second;
  // Per undirected welded edge (smaller id first): triangles along it in each direction.
  struct Uses {
    uint32_t forward = 0, backward = 0;
  };
  std::unordered_map<uint64_t, Uses> edges;
  const size_t triangles = indices.size() / 3;
  const Vec3f origin = positions.empty() ? Vec3f{} : positions[0];
  double sum = 0;
  for (size_t t = 0; t < triangles; ++t) {
    const uint32_t* tri = &indices[3 * t];
    const Vec3f a = positions[tri[0]] - origin, b = positions[tri[1]] - origin,
                c = positions[tri[2]] - origin;
    sum += double(a.x) * (double(b.y) * c.z - double(b.z) * c.y) -
           double(a.y) * (double(b.x) * c.z - double(b.z) * c.x) +
           double(a.z) * (double(b.x) * c.y - double(b.y) * c.x);
    const uint32_t w[3] = {id[tri[0]], id[tri[1]], id[tri[2]]};
    if (w[0] == w[1] || w[1] == w[2] || w[2] == w[0]) {
      ++v.degenerate;
      continue;
    }
    for (int e = 0; e < 3; ++e) {
      const uint32_t p = w[e], q = w[(e + 1) % 3];
      Uses& u = edges[(uint64_t(std::min(p, q)) << 32) | std::max(p, q)];
      (p < q ? u.forward : u.backward)++;
    }
  }
  for (const auto& [edge, u] : edges) {
    if (u.forward + u.backward == 1)
      ++v.open_edges;
    else if (u.forward != 1 || u.backward != 1)
      ++v.bad_edges;
  }
  v.closed = triangles > v.degenerate && v.open_edges == 0 && v.bad_edges == 0;
  v.signed_volume = sum / 6;
  return v;
}

ShapeVolume shape_volume(const Shape& shape, const VolumeConfig& config) {
  ShapeVolume v;
  constexpr double pi = std::numbers::pi;
  switch (shape.kind) {
    case ShapeKind::Sphere:
      v.closed = true;
      v.volume = 4.0 / 3.0 * pi * std::pow(double(shape.radius), 3);
      break;
    case ShapeKind::Box:
      v.closed = true;
      v.volume = 8.0 * double(shape.half_size.x) * shape.half_size.y * shape.half_size.z;
      break;
    case ShapeKind::Capsule: {
      v.closed = true;
      const double r = shape.radius;
      v.volume = pi * r * r * 2.0 * shape.half_height + 4.0 / 3.0 * pi * r * r * r;
      break;
    }
    case ShapeKind::Segment: {
      v.closed = true;
      const double r = shape.radius;
      v.volume = pi * r * r * double(length(shape.p1 - shape.p0)) + 4.0 / 3.0 * pi * r * r * r;
      break;
    }
    case ShapeKind::Plane:
    case ShapeKind::Disk:
    case ShapeKind::Splat:
      break;
    case ShapeKind::Implicit:
      v = implicit_volume(shape, config);
      break;
  }
  return v;
}

std::vector<InstanceVolume> instance_volumes(const Scene& scene, const VolumeConfig& config) {
  std::vector<MeshVolume> meshes(scene.meshes.size());
  std::vector<ShapeVolume> shapes(scene.shapes.size());
  std::vector<uint8_t> mesh_done(meshes.size(), 0), shape_done(shapes.size(), 0);
  std::vector<InstanceVolume> out;
  out.reserve(scene.instances.size());
  for (uint32_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    const double scale = std::fabs(det3(inst.to_world));
    InstanceVolume iv;
    iv.instance = i;
    if (inst.shape >= 0) {
      const size_t s = size_t(inst.shape);
      if (!shape_done[s]) shapes[s] = shape_volume(scene.shapes[s].shape, config), shape_done[s] = 1;
      iv.closed = shapes[s].closed;
      iv.volume = shapes[s].volume * scale;
      iv.error = shapes[s].error * scale;
    } else {
      const size_t m = size_t(inst.mesh);
      if (!mesh_done[m])
        meshes[m] = mesh_volume(scene.meshes[m].positions, scene.meshes[m].indices), mesh_done[m] = 1;
      iv.closed = meshes[m].closed && !scene.meshes[m].points;
      iv.volume = iv.closed ? std::fabs(meshes[m].signed_volume) * scale : 0;
      iv.inward = iv.closed && meshes[m].signed_volume < 0;
      iv.open_edges = meshes[m].open_edges;
      iv.bad_edges = meshes[m].bad_edges;
    }
    out.push_back(iv);
  }
  return out;
}

}  // namespace penumbra
