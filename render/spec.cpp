// The render settings spec: its table of fields, checks, defaults and identity.
#include "render/spec.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "render/accel_params.h"
#include "renderer/accel/factory.h"
#include "renderer/film/filter.h"
#include "renderer/scene/curve_size.h"

#ifndef PENUMBRA_VERSION
#define PENUMBRA_VERSION "unknown"
#endif

namespace penumbra {

namespace {

constexpr double kAny = std::numeric_limits<double>::infinity();

std::string join(const std::vector<std::string>& names, const char* last = ", ") {
  std::string r;
  for (size_t i = 0; i < names.size(); ++i)
    r += (i == 0 ? "" : i + 1 == names.size() ? last : ", ") + names[i];
  return r;
}

/// Shortest text that reads back to the same float or double.
template <class T>
std::string exact(T v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", std::numeric_limits<T>::max_digits10, double(v));
  return buf;
}

std::string colour_text(Vec3f c) {
  return exact(c.x) + "," + exact(c.y) + "," + exact(c.z);
}

std::vector<SpecField> make_fields() {
  using S = RenderSpec;
  const std::vector<std::string> filters = {"box", "tent", "gaussian", "blackman-harris"};
  return {
      {"width",
       &S::width,
       kAnyIntegrator,
       true,
       1,
       16384,
       {},
       "image width in pixels (default 960, or from --height and the camera aspect)"},
      {"height",
       &S::height,
       kAnyIntegrator,
       true,
       1,
       16384,
       {},
       "image height in pixels (default: width / camera aspect)"},
      {"integrator",
       &S::integrator,
       kAnyIntegrator,
       true,
       0,
       0,
       {"whitted", "path", "raster"},
       "whitted (default: Blinn-Phong shading, shadows and mirror reflections; fast), path (physically based "
       "path tracer) or raster (rasterised preview with Whitted's local shading)"},
      {"raster_shadows",
       &S::raster_shadows,
       kRaster,
       true,
       0,
       0,
       {"ray", "map", "none"},
       "raster: light visibility by shadow rays (ray, default), shadow maps (map) or none"},
      {"shadows",
       &S::shadows,
       kWhitted,
       true,
       0,
       0,
       {"on", "off"},
       "whitted: on (default) traces shadow rays; off lights every surface as if nothing stood between it "
       "and "
       "the lights, so that no object shades another (primary-visibility renders for deep holdouts)"},
      {"shadow_map_size",
       &S::shadow_map_size,
       kRaster,
       true,
       16,
       8192,
       {},
       "raster: shadow map texels on a side (default 1024; point lights: per cube face)"},
      {"spp",
       &S::spp,
       kAnyIntegrator,
       false,
       1,
       65536,
       {},
       "samples per pixel (default 4 for whitted, 64 for path; with --adaptive the maximum)"},
      {"max_depth",
       &S::max_depth,
       kWhitted | kPath,
       true,
       0,
       64,
       {},
       "whitted: maximum mirror bounces (default 5); path: maximum bounces, 0 = direct light only (default "
       "12)"},
      {"rr_depth",
       &S::rr_depth,
       kPath,
       true,
       1,
       64,
       {},
       "path: Russian roulette from this bounce on (default 3)"},
      {"clamp_indirect",
       &S::clamp_indirect,
       kPath,
       true,
       0,
       kAny,
       {},
       "path: clamp each indirect sample's largest channel to this radiance; biased, trades fireflies for "
       "energy (default 0 = off)"},
      {"light_sampling",
       &S::light_sampling,
       kPath,
       true,
       0,
       0,
       {"mis", "bsdf", "light"},
       "path: mis (default), bsdf (BSDF sampling only) or light (light sampling only); the single techniques "
       "are for validation"},
      {"sampler",
       &S::sampler,
       kPath,
       true,
       0,
       0,
       {"sobol", "independent"},
       "path: sobol (Owen-scrambled, default) or independent (PCG32)"},
      {"energy_compensation",
       &S::energy_compensation,
       kPath,
       true,
       0,
       0,
       {"on", "off"},
       "path: on (default) adds the energy rough GGX reflection loses to single scattering (Kulla-Conty); "
       "off "
       "for comparisons with renderers without it (Cycles 3.4's Principled BSDF)"},
      {"light_sampler",
       &S::light_sampler,
       kPath,
       true,
       0,
       0,
       {"tree", "power", "uniform"},
       "path: how an emissive triangle or shape (or a point or spot light, past eight of them) is "
       "chosen for a light sample: power (default; in proportion to power), tree (a light BVH, by "
       "importance at the shading point: for lights spread far apart) or uniform (for tests)"},
      {"light_samples",
       &S::light_samples,
       kPath,
       true,
       1,
       64,
       {},
       "path: lights chosen at each vertex, each with its own shadow ray (default 1); more lowers the "
       "noise of direct light at the cost of shadow rays"},
      {"denoise",
       &S::denoise,
       kPath,
       true,
       0,
       0,
       {},
       "path: denoise the beauty with NFOR feature regression from the even and odd samples' halves "
       "(the 'halves' layers, kept in the EXR); needs at least 2 spp (default off)"},
      {"denoise_main",
       &S::denoise_main,
       kPath,
       true,
       0,
       0,
       {"denoised", "noisy"},
       "path with denoise: which beauty is the main layer (R, G, B, A): denoised (default; the noisy one "
       "is kept as noisy.RGBA) or noisy (the denoised one written as denoised.RGBA)"},
      {"env_intensity", &S::env_intensity, kPath, true, 0, kAny, {}, "path: multiplies --env (default 1)"},
      {"env_rotation",
       &S::env_rotation,
       kPath,
       true,
       -kAny,
       kAny,
       {},
       "path: turns the --env map about +Y, degrees (default 0)"},
      {"time_limit",
       &S::time_limit,
       kPath,
       false,
       0,
       kAny,
       {},
       "path: stop after the pass that would run past this many seconds (default 0 = none)"},
      {"adaptive",
       &S::adaptive,
       kPath,
       true,
       0,
       kAny,
       {},
       "path: adaptive sampling threshold, e.g. 0.01: a pixel stops once its error estimate is below it "
       "(default 0 = off)"},
      {"adaptive_min_spp",
       &S::adaptive_min_spp,
       kPath,
       true,
       2,
       65536,
       {},
       "path: samples every pixel takes before --adaptive may stop it (default 16)"},
      {"filter", &S::filter, kAnyIntegrator, true, 0, 0, filters,
       "pixel filter: box, tent, gaussian or blackman-harris (default: box for whitted, blackman-harris for "
       "path)"},
      {"filter_width",
       &S::filter_width,
       kAnyIntegrator,
       true,
       0,
       16,
       {},
       "pixel filter width in pixels (default: box 1, tent 2, gaussian 3, blackman-harris 1.5)"},
      {"seed",
       &S::seed,
       kAnyIntegrator,
       true,
       0,
       0,
       {},
       "sampler seed, an integer in [0, 2^64 - 1] (default 0)"},
      {"threads", &S::threads, kAnyIntegrator, false, 0, 1024, {}, "worker threads (default 0 = all cores)"},
      {"tile_size",
       &S::tile_size,
       kAnyIntegrator,
       false,
       1,
       4096,
       {},
       "pixels on a side of the tiles threads take (default 32; does not change pixels)"},
      {"fstop",
       &S::fstop,
       kAnyIntegrator,
       true,
       0,
       1e6,
       {},
       "depth of field: the lens' f-number (aperture diameter = focal length / N; the focal length from "
       "--focal-length, else the field of view on a 36 mm sensor; metres as scene units) (default 0 = none)"},
      {"aperture_radius",
       &S::aperture_radius,
       kAnyIntegrator,
       true,
       0,
       kAny,
       {},
       "depth of field: the aperture radius in scene units, instead of --fstop (default 0 = none)"},
      {"focus_distance",
       &S::focus_distance,
       kAnyIntegrator,
       true,
       0,
       kAny,
       {},
       "depth of field: distance of the plane in focus along the view axis (default: autofocus)"},
      {"focus_at",
       &S::focus_at,
       kAnyIntegrator,
       true,
       0,
       0,
       {},
       "depth of field: autofocus on what pixel X,Y shows (default: the image centre)"},
      {"aperture_blades",
       &S::aperture_blades,
       kAnyIntegrator,
       true,
       0,
       kMaxApertureBlades,
       {},
       "depth of field: a polygonal aperture of N blades (bokeh shape) (default 0 = round)"},
      {"aperture_rotation",
       &S::aperture_rotation,
       kAnyIntegrator,
       true,
       -kAny,
       kAny,
       {},
       "depth of field: the polygonal aperture's turn, degrees (default 0)"},
      {"aperture_ratio",
       &S::aperture_ratio,
       kAnyIntegrator,
       true,
       0.01,
       100,
       {},
       "depth of field: anamorphic aperture height / width; > 1 stretches bokeh vertically (default 1)"},
      {"fps",
       &S::fps,
       kAnyIntegrator,
       false,
       1e-3,
       1e6,
       {},
       "frames per second: --frame N renders time N / fps, the shutter is a fraction of 1 / fps, and --aov "
       "vector's frames lie 1 / fps away (default 24)"},
      {"motion_blur",
       &S::motion_blur,
       kAnyIntegrator,
       true,
       0,
       0,
       {},
       "motion blur: each camera sample sees the animation at a time within the shutter (default off)"},
      {"shutter",
       &S::shutter,
       kAnyIntegrator,
       true,
       0,
       4,
       {},
       "motion blur: the shutter's length as a fraction of the frame interval 1 / --fps (default 0.5)"},
      {"shutter_offset",
       &S::shutter_offset,
       kAnyIntegrator,
       true,
       -4,
       4,
       {},
       "motion blur: the shutter's centre after the frame's time, in frames (default 0: centred)"},
      {"motion_steps",
       &S::motion_steps,
       kAnyIntegrator,
       true,
       2,
       64,
       {},
       "motion blur: time samples of each moving transform over the shutter, slerped between (default 3)"},
      {"accel", &S::accel, kAnyIntegrator, true, 0, 0, accelerator_names(),
       "acceleration structure: " + accelerator_list() +
           " (default embree; brute is a linear scan, for tests)"},
      {"crypto_depth",
       &S::crypto_depth,
       kAnyIntegrator,
       false,
       1,
       16,
       {},
       "Cryptomatte ranks (id, coverage pairs) kept per pixel (default 6: three RGBA layers)"},
      {"deep",
       &S::deep,
       kWhitted | kPath,
       false,
       0,
       0,
       {},
       "also a deep image: per pixel one sample per surface (R G B A Z ZBack id N albedo), from the beauty's "
       "own "
       "camera samples traced again (the command's --deep FILE.exr)"},
      {"deep_merge_tolerance",
       &S::deep_merge_tolerance,
       kWhitted | kPath,
       true,
       0,
       1,
       {},
       "deep output: a surface's camera samples in a pixel merge into one deep sample when their depths "
       "differ "
       "by at most this fraction of the nearest one's (default 0.01; 0: equal depths only)"},
      {"point_size",
       &S::point_size,
       kAnyIntegrator,
       true,
       0,
       0,
       {},
       "diameter of glTF points whose file gives none (PENUMBRA_points): pixels (2px) or scene units "
       "(0.01) (default 2px)"},
      {"line_width",
       &S::line_width,
       kAnyIntegrator,
       true,
       0,
       0,
       {},
       "width of glTF lines whose file gives none (PENUMBRA_points): pixels (1px) or scene units (0.005) "
       "(default 1px)"},
      {"wireframe",
       &S::wireframe,
       kAnyIntegrator,
       true,
       0,
       0,
       {},
       "draw the triangle edges over the image, hidden ones hidden, and write them as the wireframe layer "
       "(default off)"},
      {"wireframe_nodes",
       &S::wireframe_nodes,
       kAnyIntegrator,
       true,
       0,
       0,
       {},
       "wireframe: the nodes whose edges are drawn, comma-separated names or indices (default: every node)"},
      {"wireframe_width",
       &S::wireframe_width,
       kAnyIntegrator,
       true,
       0.25,
       64,
       {},
       "wireframe: line width in pixels (default 1)"},
      {"wireframe_color",
       &S::wireframe_color,
       kAnyIntegrator,
       true,
       0,
       0,
       {},
       "wireframe: linear RGB of the lines, R,G,B (default 0,0,0)"},
      {"wireframe_hidden",
       &S::wireframe_hidden,
       kAnyIntegrator,
       true,
       0,
       0,
       {"off", "dim", "dashed"},
       "wireframe: edges behind surfaces: off (not drawn), dim (at a quarter opacity) or dashed (default "
       "off)"},
  };
}

const char* integrator_names(unsigned mask) {
  switch (mask) {
    case kWhitted:
      return "'whitted'";
    case kPath:
      return "'path'";
    case kRaster:
      return "'raster'";
    case kWhitted | kPath:
      return "'whitted' or 'path'";
    case kWhitted | kRaster:
      return "'whitted' or 'raster'";
    default:
      return "'path' or 'raster'";
  }
}

/// Range, choices and integrator of one field. `defaults` is a default-constructed spec.
void check_field(const RenderSpec& s, const SpecField& f, const RenderSpec& defaults) {
  const bool is_default = field_text(s, f) == field_text(defaults, f);
  std::visit(
      [&](auto member) {
        using T = std::remove_cvref_t<decltype(s.*member)>;
        if constexpr (std::is_same_v<T, std::string>) {
          const std::string& v = s.*member;
          if (!f.choices.empty() && !is_default &&
              std::find(f.choices.begin(), f.choices.end(), v) == f.choices.end())
            throw std::invalid_argument(std::string(f.name) + ": unknown value '" + v +
                                        "' (known: " + join(f.choices) + ")");
        } else if (f.lo != 0 || f.hi != 0) {
          const double v = double(s.*member);
          if (is_default) return;
          if (std::isinf(f.hi)) {
            if (!std::isfinite(v) || v < f.lo)
              throw std::invalid_argument(std::string(f.name) + " must be finite" +
                                          (std::isinf(f.lo) ? "" : " and >= " + exact(f.lo)));
          } else if (!(v >= f.lo && v <= f.hi)) {
            throw std::invalid_argument(std::string(f.name) + " must be in [" + exact(f.lo) + ", " +
                                        exact(f.hi) + "] (" + field_text(defaults, f) + ": the default)");
          }
        }
      },
      f.member);
  if (!is_default && !(f.applies & integrator_bit(s.integrator)))
    throw std::invalid_argument(std::string(f.name) + " needs integrator " + integrator_names(f.applies));
}

void check_colour(const char* setting, const std::optional<Vec3f>& c) {
  if (!c) return;
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite((*c)[k]) || (*c)[k] < 0)
      throw std::invalid_argument(std::string(setting) + " must be finite and >= 0 in every channel");
}

/// The colours and the environment: each finite and non-negative, each of its integrator.
void check_lights(const RenderSpec& s) {
  check_colour("background", s.background);
  check_colour("ambient", s.ambient);
  check_colour("env_color", s.env_color);
  if (s.env_color && !s.env_map.empty())
    throw std::invalid_argument("env_color and env_map exclude each other");
  const bool path = s.integrator == "path";
  if (path && (s.background || s.ambient))
    throw std::invalid_argument(std::string(s.background ? "background" : "ambient") +
                                " applies to integrator 'whitted'; the path tracer is lit by the scene's "
                                "lights and env_color / env_map");
  if (!path && (s.env_color || !s.env_map.empty()))
    throw std::invalid_argument(std::string(s.env_color ? "env_color" : "env_map") +
                                " needs integrator 'path'");
}

/// The lens and shutter settings: one aperture, one focus, and the others only with an aperture;
/// the shutter's only with motion blur.
void check_camera_settings(const RenderSpec& s) {
  if (s.fstop > 0 && s.aperture_radius > 0)
    throw std::invalid_argument("fstop and aperture_radius exclude each other (one sets the other)");
  if (s.focus_distance > 0 && !s.focus_at.empty())
    throw std::invalid_argument("focus_distance and focus_at exclude each other");
  if (!s.focus_at.empty()) parse_focus_at(s.focus_at);
  if (s.aperture_blades == 1 || s.aperture_blades == 2)
    throw std::invalid_argument("aperture_blades must be 0 (round) or 3 to " +
                                std::to_string(kMaxApertureBlades));
  const RenderSpec defaults;
  if (!s.motion_blur)
    for (const char* name : {"shutter", "shutter_offset", "motion_steps"})
      for (const SpecField& f : spec_fields())
        if (name == std::string(f.name) && field_text(s, f) != field_text(defaults, f))
          throw std::invalid_argument(std::string(name) + " needs motion_blur");
  if (wants_depth_of_field(s)) return;
  for (const char* name :
       {"focus_distance", "focus_at", "aperture_blades", "aperture_rotation", "aperture_ratio"})
    for (const SpecField& f : spec_fields())
      if (name == std::string(f.name) && field_text(s, f) != field_text(defaults, f))
        throw std::invalid_argument(std::string(name) + " needs depth of field: fstop or aperture_radius");
}

}  // namespace

