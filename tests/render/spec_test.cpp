// The render spec: every field of its table checked, resolved and written into the identity.
#include "render/spec.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>
#include <variant>

namespace penumbra {
namespace {

/// A value other than the default that the field accepts under `integrator`.
void perturb(RenderSpec& s, const SpecField& f) {
  std::visit(
      [&](auto member) {
        using T = std::remove_cvref_t<decltype(s.*member)>;
        if constexpr (std::is_same_v<T, std::string>) {
          if (f.name == std::string("filter")) {  // differs from both integrators' defaults
            s.*member = "gaussian";
            return;
          }
          if (f.name == std::string("focus_at")) {
            s.*member = "3,4";
            return;
          }
          if (f.name == std::string("point_size") || f.name == std::string("line_width")) {
            s.*member = "0.25";
            return;
          }
          if (f.name == std::string("wireframe_nodes")) {
            s.*member = "0,Cube";
            return;
          }
          if (f.name == std::string("wireframe_color")) {
            s.*member = "1,0.5,0";
            return;
          }
          for (const auto& c : f.choices)
            if (c != s.*member && !(f.name == std::string("integrator"))) {
              s.*member = c;
              return;
            }
        } else if constexpr (std::is_floating_point_v<T>) {
          s.*member = T(std::isinf(f.hi) ? std::max(f.lo, 0.0) + 0.25 : (f.lo + f.hi) / 2 + 0.125);
        } else if (f.name == std::string("aperture_blades")) {
          s.*member = 6;
        } else if (f.lo != 0 || f.hi != 0) {
          s.*member = T(f.lo + 1 == double(s.*member) ? f.lo + 2 : f.lo + 1);
        } else {
          s.*member = T(s.*member + 7);
        }
      },
      f.member);
}

RenderSpec with_integrator(const char* integrator) {
  RenderSpec s;
  s.integrator = integrator;
  return s;
}

/// The shutter settings that only apply with motion blur.
bool needs_motion_blur(const SpecField& f) {
  const std::string n = f.name;
  return n == "shutter" || n == "shutter_offset" || n == "motion_steps";
}

/// The lens settings that only apply with an aperture.
bool needs_aperture(const SpecField& f) {
  const std::string n = f.name;
  return n == "focus_distance" || n == "focus_at" || n == "aperture_blades" || n == "aperture_rotation" ||
         n == "aperture_ratio";
}

}  // namespace

TEST_CASE("spec: point and line sizes and wireframe settings are checked", "[spec]") {
  RenderSpec s;
  for (const char* bad : {"0", "-1px", "px", "2 px", "nan", "1e40", "2pxx", ""}) {
    s.point_size = bad;
    INFO(bad);
    CHECK_THROWS_WITH(validate(s), Catch::Contains("point_size"));
  }
  s.point_size = "3px";
  s.line_width = "inf";
  CHECK_THROWS_WITH(validate(s), Catch::Contains("line_width"));
  s.line_width = "0.01";
  CHECK_NOTHROW(validate(s));
  s.wireframe_width = 3;
  CHECK_THROWS_WITH(validate(s), Catch::Contains("wireframe_width needs wireframe"));
  s.wireframe = true;
  CHECK_NOTHROW(validate(s));
  for (const char* bad : {"1,2", "1,2,3,4", "-1,0,0", "a,b,c", "nan,0,0"}) {
    s.wireframe_color = bad;
    INFO(bad);
    CHECK_THROWS_WITH(validate(s), Catch::Contains("wireframe_color"));
  }
  s.wireframe_color = "0.2,1,0";
  const Vec3f c = parse_wireframe_color(s.wireframe_color);
  CHECK((c.x == 0.2f && c.y == 1 && c.z == 0));
  s.wireframe_hidden = "sometimes";
  CHECK_THROWS_WITH(validate(s), Catch::Contains("wireframe_hidden"));
  s.wireframe_hidden = "dim";
  s.deep = true;
  CHECK_THROWS_WITH(validate(s), Catch::Contains("wireframe with deep"));
  s.deep = false;
  s.integrator = "path";
  s.denoise = true;
  CHECK_THROWS_WITH(validate(s), Catch::Contains("wireframe with denoise"));
}

TEST_CASE("spec: every field has a flag name and a help line", "[spec]") {
  std::set<std::string> names;
  for (const SpecField& f : spec_fields()) {
    INFO(f.name);
    CHECK(names.insert(f.name).second);
    CHECK_FALSE(f.help.empty());
    CHECK(flag_name(f).rfind("--", 0) == 0);
    CHECK(flag_name(f).find('_') == std::string::npos);
  }
  CHECK(flag_name(spec_fields().front()) == "--width");
}

TEST_CASE("spec: every identity field changes the identity, the others do not", "[spec]") {
  for (const char* integrator : {"whitted", "path", "raster"}) {
    const Camera cam = frame_bounds(Bounds3f{{-1, -1, -1}, {1, 1, 1}}, 1.5f);
    for (const SpecField& f : spec_fields()) {
      if (f.name == std::string("integrator") || !(f.applies & integrator_bit(integrator))) continue;
      RenderSpec base = with_integrator(integrator);
      if (needs_aperture(f)) base.aperture_radius = 0.5f;
      if (needs_motion_blur(f)) base.motion_blur = true;
      if (f.name == std::string("denoise_main")) base.denoise = true;
      if (f.name == std::string("deep_merge_tolerance")) base.deep = true;
      if (std::string(f.name).rfind("wireframe_", 0) == 0) base.wireframe = true;
      const RenderSettings reference = render_identity(resolve(base, 1.5f), cam, {});
      RenderSpec changed = base;
      perturb(changed, f);
      INFO(integrator << " " << f.name << " = " << field_text(changed, f));
      REQUIRE(field_text(changed, f) != field_text(base, f));
      REQUIRE_NOTHROW(validate(changed));
      const RenderSettings id = render_identity(resolve(changed, 1.5f), cam, {});
      if (f.identity)
        CHECK(canonical_text(id) != canonical_text(reference));
      else
        CHECK(canonical_text(id) == canonical_text(reference));
    }
  }
}

TEST_CASE("spec: a field of another integrator, out of range or of no known value is refused by name",
          "[spec]") {
  for (const SpecField& f : spec_fields()) {
    INFO(f.name);
    for (const char* integrator : {"whitted", "path", "raster"}) {
      if (f.applies & integrator_bit(integrator)) continue;
      RenderSpec s = with_integrator(integrator);
      perturb(s, f);
      CHECK_THROWS_WITH(validate(s), Catch::Contains(std::string(f.name) + " needs integrator"));
    }
    RenderSpec s = with_integrator(f.applies & kPath ? "path" : f.applies & kWhitted ? "whitted" : "raster");
    std::visit(
        [&](auto member) {
          using T = std::remove_cvref_t<decltype(s.*member)>;
          if constexpr (std::is_same_v<T, std::string>) {
            if (f.choices.empty()) return;
            s.*member = "no-such-value";
            CHECK_THROWS_WITH(validate(s), Catch::Contains(std::string(f.name) + ": unknown value"));
          } else if (f.lo != 0 || f.hi != 0) {
            if (!std::isinf(f.hi)) {
              s.*member = T(f.hi + 1);
              CHECK_THROWS_WITH(validate(s), Catch::StartsWith(std::string(f.name) + " must be"));
            }
            const RenderSpec defaults;
            if (!std::isinf(f.lo) && T(f.lo - 1) < T(f.lo) && T(f.lo - 1) != defaults.*member) {
              s.*member = T(f.lo - 1);
              CHECK_THROWS_WITH(validate(s), Catch::StartsWith(std::string(f.name) + " must be"));
            }
          }
        },
        f.member);
  }
}

TEST_CASE("spec: colours, environments and the structure's parameters are checked", "[spec]") {
  RenderSpec s = with_integrator("path");
  s.background = Vec3f{1, 1, 1};
  CHECK_THROWS_WITH(validate(s), Catch::Contains("background applies to integrator 'whitted'"));
  s = with_integrator("whitted");
  s.env_color = Vec3f{1, 1, 1};
  CHECK_THROWS_WITH(validate(s), Catch::Contains("env_color needs integrator 'path'"));
  s = with_integrator("path");
  s.env_color = Vec3f{1, -1, 1};
  CHECK_THROWS_WITH(validate(s), Catch::Contains("env_color must be finite and >= 0"));
  s = RenderSpec{};
  s.accel = "bvh";
  s.accel_params = {"kdtree.max_depth=4"};
  CHECK_THROWS_WITH(validate(s), Catch::Contains("a parameter of 'kdtree', but accel is 'bvh'"));
  // Every structure's parameters are range-checked, the octree's and the BSP's included.
  for (const auto& [accel, param] : {std::pair{"octree", "octree.max_depth=99"},
                                     {"bsp", "bsp.traversal_cost=-1"},
                                     {"kdtree", "kdtree.max_depth=9999"},
                                     {"grid", "grid.lambda=-1"}}) {
    s.accel = accel;
    s.accel_params = {param};
    INFO(param);
    CHECK_THROWS_AS(validate(s), std::invalid_argument);
  }
  s = RenderSpec{};
  s.aovs = {"samples"};
  CHECK_THROWS_WITH(validate(s), Catch::Contains("'samples' needs integrator 'path'"));
  CHECK_THROWS_WITH(check_aovs({"depth"}, "path"), Catch::Contains("unknown AOV 'depth'"));
  CHECK(check_aovs({"all"}, "whitted").count("samples") == 0);
  CHECK(check_aovs({"all"}, "path").count("samples") == 1);
  CHECK(check_aovs({"all"}, "path").count("cost") == 0);
  CHECK(check_aovs({"all"}, "path").count("vector") == 0);
  CHECK(check_aovs({"all"}, "path").count("velocity") == 0);
  CHECK(check_aovs({"velocity"}, "whitted").count("velocity") == 1);
}

TEST_CASE("spec: defaults resolve per integrator and follow the aspect hint", "[spec]") {
  const RenderSpec w = resolve(with_integrator("whitted"), 2.0f);
  CHECK(w.width == 960);
  CHECK(w.height == 480);
  CHECK(w.spp == 4);
  CHECK(w.max_depth == 5);
  CHECK(w.filter == "box");
  CHECK(w.filter_width == 1.0f);
  RenderSpec p = with_integrator("path");
  p.height = 100;
  p = resolve(p, 2.0f);
  CHECK(p.width == 200);
  CHECK(p.spp == 64);
  CHECK(p.max_depth == 12);
  CHECK(p.filter == "blackman-harris");
  const RenderConfig cfg = make_render_config(p);
  CHECK(cfg.width == 200);
  CHECK(cfg.height == 100);
  CHECK(cfg.path.max_depth == 12);
  CHECK(cfg.filter.type == FilterType::BlackmanHarris);
}

TEST_CASE("spec: the lens takes one aperture, one focus, and its other settings only with an aperture",
          "[spec]") {
  RenderSpec s = with_integrator("path");
  s.fstop = 2;
  CHECK_NOTHROW(validate(s));
  CHECK(wants_depth_of_field(s));
  s.aperture_radius = 0.1f;
  CHECK_THROWS_WITH(validate(s), Catch::Contains("fstop and aperture_radius exclude each other"));
  s.aperture_radius = 0;
  s.focus_distance = 3;
  s.focus_at = "1,2";
  CHECK_THROWS_WITH(validate(s), Catch::Contains("focus_distance and focus_at exclude each other"));
  s.focus_distance = 0;
  for (const char* bad : {"1", "1,", ",2", "a,b", "1,2,3", "nan,1", "1, 2", "inf,0"}) {
    INFO(bad);
    s.focus_at = bad;
    CHECK_THROWS_WITH(validate(s), Catch::Contains("focus_at: '"));
  }
  s.focus_at = "-0.5,7.25";
  CHECK(parse_focus_at(s.focus_at).x == -0.5f);
  CHECK(parse_focus_at(s.focus_at).y == 7.25f);
  s.aperture_blades = 2;
  CHECK_THROWS_WITH(validate(s), Catch::Contains("aperture_blades must be 0 (round) or 3"));
  for (const char* field :
       {"focus_distance", "focus_at", "aperture_blades", "aperture_rotation", "aperture_ratio"}) {
    INFO(field);
    RenderSpec pinhole = with_integrator("whitted");
    for (const SpecField& f : spec_fields())
      if (f.name == std::string(field)) perturb(pinhole, f);
    CHECK_THROWS_WITH(validate(pinhole), Catch::Contains(std::string(field) + " needs depth of field"));
  }
}

TEST_CASE("spec: deep needs a ray-traced integrator, and its tolerance needs deep", "[spec]") {
  RenderSpec s = with_integrator("whitted");
  s.deep_merge_tolerance = 0.05f;
  CHECK_THROWS_WITH(validate(s), Catch::Contains("deep_merge_tolerance needs deep"));
  s.deep = true;
  REQUIRE_NOTHROW(validate(s));
  s.integrator = "path";
  REQUIRE_NOTHROW(validate(s));
  s.integrator = "raster";
  CHECK_THROWS_WITH(validate(s), Catch::Contains("needs integrator 'whitted' or 'path'"));
  s = with_integrator("whitted");
  s.deep = true;
  s.deep_merge_tolerance = -0.1f;
  CHECK_THROWS_WITH(validate(s), Catch::Contains("deep_merge_tolerance must be in [0, 1]"));
  // The deep image does not change the beauty: asking for it leaves the identity as it is; its
  // tolerance is part of it (stripes merged deep must share it).
  const Camera cam = frame_bounds(Bounds3f{{-1, -1, -1}, {1, 1, 1}}, 1.5f);
  s.deep_merge_tolerance = 0.01f;
  CHECK(canonical_text(render_identity(resolve(s, 1.5f), cam, {})) ==
        canonical_text(render_identity(resolve(with_integrator("whitted"), 1.5f), cam, {})));
}

TEST_CASE("spec: denoise keeps the halves, needs two samples, and denoise_main needs it", "[spec]") {
  RenderSpec s = with_integrator("path");
  s.denoise_main = "noisy";
  CHECK_THROWS_WITH(validate(s), Catch::Contains("denoise_main needs denoise"));
  s.denoise = true;
  REQUIRE_NOTHROW(validate(s));
  const RenderSpec r = resolve(s, 1.5f);
  CHECK(r.aovs.count("halves") == 1);
  CHECK(make_render_config(r).halves);
  CHECK(render_identity(r, frame_bounds(Bounds3f{{-1, -1, -1}, {1, 1, 1}}, 1.5f), {}).entries.at("halves") ==
        "1");
  s.spp = 1;
  CHECK_THROWS_WITH(validate(s), Catch::Contains("denoise needs spp >= 2"));
  CHECK_FALSE(make_render_config(resolve(with_integrator("path"), 1.5f)).halves);
  // "all" leaves the halves out (twenty float channels only a denoiser reads); they are path-only.
  CHECK(check_aovs({"all"}, "path").count("halves") == 0);
  CHECK(check_aovs({"halves"}, "path").count("halves") == 1);
  CHECK_THROWS_WITH(check_aovs({"halves"}, "whitted"), Catch::Contains("'halves' needs integrator 'path'"));
}

}  // namespace penumbra
