// The wireframe overlay: on a cube seen edge-on, exactly the edges of faces turned to the camera
// are drawn (against the analytic edge list projected by the camera), hidden ones only when
// asked, dimmed or dashed; chosen nodes only; the same coverage for any threads or window split.
#include "renderer/integrators/wireframe.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <utility>

#include "renderer/integrators/scene_accel.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

struct Edge2 {
  Vec2f a, b;
};

/// Distance from point c to the segment a-b.
float distance_to(const Edge2& e, Vec2f c) {
  const Vec2f d{e.b.x - e.a.x, e.b.y - e.a.y};
  const float dd = d.x * d.x + d.y * d.y;
  const float s = dd > 0 ? std::clamp(((c.x - e.a.x) * d.x + (c.y - e.a.y) * d.y) / dd, 0.0f, 1.0f) : 0.0f;
  const float x = e.a.x + d.x * s - c.x, y = e.a.y + d.y * s - c.y;
  return std::sqrt(x * x + y * y);
}

/// Raster position of world point p through an orthographic camera, as the renderer maps it.
Vec2f project(const Camera& cam, int w, int h, Vec3f p) {
  const Vec3f q = p - cam.eye;
  const float sx = dot(q, cam.u) / (cam.ymag * float(w) / float(h)), sy = dot(q, cam.v) / cam.ymag;
  return {(sx + 1) * 0.5f * float(w), (1 - sy) * 0.5f * float(h)};
}

/// The cube's triangle edges split into those with a face turned to the camera (seen) and the
/// others (hidden behind the cube), projected.
std::pair<std::vector<Edge2>, std::vector<Edge2>> cube_edges(const Mesh& cube, const Camera& cam, int w,
                                                             int h) {
  std::vector<Edge2> seen, hidden;
  const size_t n = cube.indices.size() / 3;
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = cube.indices[3 * t + size_t(k)], b = cube.indices[3 * t + size_t((k + 1) % 3)];
      bool front = false;
      for (size_t u = 0; u < n; ++u) {  // the faces having edge a-b
        const uint32_t* f = &cube.indices[3 * u];
        const bool has_a = f[0] == a || f[1] == a || f[2] == a, has_b = f[0] == b || f[1] == b || f[2] == b;
        if (!has_a || !has_b) continue;
        const Vec3f ng =
            cross(cube.positions[f[1]] - cube.positions[f[0]], cube.positions[f[2]] - cube.positions[f[0]]);
        front |= dot(ng, cam.w) > 0;  // facing the camera (it looks along -w)
      }
      const Edge2 e{project(cam, w, h, cube.positions[a]), project(cam, w, h, cube.positions[b])};
      (front ? seen : hidden).push_back(e);
    }
  return {seen, hidden};
}

float nearest(const std::vector<Edge2>& edges, Vec2f c) {
  float d = kInfinity;
  for (const Edge2& e : edges) d = std::min(d, distance_to(e, c));
  return d;
}

Scene cube_scene() {
  Scene s;
  Mesh cube = cube_mesh(1);
  cube.node = 0;
  add_world_mesh(s, std::move(cube));
  Mesh other = cube_mesh(0.3f);  // a second node, beside the cube on screen
  for (Vec3f& p : other.positions) p = p + Vec3f{1.6f, 0, -1.6f};
  other.node = 1;
  add_world_mesh(s, std::move(other));
  return s;
}

Camera edge_on_camera() {
  // Facing the cube's vertical edge at x = z = 1 from a little above: three faces seen.
  Camera cam = look_at(Vec3f{6, 2.5f, 6}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 2;
  return cam;
}

}  // namespace

