// Tests for renderer/raster/clip.h: near-plane clipping of a triangle crossing the camera
// plane, trivial accept and reject, and crack-free shared edges.
#include "renderer/raster/clip.h"

#include <catch2/catch.hpp>

#include "renderer/scene/camera.h"

using namespace penumbra;

namespace {
// Clip-space vertex of world point p under the camera (aspect 1), with its depth.
ClipVertex vertex(const Camera& cam, Vec3f p, int k) {
  const Transform m = projection_matrix(cam, 1) * view_matrix(cam);
  double c[4];
  for (int r = 0; r < 4; ++r)
    c[r] = m.m[size_t(r)][0] * p.x + m.m[size_t(r)][1] * p.y + m.m[size_t(r)][2] * p.z + m.m[size_t(r)][3];
  ClipVertex v;
  v.p = {float(c[0]), float(c[1]), float(c[2]), float(c[3])};
  v.b[k] = 1;
  v.depth = dot(p - cam.eye, -cam.w);
  return v;
}
}  // namespace

TEST_CASE("clip: a triangle crossing the camera plane is cut at the near plane", "[raster][quick]") {
  Camera cam = look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1.2f);
  cam.znear = 0.1f;
  // Two vertices in front (depth 1 and 2), one behind the camera (depth -1); narrow enough that
  // the guard band does not cut it too.
  const Vec3f P[3] = {{-0.05f, 0, -1}, {0.05f, 0, -2}, {0, 0.01f, 1}};
  ClipVertex in[3];
  for (int k = 0; k < 3; ++k) in[k] = vertex(cam, P[k], k);
  const ClipPlanes planes{false, 2.0f};
  CHECK((clip_outcode(in[2].p, planes) & 1u) != 0);  // behind: outside the near plane
  CHECK(clip_outcode(in[0].p, planes) == 0);
  ClipVertex out[kMaxClipVertices];
  const int n = clip_triangle(in, planes, out);
  REQUIRE(n == 4);  // the triangle minus a corner: a quadrilateral
  int on_near = 0;
  for (int i = 0; i < n; ++i) {
    const ClipVertex& v = out[i];
    CHECK(v.p.z + v.p.w >= -1e-6f * v.p.w);  // in front of (or on) the near plane
    CHECK(v.p.w > 0);
    CHECK(v.b[0] + v.b[1] + v.b[2] == Approx(1).margin(1e-6));
    // The barycentrics name the same point as the clip position: project it again.
    const Vec3f p = P[0] * v.b[0] + P[1] * v.b[1] + P[2] * v.b[2];
    const ClipVertex again = vertex(cam, p, 0);
    CHECK(again.p.x == Approx(v.p.x).margin(1e-5));
    CHECK(again.p.w == Approx(v.p.w).margin(1e-5));
    CHECK(v.depth == Approx(again.depth).margin(1e-5));
    if (std::fabs(v.depth - 0.1f) < 1e-5f) ++on_near;
  }
  CHECK(on_near == 2);  // the two new vertices lie on the near plane, depth = znear
}

TEST_CASE("clip: trivial accept, reject, and crack-free shared edges", "[raster][quick]") {
  Camera cam = look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1.2f);
  cam.znear = 0.1f;
  cam.zfar = 10;
  const ClipPlanes planes{true, 2.0f};
  ClipVertex in[3] = {vertex(cam, {-1, 0, -3}, 0), vertex(cam, {1, 0, -3}, 1), vertex(cam, {0, 1, -3}, 2)};
  ClipVertex out[kMaxClipVertices];
  CHECK(clip_triangle(in, planes, out) == 3);
  // Entirely behind the camera, or beyond the far plane: nothing remains.
  ClipVertex behind[3] = {vertex(cam, {-1, 0, 3}, 0), vertex(cam, {1, 0, 3}, 1), vertex(cam, {0, 1, 3}, 2)};
  CHECK(clip_triangle(behind, planes, out) == 0);
  ClipVertex far[3] = {vertex(cam, {-1, 0, -30}, 0), vertex(cam, {1, 0, -30}, 1),
                       vertex(cam, {0, 1, -30}, 2)};
  CHECK((clip_outcode(far[0].p, planes) & clip_outcode(far[1].p, planes) & clip_outcode(far[2].p, planes)) !=
        0);
  // Two triangles sharing the edge a-b that crosses the near plane, given in opposite
  // directions: the vertex each gets on the plane is bit-identical.
  const Vec3f a{0, -0.05f, 0.5f}, b{0.3f, 0.2f, -4}, c{-2, 0, -3}, d{2, 0, -3};
  ClipVertex t1[3] = {vertex(cam, a, 0), vertex(cam, b, 1), vertex(cam, c, 2)};
  ClipVertex t2[3] = {vertex(cam, b, 0), vertex(cam, a, 1), vertex(cam, d, 2)};
  ClipVertex o1[kMaxClipVertices], o2[kMaxClipVertices];
  const int n1 = clip_triangle(t1, planes, o1), n2 = clip_triangle(t2, planes, o2);
  REQUIRE(n1 >= 3);
  REQUIRE(n2 >= 3);
  int shared = 0;
  for (int i = 0; i < n1; ++i)
    for (int j = 0; j < n2; ++j)
      if (std::fabs(o1[i].depth - 0.1f) < 1e-4f && o1[i].p.x == o2[j].p.x && o1[i].p.y == o2[j].p.y &&
          o1[i].p.z == o2[j].p.z && o1[i].p.w == o2[j].p.w)
        ++shared;
  CHECK(shared == 1);
}