bool wants_depth_of_field(const RenderSpec& spec) {
  return spec.fstop > 0 || spec.aperture_radius > 0;
}

Vec2f parse_focus_at(const std::string& text) {
  const auto fail = [&] {
    return std::invalid_argument("focus_at: '" + text + "' is not a pixel X,Y (two finite numbers)");
  };
  const size_t comma = text.find(',');
  if (comma == std::string::npos) throw fail();
  float p[2];
  for (int k = 0; k < 2; ++k) {
    const std::string part = k == 0 ? text.substr(0, comma) : text.substr(comma + 1);
    size_t used = 0;
    try {
      p[k] = std::stof(part, &used);
    } catch (const std::exception&) {
      throw fail();
    }
    if (part.empty() || used != part.size() || !std::isfinite(p[k]) || std::isspace((unsigned char)part[0]))
      throw fail();
  }
  return {p[0], p[1]};
}

const std::vector<SpecField>& spec_fields() {
  static const std::vector<SpecField> fields = make_fields();
  return fields;
}

std::string flag_name(const SpecField& field) {
  std::string f = std::string("--") + field.name;
  std::replace(f.begin(), f.end(), '_', '-');
  return f;
}

std::string field_text(const RenderSpec& spec, const SpecField& field) {
  return std::visit(
      [&](auto member) -> std::string {
        using T = std::remove_cvref_t<decltype(spec.*member)>;
        if constexpr (std::is_same_v<T, std::string>)
          return spec.*member;
        else if constexpr (std::is_floating_point_v<T>)
          return exact(spec.*member);
        else
          return std::to_string(spec.*member);
      },
      field.member);
}