TEST_CASE("wireframe: on a cube seen edge-on, exactly the visible edges are drawn", "[wireframe][quick]") {
  const Scene s = cube_scene();
  const Camera cam = edge_on_camera();
  const int w = 160, h = 120;
  RenderConfig cfg = small_render_config(w, h, 1, 16);
  const auto accel = make_scene_accelerator("embree", s);
  WireframeConfig wire;
  wire.width = 2;
  wire.nodes = {0};
  const auto [seen, hidden] = cube_edges(s.meshes[0], cam, w, h);
  REQUIRE(seen.size() > hidden.size());
  REQUIRE_FALSE(hidden.empty());
  const std::vector<float> a = render_wireframe(s, *accel, cam, cfg, wire);
  REQUIRE(a.size() == size_t(w * h));
  int on_seen = 0, on_hidden_only = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Vec2f c{float(x) + 0.5f, float(y) + 0.5f};
      const float ds = nearest(seen, c), dh = nearest(hidden, c), alpha = a[size_t(y * w + x)];
      INFO("pixel " << x << "," << y << ": " << ds << " px from a seen edge, " << dh << " from a hidden one");
      if (ds <= 0.25f) {  // on a seen edge: covered
        ++on_seen;
        CHECK(alpha >= 0.75f);
      } else if (ds >= wire.width / 2 + 1) {  // away from every seen edge: nothing, hidden edges included
        CHECK(alpha == 0);
        on_hidden_only += dh <= 0.25f;
      }
    }
  CHECK(on_seen > 200);
  CHECK(on_hidden_only > 20);  // hidden edges do cross the image where nothing seen is drawn
  // The other node (chosen nowhere above) is drawn once chosen.
  wire.nodes = {1};
  const std::vector<float> b = render_wireframe(s, *accel, cam, cfg, wire);
  double left = 0, right = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      (project(cam, w, h, {1.6f, 0, -1.6f}).x - float(x) > 20 ? left : right) += b[size_t(y * w + x)];
  CHECK(left == 0);
  CHECK(right > 10);
}

TEST_CASE("wireframe: hidden edges dimmed or dashed when asked", "[wireframe][quick]") {
  const Scene s = cube_scene();
  const Camera cam = edge_on_camera();
  const int w = 160, h = 120;
  const RenderConfig cfg = small_render_config(w, h, 1, 16);
  const auto accel = make_scene_accelerator("bvh", s);
  const auto [seen, hidden] = cube_edges(s.meshes[0], cam, w, h);
  WireframeConfig wire;
  wire.width = 2;
  wire.nodes = {0};
  for (WireframeHidden mode : {WireframeHidden::Dim, WireframeHidden::Dashed}) {
    wire.hidden = mode;
    const std::vector<float> a = render_wireframe(s, *accel, cam, cfg, wire);
    int drawn = 0, blank = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const Vec2f c{float(x) + 0.5f, float(y) + 0.5f};
        if (nearest(seen, c) < wire.width / 2 + 1 || nearest(hidden, c) > 0.25f) continue;
        const float alpha = a[size_t(y * w + x)];
        if (mode == WireframeHidden::Dim) CHECK((alpha > 0.15f && alpha <= 0.25f));
        drawn += alpha > 0;
        blank += alpha == 0;
      }
    INFO((mode == WireframeHidden::Dim ? "dim" : "dashed")
         << ": " << drawn << " drawn, " << blank << " blank");
    CHECK(drawn > 10);
    if (mode == WireframeHidden::Dashed) CHECK(blank > 5);  // the gaps between dashes
  }
}

TEST_CASE("wireframe: the same coverage for any thread count and window split, composited over",
          "[wireframe][quick]") {
  const Scene s = cube_scene();
  const Camera cam = look_at({3, 2, 5}, {0.5f, 0, 0}, {0, 1, 0}, 0.8f);  // perspective
  const auto accel = make_scene_accelerator("embree", s);
  RenderConfig cfg = small_render_config(96, 64, 1, 16);
  const std::vector<float> whole = render_wireframe(s, *accel, cam, cfg, {});
  cfg.threads = 1;
  CHECK(render_wireframe(s, *accel, cam, cfg, {}) == whole);
  cfg.threads = 0;
  cfg.window = {10, 20, 70, 50};
  const std::vector<float> part = render_wireframe(s, *accel, cam, cfg, {});
  REQUIRE(part.size() == 60 * 30);
  for (int y = 20; y < 50; ++y)
    for (int x = 10; x < 70; ++x) REQUIRE(part[size_t((y - 20) * 60 + x - 10)] == whole[size_t(y * 96 + x)]);
  // Premultiplied "over": colour a + rgb (1 - a), alpha a + alpha (1 - a).
  Film f = make_film(2, 1);
  f.rgba = {0.2f, 0.4f, 0.6f, 1, 0, 0, 0, 0};
  overlay_wireframe(f, {0.5f, 0.25f}, {1, 0, 0});
  CHECK(f.rgba[0] == Approx(0.6f));
  CHECK(f.rgba[1] == Approx(0.2f));
  CHECK(f.rgba[3] == Approx(1));
  CHECK(f.rgba[4] == Approx(0.25f));
  CHECK(f.rgba[7] == Approx(0.25f));
}
