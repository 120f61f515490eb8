// Seeded stress-scene generators: see scenegen.h.
#include "benchmarks/scenegen.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "renderer/core/rng.h"
#include "renderer/scene/camera.h"

namespace penumbra::bench {
namespace {

/// The SplitMix64 sequence (Steele, Lea & Flood 2014) over the renderer's splitmix64 mixer: a
/// portable, seedable generator (the sample generator, PCG32, is seeded per pixel instead).
struct SceneRng {
  uint64_t state;
  explicit SceneRng(uint64_t seed) : state(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull) {}
  uint64_t next() {
    const uint64_t z = splitmix64(state);  // mixes state + golden ratio
    state += 0x9E3779B97F4A7C15ull;
    return z;
  }
  /// Uniform in [0, 1) with 24 random bits (exact in float).
  float uniform() { return float(next() >> 40) * 0x1p-24f; }
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
};

constexpr float kTwoPi = 2 * kPi;

/// Appends geometry to one mesh.
struct MeshBuilder {
  Mesh& m;
  uint32_t vertex(Vec3f p) {
    m.positions.push_back(p);
    return uint32_t(m.positions.size() - 1);
  }
  void tri(uint32_t a, uint32_t b, uint32_t c) { m.indices.insert(m.indices.end(), {a, b, c}); }
  void quad(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
    tri(a, b, c);
    tri(a, c, d);
  }
  /// Axis-aligned box, faces outward (counter-clockwise seen from outside).
  void box(Vec3f lo, Vec3f hi) {
    uint32_t v[8];
    for (int i = 0; i < 8; ++i)
      v[i] = vertex({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
    quad(v[0], v[2], v[3], v[1]);  // -z
    quad(v[4], v[5], v[7], v[6]);  // +z
    quad(v[0], v[4], v[6], v[2]);  // -x
    quad(v[1], v[3], v[7], v[5]);  // +x
    quad(v[0], v[1], v[5], v[4]);  // -y
    quad(v[2], v[6], v[7], v[3]);  // +y
  }
  /// Parametric surface f(u, v) on [0,1]^2 as an nu x nv grid of quads. With `wrap_u` the last
  /// column reuses the first (closed in u, e.g. a surface of revolution).
  void surface(int nu, int nv, bool wrap_u, const std::function<Vec3f(float, float)>& f) {
    const int cols = wrap_u ? nu : nu + 1;
    const uint32_t base = uint32_t(m.positions.size());
    for (int j = 0; j <= nv; ++j)
      for (int i = 0; i < cols; ++i) vertex(f(float(i) / float(nu), float(j) / float(nv)));
    auto at = [&](int i, int j) { return base + uint32_t(j * cols + (wrap_u ? i % nu : i)); };
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) quad(at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
  }
  /// Open cylinder around the vertical axis through `base`, plus a cap disc on top.
  void column(Vec3f base, float radius, float height, int segments, int rings) {
    surface(segments, rings, true, [&](float u, float v) {
      const float a = kTwoPi * u;
      // A gentle entasis (swelling) so rings are not all identical.
      const float r = radius * (1.0f + 0.06f * std::sin(kPi * v));
      return base + Vec3f{r * std::cos(a), height * v, r * std::sin(a)};
    });
  }
  /// Tube (radius r) along the circular arc of radius R in the plane spanned by `e1` (arc start
  /// direction) and `e2`, from angle a0 to a1.
  void arc_tube(Vec3f center, Vec3f e1, Vec3f e2, float R, float r, float a0, float a1, int nu, int nv) {
    const Vec3f n = normalize(cross(e1, e2));
    surface(nu, nv, false, [&](float u, float v) {
      const float a = a0 + (a1 - a0) * u, b = kTwoPi * v;
      const Vec3f radial = e1 * std::cos(a) + e2 * std::sin(a);
      return center + radial * (R + r * std::cos(b)) + n * (r * std::sin(b));
    });
  }
};

int material(Scene& s, const char* name, Vec3f color, float metallic, float roughness) {
  Material m;
  m.name = name;
  m.base_color = color;
  m.metallic = metallic;
  m.roughness = roughness;
  s.materials.push_back(m);
  return int(s.materials.size() - 1);
}

Mesh& new_mesh(Scene& s, const char* name, int mat) {
  Mesh m;
  m.name = name;
  m.material = mat;
  return s.meshes[size_t(add_world_mesh(s, std::move(m)))];
}

Light point_light(const char* name, Vec3f p, float intensity, Vec3f color = {1, 1, 1}) {
  Light l;
  l.name = name;
  l.type = LightType::Point;
  l.position = p;
  l.intensity = intensity;
  l.color = color;
  return l;
}

Light sun(Vec3f dir, float lux) {
  Light l;
  l.name = "sun";
  l.type = LightType::Directional;
  l.direction = normalize(dir);
  l.intensity = lux;
  return l;
}

Camera camera(const char* name, Vec3f eye, Vec3f target, float yfov_deg) {
  Camera c = look_at(eye, target, {0, 1, 0}, yfov_deg * kPi / 180);
  c.name = name;
  c.aspect = 16.0f / 9.0f;
  c.znear = 0.01f;
  return c;
}

// ---- atrium ---------------------------------------------------------------------------------

/// Hall 32 x 14 x 18 m (x, y, z) with a skylight, two storeys of columns joined by arches,
/// gallery floors, drapes hanging between the upper columns and seeded crates. `s` scales the
/// tessellation of the curved parts (triangles grow with s^2).
Scene atrium(uint64_t seed, float s) {
  Scene sc;
  sc.meshes.reserve(8);  // MeshBuilders hold references into sc.meshes
  SceneRng rng(seed);
  const int stone = material(sc, "stone", {0.62f, 0.58f, 0.52f}, 0, 0.8f);
  const int marble = material(sc, "marble", {0.85f, 0.84f, 0.8f}, 0, 0.3f);
  const int cloth = material(sc, "cloth", {0.55f, 0.08f, 0.06f}, 0, 0.9f);
  const int wood = material(sc, "wood", {0.45f, 0.3f, 0.16f}, 0, 0.7f);
  const auto n = [&](float k) { return std::max(3, int(std::lround(k * s))); };

  MeshBuilder shell{new_mesh(sc, "shell", stone)};
  const float X = 16, Y = 14, Z = 9, T = 0.4f;
  shell.surface(n(64), n(36), false, [&](float u, float v) {
    return Vec3f{-X + 2 * X * u, 0, Z - 2 * Z * v};
  });  // floor
  shell.box({-X - T, 0, -Z - T}, {-X, Y, Z + T});
  shell.box({X, 0, -Z - T}, {X + T, Y, Z + T});
  shell.box({-X, 0, -Z - T}, {X, Y, -Z});
  shell.box({-X, 0, Z}, {X, Y, Z + T});
  // Ceiling with a skylight opening of 16 x 6 m.
  shell.box({-X, Y, -Z}, {X, Y + T, -3});
  shell.box({-X, Y, 3}, {X, Y + T, Z});
  shell.box({-X, Y, -3}, {-8, Y + T, 3});
  shell.box({8, Y, -3}, {X, Y + T, 3});
  // Gallery floors at 6 m along both long sides, with a balustrade of small posts.
  for (float side : {-1.0f, 1.0f}) {
    const float z0 = side * 5.6f, z1 = side * Z;
    shell.box({-X, 6, std::min(z0, z1)}, {X, 6.35f, std::max(z0, z1)});
    for (float x = -X + 0.5f; x < X; x += 0.5f) {
      MeshBuilder post{sc.meshes[0]};
      post.column({x, 6.35f, side * 5.7f}, 0.06f, 0.9f, n(8), n(2));
    }
    shell.box({-X, 7.25f, side * 5.7f - 0.08f}, {X, 7.35f, side * 5.7f + 0.08f});
  }

  MeshBuilder cols{new_mesh(sc, "colonnade", marble)};
  for (float side : {-1.0f, 1.0f}) {
    for (int storey = 0; storey < 2; ++storey) {
      const float y0 = storey == 0 ? 0.0f : 6.35f, h = storey == 0 ? 4.0f : 3.6f;
      const float r = storey == 0 ? 0.42f : 0.32f;
      for (int i = 0; i <= 8; ++i) {
        const float x = -12 + 3.0f * float(i);
        cols.box({x - 0.6f, y0, side * 5 - 0.6f}, {x + 0.6f, y0 + 0.3f, side * 5 + 0.6f});  // base
        cols.column({x, y0 + 0.3f, side * 5}, r, h, n(48), n(24));
        cols.box({x - 0.55f, y0 + 0.3f + h, side * 5 - 0.55f},
                 {x + 0.55f, y0 + 0.6f + h, side * 5 + 0.55f});  // capital
        if (i < 8) {
          // Semicircular arch from this column's capital to the next one's.
          const Vec3f c{x + 1.5f, y0 + 0.6f + h, side * 5};
          cols.arc_tube(c, {1, 0, 0}, {0, 1, 0}, 1.5f, 0.25f, 0, kPi, n(40), n(12));
        }
      }
    }
  }

  // Drapes between the upper columns: wavy sheets, each with its own seeded phase.
  MeshBuilder drapes{new_mesh(sc, "drapes", cloth)};
  for (float side : {-1.0f, 1.0f}) {
    for (int i = 0; i < 8; ++i) {
      const float x0 = -12 + 3.0f * float(i) + 0.45f, phase = rng.uniform(0, kTwoPi),
                  depth = rng.uniform(0.05f, 0.2f);
      drapes.surface(n(30), n(40), false, [&](float u, float v) {
        const float sag = 0.4f * std::sin(kPi * u) * v;
        return Vec3f{x0 + 2.1f * u, 10.2f - 3.2f * v + sag,
                     side * 5.3f + depth * std::sin(phase + 9 * u) * (0.3f + v)};
      });
    }
  }

  // Seeded clutter: crates and barrels on the ground floor.
  MeshBuilder crates{new_mesh(sc, "crates", wood)};
  for (int i = 0; i < 60; ++i) {
    const float x = rng.uniform(-14, 14), z = rng.uniform(-3.8f, 3.8f), a = rng.uniform(0.2f, 0.7f);
    if (rng.uniform() < 0.5f)
      crates.box({x - a, 0, z - a}, {x + a, 2 * a, z + a});
    else
      crates.column({x, 0, z}, a * 0.7f, 2.2f * a, n(20), n(6));
  }

  sc.lights.push_back(point_light("skylight", {0, 12, 0}, 900, {1.0f, 0.95f, 0.85f}));
  sc.lights.push_back(point_light("lamp_east", {11, 4, 0}, 150, {1.0f, 0.8f, 0.6f}));
  sc.lights.push_back(point_light("lamp_west", {-11, 4, 0}, 150, {1.0f, 0.8f, 0.6f}));
  sc.cameras.push_back(camera("nave", {-15, 2.2f, 0.5f}, {4, 4.5f, 0}, 60));
  sc.cameras.push_back(camera("gallery", {14, 8, 7.5f}, {-6, 3, -2}, 55));
  return sc;
}

// ---- soup -----------------------------------------------------------------------------------

Scene soup(uint64_t seed, uint64_t triangles) {
  Scene sc;
  SceneRng rng(seed);
  MeshBuilder b{new_mesh(sc, "soup", material(sc, "grey", {0.6f, 0.6f, 0.6f}, 0, 0.6f))};
  // Edge length ~2.5x the mean spacing: triangles overlap their neighbours somewhat.
  const float size = 2.5f * 2.0f / std::cbrt(float(triangles));
  b.m.positions.reserve(triangles * 3);
  b.m.indices.reserve(triangles * 3);
  for (uint64_t i = 0; i < triangles; ++i) {
    const Vec3f c{rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
    uint32_t v[3];
    for (auto& k : v)
      k = b.vertex(c + Vec3f{rng.uniform(-size, size), rng.uniform(-size, size), rng.uniform(-size, size)} *
                           0.5f);
    b.tri(v[0], v[1], v[2]);
  }
  sc.lights.push_back(point_light("key", {3, 4, 3}, 40));
  sc.cameras.push_back(camera("front", {2.3f, 1.7f, 3.4f}, {0, 0, 0}, 45));
  return sc;
}

// ---- stadium --------------------------------------------------------------------------------

/// Catmull-Rom interpolation through `pts` (as (r, y) pairs) at parameter t in [0, 1].
Vec2f catmull_rom(const std::vector<Vec2f>& pts, float t) {
  const int n = int(pts.size()) - 1;
  const float f = std::clamp(t, 0.0f, 1.0f) * float(n);
  const int i = std::min(int(f), n - 1);
  const float x = f - float(i);
  auto p = [&](int k) { return pts[size_t(std::clamp(k, 0, n))]; };
  const Vec2f p0 = p(i - 1), p1 = p(i), p2 = p(i + 1), p3 = p(i + 2);
  auto cr = [&](float a, float b, float c, float d) {
    return 0.5f * (2 * b + (-a + c) * x + (2 * a - 5 * b + 4 * c - d) * x * x +
                   (-a + 3 * b - 3 * c + d) * x * x * x);
  };
  return {cr(p0.x, p1.x, p2.x, p3.x), cr(p0.y, p1.y, p2.y, p3.y)};
}

/// A teapot-like object (body and lid of revolution, spout, handle, knob) about 1 m tall at the
/// origin; `s` scales its tessellation.
void teapot(MeshBuilder& b, float s) {
  const auto n = [&](float k) { return std::max(4, int(std::lround(k * s))); };
  const std::vector<Vec2f> body = {{0.0f, 0.0f},   {0.55f, 0.0f},  {0.68f, 0.06f}, {0.75f, 0.3f},
                                   {0.72f, 0.55f}, {0.58f, 0.72f}, {0.45f, 0.78f}};
  const std::vector<Vec2f> lid = {{0.45f, 0.78f}, {0.32f, 0.84f}, {0.1f, 0.9f},
                                  {0.08f, 0.96f}, {0.12f, 1.0f},  {0.0f, 1.04f}};
  for (const auto* profile : {&body, &lid}) {
    const int rings = n(profile == &body ? 120 : 50);
    b.surface(n(160), rings, true, [&](float u, float v) {
      const Vec2f p = catmull_rom(*profile, v);
      const float a = -kTwoPi * u;
      return Vec3f{p.x * std::cos(a), p.y, p.x * std::sin(a)};
    });
  }
  // Spout: a tapering tube along a quadratic curve from the body's side outward and up.
  b.surface(n(40), n(60), false, [&](float u, float v) {
    const Vec3f p0{0.6f, 0.25f, 0}, p1{1.05f, 0.35f, 0}, p2{1.15f, 0.78f, 0};
    const Vec3f c = p0 * ((1 - u) * (1 - u)) + p1 * (2 * u * (1 - u)) + p2 * (u * u);
    const Vec3f t = normalize((p1 - p0) * (2 * (1 - u)) + (p2 - p1) * (2 * u));
    const Vec3f nz{0, 0, 1}, nn = normalize(cross(nz, t));
    const float r = 0.12f - 0.07f * u, a = kTwoPi * v;
    return c + nn * (r * std::cos(a)) + nz * (r * std::sin(a));
  });
  // Handle: a tube along a circular arc on the -x side.
  b.arc_tube({-0.72f, 0.42f, 0}, {0, 1, 0}, {-1, 0, 0}, 0.24f, 0.045f, -0.1f * kPi, 1.1f * kPi, n(60), n(24));
}

Scene stadium(uint64_t seed, float s) {
  Scene sc;
  sc.meshes.reserve(8);  // MeshBuilders hold references into sc.meshes
  SceneRng rng(seed);
  MeshBuilder pot{new_mesh(sc, "teapot", material(sc, "porcelain", {0.9f, 0.9f, 0.95f}, 0, 0.15f))};
  teapot(pot, s);
  MeshBuilder bowl{new_mesh(sc, "stadium", material(sc, "concrete", {0.5f, 0.5f, 0.48f}, 0, 0.9f))};
  const float R = 400;
  bowl.box({-R, -1, -R}, {R, 0, R});  // pitch: two big triangles on top
  // Stands: 12 rising tiers of 48 straight segments around the pitch, each a large slab.
  for (int tier = 0; tier < 12; ++tier)
    for (int k = 0; k < 48; ++k) {
      const float a0 = kTwoPi * float(k) / 48, a1 = kTwoPi * float(k + 1) / 48;
      const float r0 = 220 + 12 * float(tier), r1 = r0 + 12, y = 4 * float(tier + 1);
      const uint32_t v0 = bowl.vertex({r0 * std::cos(a0), y, r0 * std::sin(a0)});
      const uint32_t v1 = bowl.vertex({r0 * std::cos(a1), y, r0 * std::sin(a1)});
      const uint32_t v2 = bowl.vertex({r1 * std::cos(a1), y, r1 * std::sin(a1)});
      const uint32_t v3 = bowl.vertex({r1 * std::cos(a0), y, r1 * std::sin(a0)});
      const uint32_t v4 = bowl.vertex({r0 * std::cos(a0), y - 4, r0 * std::sin(a0)});
      const uint32_t v5 = bowl.vertex({r0 * std::cos(a1), y - 4, r0 * std::sin(a1)});
      bowl.quad(v0, v1, v2, v3);  // tread
      bowl.quad(v4, v5, v1, v0);  // riser
    }
  // Four floodlight masts at seeded angles.
  for (int i = 0; i < 4; ++i) {
    const float a = kTwoPi * (float(i) + rng.uniform(0.2f, 0.8f)) / 4;
    const Vec3f p{370 * std::cos(a), 0, 370 * std::sin(a)};
    bowl.box(p - Vec3f{2, 0, 2}, p + Vec3f{2, 90, 2});
    sc.lights.push_back(point_light("flood", p + Vec3f{0, 92, 0}, 4e5f, {1.0f, 0.97f, 0.9f}));
  }
  sc.lights.push_back(point_light("key", {2, 3, 2.5f}, 6));
  sc.cameras.push_back(camera("teapot", {0.5f, 1.2f, 3.1f}, {0.1f, 0.45f, 0}, 40));
  sc.cameras.push_back(camera("overview", {150, 80, 260}, {0, 0, 0}, 50));
  return sc;
}

// ---- slivers --------------------------------------------------------------------------------

Scene slivers(uint64_t seed, uint64_t triangles) {
  Scene sc;
  SceneRng rng(seed);
  MeshBuilder b{new_mesh(sc, "slivers", material(sc, "steel", {0.7f, 0.7f, 0.72f}, 0, 0.4f))};
  b.m.positions.reserve(triangles * 3);
  b.m.indices.reserve(triangles * 3);
  for (uint64_t i = 0; i < triangles; ++i) {
    // 60-80 m long along x, 5-20 mm wide, in a 4 x 4 m cross-section.
    const float x0 = rng.uniform(-50, -30), len = rng.uniform(60, 80);
    const float y = rng.uniform(-2, 2), z = rng.uniform(-2, 2), w = rng.uniform(0.005f, 0.02f);
    const float a = rng.uniform(0, kTwoPi);
    const Vec3f off{0, w * std::cos(a), w * std::sin(a)};
    const uint32_t v0 = b.vertex({x0, y, z});
    const uint32_t v1 = b.vertex(Vec3f{x0 + len, y, z} + off);
    const uint32_t v2 = b.vertex(Vec3f{x0 + len, y, z} - off);
    b.tri(v0, v1, v2);
  }
  sc.lights.push_back(point_light("key", {0, 20, 20}, 800));
  sc.cameras.push_back(camera("side", {-8, 3, 11}, {2, 0, 0}, 50));
  return sc;
}

// ---- terrain --------------------------------------------------------------------------------

/// Value noise (lattice values, smoothstep interpolation) summed in octaves (fBm), as in
/// Ebert et al., "Texturing and Modeling: A Procedural Approach", ch. 2.
float value_noise(float x, float z, uint64_t seed) {
  auto lattice = [&](int64_t i, int64_t j) {
    SceneRng r(seed ^ (uint64_t(i) * 0x8DA6B343ull) ^ (uint64_t(j) * 0xD8163841ull));
    return r.uniform();
  };
  const float fx = std::floor(x), fz = std::floor(z);
  const int64_t i = int64_t(fx), j = int64_t(fz);
  float tx = x - fx, tz = z - fz;
  tx = tx * tx * (3 - 2 * tx);
  tz = tz * tz * (3 - 2 * tz);
  const float a = lattice(i, j), b = lattice(i + 1, j), c = lattice(i, j + 1), d = lattice(i + 1, j + 1);
  return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * tz;
}

Scene terrain(uint64_t seed, uint64_t triangles) {
  Scene sc;
  MeshBuilder b{new_mesh(sc, "terrain", material(sc, "ground", {0.35f, 0.32f, 0.25f}, 0, 0.95f))};
  const int k = std::max(2, int(std::lround(std::sqrt(double(triangles) / 2))));
  const float size = 1000;
  b.m.positions.reserve(size_t(k + 1) * size_t(k + 1));
  b.m.indices.reserve(size_t(k) * size_t(k) * 6);
  b.surface(k, k, false, [&](float u, float v) {
    const float x = (u - 0.5f) * size, z = (v - 0.5f) * size;
    float h = 0, amp = 80, freq = 1.0f / 250;
    for (int o = 0; o < 7; ++o, amp *= 0.5f, freq *= 2)
      h += amp * (value_noise(x * freq, z * freq, seed + uint64_t(o)) - 0.5f);
    return Vec3f{x, h, z};
  });
  sc.lights.push_back(sun({0.4f, -0.6f, 0.3f}, 3));
  sc.cameras.push_back(camera("vista", {-420, 160, -420}, {60, 0, 60}, 45));
  return sc;
}

// ---- spheres ---------------------------------------------------------------------------------

/// `count` spheres of seeded radii on a jittered square grid over a ground quad, each either an
/// analytic sphere (one shape, placed by its instance) or tessellated into a UV sphere of 70 x 72
/// quads (10,080 triangles, smooth normals) in world space: the same scene for both, so rays
/// meet the same surfaces up to the tessellation.
Scene spheres(uint64_t seed, uint64_t count, bool tessellate) {
  Scene sc;
  SceneRng rng(seed);
  const int mat = material(sc, "ceramic", {0.8f, 0.75f, 0.7f}, 0, 0.3f);
  const int side = std::max(1, int(std::ceil(std::sqrt(double(count)))));
  const float extent = 3.0f * float(side);
  {
    MeshBuilder ground{new_mesh(sc, "ground", material(sc, "ground", {0.5f, 0.5f, 0.5f}, 0, 0.9f))};
    ground.box({-extent, -1, -extent}, {extent, 0, extent});
  }
  for (uint64_t i = 0; i < count; ++i) {
    const float r = rng.uniform(0.6f, 1.2f);
    const Vec3f c{3.0f * (2.0f * float(i % uint64_t(side)) - float(side) + 1) + rng.uniform(-0.4f, 0.4f), r,
                  3.0f * (2.0f * float(i / uint64_t(side)) - float(side) + 1) + rng.uniform(-0.4f, 0.4f)};
    if (!tessellate) {
      SceneShape shape;
      shape.name = "sphere" + std::to_string(i);
      shape.shape.kind = ShapeKind::Sphere;
      shape.shape.radius = r;
      shape.material = mat;
      sc.shapes.push_back(shape);
      Affine3f place;
      place.m[0][3] = c.x, place.m[1][3] = c.y, place.m[2][3] = c.z;
      sc.instances.push_back(make_shape_instance(int(sc.shapes.size()) - 1, place));
      continue;
    }
    MeshBuilder b{new_mesh(sc, "sphere", mat)};
    constexpr int kRings = 70, kSegments = 72;
    for (int y = 0; y <= kRings; ++y)
      for (int x = 0; x <= kSegments; ++x) {
        const float theta = kPi * float(y) / kRings, phi = kTwoPi * float(x) / kSegments;
        b.vertex(c +
                 Vec3f{std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)} *
                     r);
      }
    for (int y = 0; y < kRings; ++y)
      for (int x = 0; x < kSegments; ++x) {
        const uint32_t a = uint32_t(y * (kSegments + 1) + x), d = a + kSegments + 1;
        b.quad(a, d, d + 1, a + 1);
      }
  }
  for (Mesh& m : sc.meshes) m.normals = compute_smooth_normals(m.positions, m.indices);
  sc.lights.push_back(point_light("key", {extent, 4 * extent, extent * 0.5f}, 40 * extent * extent));
  sc.cameras.push_back(camera("overview", {0.2f * extent, 0.9f * extent, 1.4f * extent}, {0, 0, 0}, 45));
  return sc;
}

/// Runs `make(scale)` once at scale 1 and once more at the scale whose triangle count is
/// nearest `target` (curved parts grow with scale^2).
Scene fit(uint64_t target, const std::function<Scene(float)>& make) {
  Scene first = make(1.0f);
  const double n = double(count_triangles(first));
  const float scale = float(std::sqrt(double(target) / n));
  if (std::fabs(scale - 1) < 0.01f) return first;
  return make(scale);
}

}  // namespace

std::vector<GeneratorInfo> generators() {
  return {{"atrium", "architectural interior: hall, columns, arches, galleries, drapes", 300000},
          {"soup", "uniformly random triangles in a cube", 1000000},
          {"stadium", "teapot in a stadium: dense object in a huge sparse room", 250000},
          {"slivers", "long thin triangles along one axis", 500000},
          {"terrain", "fBm heightfield for scaling (>= 5M triangles)", 5200000},
          {"spheres", "analytic spheres on a ground quad, one per 10k requested triangles", 640000},
          {"spheres-mesh", "the same spheres tessellated to 10,080 triangles each", 640000}};
}

Scene generate_scene(const std::string& name, uint64_t seed, uint64_t triangles) {
  const auto all = generators();
  const auto it =
      std::find_if(all.begin(), all.end(), [&](const GeneratorInfo& g) { return g.name == name; });
  if (it == all.end()) {
    std::string known;
    for (const auto& g : all) known += (known.empty() ? "" : ", ") + g.name;
    throw std::invalid_argument("unknown generated scene '" + name + "' (known: " + known + ")");
  }
  if (triangles == 0) triangles = it->default_triangles;
  if (triangles < 1000 || triangles > 100000000)
    throw std::invalid_argument(name + ": triangle count " + std::to_string(triangles) +
                                " outside [1000, 100000000]");
  if (name == "atrium") return fit(triangles, [&](float s) { return atrium(seed, s); });
  if (name == "soup") return soup(seed, triangles);
  if (name == "stadium") return fit(triangles, [&](float s) { return stadium(seed, s); });
  if (name == "slivers") return slivers(seed, triangles);
  if (name == "spheres" || name == "spheres-mesh")
    return spheres(seed, std::max<uint64_t>(1, triangles / 10000), name == "spheres-mesh");
  return terrain(seed, triangles);
}

}  // namespace penumbra::bench