unsigned integrator_bit(const std::string& integrator) {
  return integrator == "path" ? kPath : integrator == "raster" ? kRaster : kWhitted;
}

const std::vector<std::string>& aov_names() {
  static const std::vector<std::string> names = {"albedo",
                                                 "N",
                                                 "P",
                                                 "Z",
                                                 "UV",
                                                 "id",
                                                 "samples",
                                                 "variance",
                                                 "light",
                                                 "halves",
                                                 "cost",
                                                 "crypto_object",
                                                 "crypto_material",
                                                 "crypto_asset",
                                                 "vector",
                                                 "velocity"};
  return names;
}

std::set<std::string> check_aovs(const std::vector<std::string>& names, const std::string& integrator,
                                 const std::vector<std::string>& known) {
  const bool path = integrator == "path";
  const auto is_path_layer = [](const std::string& n) {
    return n == "samples" || n == "variance" || n == "light" || n == "halves";
  };
  std::set<std::string> aovs;
  for (const auto& name : names) {
    if (name == "all") {
      for (const auto& n : known)
        if (n != "cost" && n != "vector" && n != "velocity" && n != "halves" && (path || !is_path_layer(n)))
          aovs.insert(n);
      continue;
    }
    if (std::find(known.begin(), known.end(), name) == known.end())
      throw std::invalid_argument("unknown AOV '" + name + "' (known: " + join(known) + ", all)");
    if (!path && is_path_layer(name)) throw std::invalid_argument("'" + name + "' needs integrator 'path'");
    aovs.insert(name);
  }
  return aovs;
}

