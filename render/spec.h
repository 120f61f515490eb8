// The one typed description of a render that every front end fills: RenderSpec. The command
// line's flags, the Python module's keyword arguments and the benchmark all describe a render
// with it, check it with validate(), resolve it into the renderer's RenderConfig with
// make_render_config() and derive the render's identity (the canonical settings that resume
// state and tiles carry) from it with render_identity().
//
// spec_fields() lists every scalar setting once, with its name, type, range or choices, the
// integrators it applies to and whether it decides pixels. The command registers a flag per
// entry (--name-with-dashes), the Python module an attribute and keyword per entry, validate()
// checks each entry and render_identity() writes each pixel-deciding entry: a setting added to
// the table reaches all of them.
#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "io/farm/render_settings.h"
#include "renderer/integrators/render_config.h"
#include "renderer/scene/camera.h"

namespace penumbra {

/// A render as asked for; zero or empty fields take the documented defaults when resolved.
struct RenderSpec {
  int width = 0, height = 0;  ///< 0 and 0: 960 wide; one 0: follows the camera's aspect hint
  PixelWindow window;         ///< the pixels rendered (a crop or tile); empty: the whole frame
  int spp = 0;                ///< 0: 4 (whitted, raster) or 64 (path)
  uint64_t seed = 0;
  int threads = 0;  ///< 0: every hardware thread (does not change pixels)
  int tile_size = 32;
  std::string camera;  ///< index (digits) or name; empty: the first camera, else framing the bounds
  std::string integrator = "whitted";        ///< whitted, path or raster
  std::string filter;                        ///< box, tent, gaussian, blackman-harris; empty: per integrator
  float filter_width = 0;                    ///< pixels; 0: the filter's default width
  int max_depth = -1;                        ///< -1: 5 mirror bounces (whitted), 12 bounces (path)
  std::optional<Vec3f> background, ambient;  ///< whitted and raster; unset: black, 0.05 grey
  std::string raster_shadows = "ray";        ///< raster: ray, map or none
  int shadow_map_size = 1024;                ///< raster with map shadows: texels on a side
  int rr_depth = 3;                          ///< path: Russian roulette from this bounce on
  float clamp_indirect = 0;                  ///< path: 0 = off
  std::string light_sampling = "mis";        ///< path: mis, bsdf or light
  std::string sampler = "sobol";             ///< path: sobol or independent
  std::string energy_compensation = "on";    ///< path: on or off (multiple-scattering GGX)
  std::string light_sampler = "power";       ///< path: tree, power or uniform (choosing an area light)
  int light_samples = 1;                     ///< path: lights chosen at each vertex, each with its shadow ray
  bool denoise = false;                   ///< path: denoise the beauty (render/denoise.h); implies "halves"
  std::string denoise_main = "denoised";  ///< path with denoise: the main layer, denoised or noisy
  std::optional<Vec3f> env_color;         ///< path: constant environment radiance
  std::string env_map;                    ///< path: equirectangular map file
  float env_intensity = 1, env_rotation = 0;  ///< path: the environment's multiplier and turn (degrees)
  double time_limit = 0;                      ///< path: seconds; 0: none
  float adaptive = 0;                         ///< path: adaptive sampling threshold; 0: off
  int adaptive_min_spp = 16;                  ///< path: samples before --adaptive may stop a pixel
  float fstop = 0;                            ///< depth of field by f-number; 0: none
  float aperture_radius = 0;                  ///< depth of field by aperture radius, scene units; 0: none
  float focus_distance = 0;                   ///< depth of the plane in focus; 0: autofocus at focus_at
  std::string focus_at;                       ///< "X,Y": autofocus through that pixel; empty: the centre
  int aperture_blades = 0;                    ///< 0: a round aperture; 3..64: a polygon
  float aperture_rotation = 0;                ///< the polygon's turn, degrees
  float aperture_ratio = 1;                   ///< anamorphic: aperture height / width
  double fps =
      24;  ///< frames per second: the shutter's frame interval; the vector layer's frames lie 1/fps away
  bool motion_blur = false;               ///< the scene's motion over the shutter
  float shutter = 0.5f;                   ///< the shutter's length, a fraction of the frame interval
  float shutter_offset = 0;               ///< the shutter's centre after the frame's time, in frames
  int motion_steps = 3;                   ///< the transforms' keys over the shutter
  std::string accel = "embree";           ///< an accelerator_names() entry
  std::vector<std::string> accel_params;  ///< "bvh.max_leaf_size=4", ... of `accel` only
  std::set<std::string> aovs;             ///< checked layer names (check_aovs)
  int crypto_depth = 6;                   ///< Cryptomatte ranks per pixel
  std::string shadows = "on";          ///< whitted: on, or off (no shadow rays: lights reach every surface)
  bool deep = false;                   ///< whitted, path: a deep image too (render_deep_image)
  float deep_merge_tolerance = 0.01f;  ///< deep: relative depth within which one surface's records merge
  std::string point_size = "2px";  ///< points without a size from the file: diameter, "Npx" or scene units
  std::string line_width = "1px";  ///< lines without a width from the file: "Npx" or scene units
  bool wireframe = false;          ///< triangle edges drawn over the image and in a wireframe layer
  std::string wireframe_nodes;     ///< comma-separated node names or indices; empty: every node
  float wireframe_width = 1;       ///< pixels
  std::string wireframe_color = "0,0,0";  ///< linear RGB "r,g,b"
  std::string wireframe_hidden = "off";   ///< edges behind surfaces: off, dim or dashed
};

/// The integrators a setting applies to (a bit mask).
enum IntegratorMask : unsigned { kWhitted = 1, kPath = 2, kRaster = 4, kAnyIntegrator = 7 };

/// One scalar setting of RenderSpec.
struct SpecField {
  using Member = std::variant<bool RenderSpec::*, int RenderSpec::*, uint64_t RenderSpec::*,
                              float RenderSpec::*, double RenderSpec::*, std::string RenderSpec::*>;
  const char* name;  ///< snake_case: the Python keyword and identity key; the flag is --name-with-dashes
  Member member;
  unsigned applies;  ///< IntegratorMask: elsewhere a value other than the default is an error
  bool identity;     ///< decides pixels: written into the identity (not the sample target, the
                     ///< stopping rule, threads or tiles)
  double lo, hi;     ///< numbers: the accepted range (both 0: any finite value)
  std::vector<std::string> choices;  ///< strings: the accepted values (empty: any)
  std::string help;                  ///< one line, with the default
};

/// Every scalar setting, in the order help texts list them.
const std::vector<SpecField>& spec_fields();

/// The field's name as a command-line flag: "--max-depth".
std::string flag_name(const SpecField& field);

/// The field's value as text ("12", "0.5", "path").
std::string field_text(const RenderSpec& spec, const SpecField& field);

/// The integrator's bit in IntegratorMask.
unsigned integrator_bit(const std::string& integrator);

/// The AOV names a render accepts (besides "all"), in help order.
const std::vector<std::string>& aov_names();

/// The layer names `names` asks for ("all": every layer of `known` the integrator has, except
/// cost and vector, which trace or load more), checked against `known` and the integrator. Throws
/// std::invalid_argument naming the layer ("unknown AOV 'x' (known: ...)", "'samples' needs integrator
/// 'path'").
std::set<std::string> check_aovs(const std::vector<std::string>& names, const std::string& integrator,
                                 const std::vector<std::string>& known = aov_names());

/// Checks every part of the spec before any work: each field of spec_fields() (range, choices,
/// integrator), the colours and the environment, the accelerator's name and parameters (every
/// structure's config validated), the layers, and the renderer's own ranges (RenderConfig
/// validate on a stand-in size). Throws std::invalid_argument naming the setting as the Python
/// API spells it.
void validate(const RenderSpec& spec);

/// The colour wireframe_color names ("r,g,b", finite, >= 0). Throws std::invalid_argument naming
/// wireframe_color otherwise.
Vec3f parse_wireframe_color(const std::string& text);

/// The spec with every default resolved for an image whose aspect follows `hint` where the width
/// or height is open: size, spp, filter and width, depth.
RenderSpec resolve(const RenderSpec& spec, float hint);

/// Whether the spec asks for depth of field (an f-number or an aperture radius).
bool wants_depth_of_field(const RenderSpec& spec);

/// The pixel focus_at names, "X,Y" (column and row from the top left, any real numbers; the
/// pixel's centre is traced). Throws std::invalid_argument naming focus_at otherwise.
Vec2f parse_focus_at(const std::string& text);

/// The renderer's configuration of a resolved spec (resolve()).
RenderConfig make_render_config(const RenderSpec& resolved);

/// What identifies the scene a render was made of, besides the spec.
struct SceneIdentity {
  std::string sha256;           ///< over every file the scene loaded
  int index = -1;               ///< the glTF scene; -1: the file's default
  bool flatten = false;         ///< instances flattened
  std::string variant;          ///< KHR_materials_variants name, empty for none
  std::string time = "static";  ///< the pose: "static", seconds, or "frame N at F fps"
  std::string camera;           ///< the camera as the spec names it; empty: the default (named by the camera)
  std::string env_sha256;       ///< the environment map's content hash (prepare_render reads it; empty for a
                                ///< colour or none)
  std::string shutter;  ///< motion blur: the shutter interval in seconds ("open..close"); empty without
  std::string vector_cameras;  ///< the vector layer's previous and next cameras when the front end
                               ///< moves them (a turntable; prepare_render fills it); else empty
};

/// Everything that decides a render's pixels except its window and sample target: the renderer
/// version, the scene, the camera as rendered, every pixel-deciding spec_fields() entry that
/// applies to the integrator (by name), the colours, the environment and the accelerator's
/// parameters; with the vector layer, fps; the camera's motion over the shutter when it has one.
/// `resolved` is resolve()'s result.
RenderSettings render_identity(const RenderSpec& resolved, const Camera& camera, const SceneIdentity& scene);

}  // namespace penumbra