void validate(const RenderSpec& s) {
  const RenderSpec defaults;
  // The integrator first: every other field's check depends on it.
  for (const SpecField& f : spec_fields())
    if (std::string(f.name) == "integrator") check_field(s, f, defaults);
  for (const SpecField& f : spec_fields()) check_field(s, f, defaults);
  if (s.width < 0 || s.height < 0) throw std::invalid_argument("width and height must be >= 0");
  check_lights(s);
  check_camera_settings(s);
  accel_config(s.accel, s.accel_params);
  for (const auto& name : s.aovs) check_aovs({name}, s.integrator, aov_names());
  if (s.denoise && s.spp == 1)
    throw std::invalid_argument("denoise needs spp >= 2 (it compares the even and odd samples)");
  if (!s.denoise && s.denoise_main != defaults.denoise_main)
    throw std::invalid_argument("denoise_main needs denoise");
  if (!s.deep && s.deep_merge_tolerance != defaults.deep_merge_tolerance)
    throw std::invalid_argument("deep_merge_tolerance needs deep (the command's --deep FILE.exr)");
  parse_curve_size(s.point_size, "point_size");
  parse_curve_size(s.line_width, "line_width");
  parse_wireframe_color(s.wireframe_color);
  if (s.wireframe && s.deep)
    throw std::invalid_argument(
        "wireframe with deep: the deep image holds the surfaces, not the overlay; render the wireframe "
        "layer (wireframe.A) in the flat image and composite it after the deep merge");
  if (s.wireframe && s.denoise)
    throw std::invalid_argument(
        "wireframe with denoise: the overlay would be denoised with the beauty; render the wireframe "
        "without denoise and composite its layer (wireframe.A) over the denoised image");
  if (!s.wireframe)
    for (const char* name : {"wireframe_nodes", "wireframe_width", "wireframe_color", "wireframe_hidden"})
      for (const SpecField& f : spec_fields())
        if (f.name == std::string(name) && field_text(s, f) != field_text(defaults, f))
          throw std::invalid_argument(std::string(name) + " needs wireframe");
  // The renderer's own range checks (tile size, threads, depths) on a stand-in size.
  RenderConfig probe = make_render_config(resolve(s, 16.0f / 9.0f));
  probe.window = {};
  validate(probe);
}

Vec3f parse_wireframe_color(const std::string& text) {
  Vec3f c;
  int used = 0;
  if (std::sscanf(text.c_str(), "%f,%f,%f%n", &c.x, &c.y, &c.z, &used) != 3 || size_t(used) != text.size() ||
      !is_finite(c) || c.x < 0 || c.y < 0 || c.z < 0)
    throw std::invalid_argument("wireframe_color: '" + text +
                                "' is not a colour (three finite non-negative numbers R,G,B)");
  return c;
}

RenderSpec resolve(const RenderSpec& s, float hint) {
  RenderSpec r = s;
  const bool path = s.integrator == "path";
  if (r.denoise) r.aovs.insert("halves");
  if (!r.width && !r.height) r.width = 960;
  if (!r.height) r.height = std::max(1, int(std::lround(float(r.width) / hint)));
  if (!r.width) r.width = std::max(1, int(std::lround(float(r.height) * hint)));
  if (r.spp <= 0) r.spp = path ? 64 : 4;
  FilterType type = path ? FilterType::BlackmanHarris : FilterType::Box;
  if (!r.filter.empty()) parse_filter_type(r.filter, type);
  r.filter = filter_name(type);
  if (!(r.filter_width > 0)) r.filter_width = default_filter_width(type);
  if (r.max_depth < 0) r.max_depth = path ? 12 : 5;
  return r;
}

RenderConfig make_render_config(const RenderSpec& r) {
  RenderConfig cfg;
  cfg.width = r.width;
  cfg.height = r.height;
  cfg.window = r.window;
  cfg.spp = r.spp;
  cfg.threads = r.threads;
  cfg.tile_size = r.tile_size;
  cfg.seed = r.seed;
  FilterType type = FilterType::Box;
  parse_filter_type(r.filter, type);
  cfg.filter = make_filter(type, r.filter_width);
  cfg.whitted.max_depth = r.max_depth;
  cfg.whitted.background = r.background.value_or(Vec3f{0, 0, 0});
  cfg.whitted.ambient = r.ambient.value_or(Vec3f{0.05f, 0.05f, 0.05f});
  cfg.whitted.shadows = r.shadows == "on";
  cfg.raster.shadows = r.raster_shadows == "map"    ? RasterShadows::Map
                       : r.raster_shadows == "none" ? RasterShadows::None
                                                    : RasterShadows::Ray;
  cfg.raster.shadow_map_size = r.shadow_map_size;
  cfg.path.max_depth = r.max_depth;
  cfg.path.rr_depth = r.rr_depth;
  cfg.path.clamp_indirect = r.clamp_indirect;
  cfg.path.strategy = r.light_sampling == "bsdf"    ? LightStrategy::Bsdf
                      : r.light_sampling == "light" ? LightStrategy::Light
                                                    : LightStrategy::Mis;
  cfg.path.energy_compensation = r.energy_compensation == "on";
  cfg.path.light_sampler = r.light_sampler == "tree"      ? LightSampler::Tree
                           : r.light_sampler == "uniform" ? LightSampler::Uniform
                                                          : LightSampler::Power;
  cfg.path.light_samples = r.light_samples;
  cfg.sampler = r.sampler == "independent" ? SamplerType::Independent : SamplerType::Sobol;
  cfg.time_limit = r.time_limit;
  cfg.adaptive_threshold = r.adaptive;
  cfg.adaptive_min_spp = r.adaptive_min_spp;
  cfg.light_groups = r.aovs.count("light") > 0;
  cfg.halves = r.aovs.count("halves") > 0;
  cfg.motion_blur = r.motion_blur;
  return cfg;
}

RenderSettings render_identity(const RenderSpec& r, const Camera& camera, const SceneIdentity& scene) {
  std::map<std::string, std::string> e;
  e["version"] = PENUMBRA_VERSION;  // another renderer version may sample differently
  e["scene.sha256"] = scene.sha256;
  e["scene.index"] = std::to_string(scene.index);
  e["scene.flatten"] = scene.flatten ? "1" : "0";
  e["scene.variant"] = scene.variant.empty() ? "none" : scene.variant;
  e["scene.time"] = scene.time;
  if (!scene.shutter.empty()) e["scene.shutter"] = scene.shutter;
  e["camera"] = scene.camera.empty() ? "default '" + camera.name + "'" : scene.camera;
  // The camera as rendered, whichever flags or file placed it.
  const auto vec = [](Vec3f v) { return exact(v.x) + "," + exact(v.y) + "," + exact(v.z); };
  e["camera.frame"] = vec(camera.eye) + " u " + vec(camera.u) + " v " + vec(camera.v) + " w " + vec(camera.w);
  if (!camera.motion.empty()) {
    std::string keys;
    for (const MotionKey& k : camera.motion) {
      if (!keys.empty()) keys.append(" | ");
      keys.append(vec(k.translation)).append(" q ");
      for (double q : {k.rotation.x, k.rotation.y, k.rotation.z, k.rotation.w})
        keys.append(exact(q)).append(",");
      keys.append("u");
      for (float u : k.u) keys.append(",").append(exact(u));
    }
    e["camera.motion"] = keys;
  }
  e["camera.lens"] =
      (camera.projection == Projection::Orthographic ? "orthographic ymag " + exact(camera.ymag)
                                                     : "perspective yfov " + exact(camera.yfov)) +
      " near " + exact(camera.znear) + " far " + exact(camera.zfar);
  if (camera.lens.radius > 0)
    e["camera.lens"] += " aperture " + exact(camera.lens.radius) + " focus " +
                        exact(camera.lens.focus_distance) + " blades " + std::to_string(camera.lens.blades) +
                        " rotation " + exact(camera.lens.rotation) + " ratio " + exact(camera.lens.ratio);
  const unsigned bit = integrator_bit(r.integrator);
  for (const SpecField& f : spec_fields())
    if (f.identity && (f.applies & bit)) e[f.name] = field_text(r, f);
  for (const auto& p : r.accel_params) e["accel." + p.substr(0, p.find('='))] = p.substr(p.find('=') + 1);
  if (bit == kPath) {
    e["env"] = r.env_color ? colour_text(*r.env_color) : r.env_map.empty() ? "none" : r.env_map;
    if (!scene.env_sha256.empty()) e["env.sha256"] = scene.env_sha256;
    e["light_groups"] = r.aovs.count("light") ? "1" : "0";
    e["halves"] = r.aovs.count("halves") ? "1" : "0";
  } else {
    e["background"] = colour_text(r.background.value_or(Vec3f{0, 0, 0}));
    e["ambient"] = colour_text(r.ambient.value_or(Vec3f{0.05f, 0.05f, 0.05f}));
  }
  if (r.aovs.count("vector") || r.aovs.count("velocity")) {
    e["vector.fps"] = exact(r.fps);
    if (!scene.vector_cameras.empty()) e["vector.cameras"] = scene.vector_cameras;
  }
  return {e};
}

}  // namespace penumbra
