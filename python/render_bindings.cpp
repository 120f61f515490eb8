// penumbra.RenderSettings, Scene.render, Scene.render_to_file and penumbra.RenderResult: the
// settings as keyword arguments with the command's defaults, a render with the GIL released,
// its beauty and AOVs as read-only NumPy views into the result, and its EXR and display image.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <map>
#include <string>
#include <type_traits>
#include <variant>

#include "io/files/atomic_file.h"
#include "io/image/exr_denoise.h"
#include "python/bindings.h"
#include "renderer/film/denoise.h"
#include "renderer/integrators/light_groups.h"

namespace penumbra::python {

namespace {

using ResultPtr = std::shared_ptr<RenderOutput>;

/// The attribute names of RenderSettings, in the order its repr lists them: every field of the
/// spec's table (render/spec.h), then the settings that are not plain numbers or text.
const std::vector<std::string>& setting_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const SpecField& f : spec_fields()) n.push_back(f.name);
    for (const char* other :
         {"camera", "window", "accel_params", "background", "ambient", "env_color", "env_map"})
      n.push_back(other);
    return n;
  }();
  return names;
}

/// Sets each keyword on `settings` (a RenderSettings object); TypeError for an unknown one.
void apply_keywords(py::object& settings, const py::kwargs& kw) {
  const auto& names = setting_names();
  for (const auto& [key, value] : kw) {
    const std::string name = py::str(key);
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
      throw py::type_error("unknown render setting '" + name + "' (known: " + known + ")");
    }
    settings.attr(name.c_str()) = value;
  }
}

/// The name of `v`'s type, for TypeError messages.
std::string type_name(const py::handle& v) {
  return py::str(py::type::handle_of(v).attr("__name__"));
}

/// True for Python ints and other integer types (those with __index__, such as NumPy's).
bool is_integer(const py::handle& v) {
  return PyIndex_Check(v.ptr());
}

/// The integer `v` (is_integer) if it lies in [lo, INT_MAX], else ValueError naming `what`.
int int_in_range(const py::handle& v, int lo, const std::string& what) {
  const auto i = py::reinterpret_steal<py::int_>(PyNumber_Index(v.ptr()));
  if (!i) throw py::error_already_set();
  if (i < py::int_(lo) || i > py::int_(INT_MAX))
    throw py::value_error(what + " " + std::string(py::repr(i)) + " is out of range [" + std::to_string(lo) +
                          ", " + std::to_string(INT_MAX) + "]");
  return i.cast<int>();
}

}  // namespace

RenderSettings settings_from(const py::object& settings, const py::kwargs& kw) {
  if (!settings.is_none() && !py::isinstance<RenderSettings>(settings))
    throw py::type_error("settings must be a penumbra.RenderSettings or None, not " + type_name(settings));
  py::object s = settings.is_none() ? py::cast(RenderSettings{}) : py::cast(settings.cast<RenderSettings>());
  apply_keywords(s, kw);
  return s.cast<RenderSettings>();
}

namespace {

/// None, one grey value or three values as an optional colour.
std::optional<Vec3f> colour_from(const py::object& v, const char* name) {
  if (v.is_none()) return std::nullopt;
  if (py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v)) {
    const float g = v.cast<float>();
    return Vec3f{g, g, g};
  }
  const auto c = v.cast<std::vector<float>>();
  if (c.size() != 3) throw py::value_error(std::string(name) + " must be None, one value or (r, g, b)");
  return Vec3f{c[0], c[1], c[2]};
}

py::object colour_to(const std::optional<Vec3f>& c) {
  if (!c) return py::none();
  return py::make_tuple(c->x, c->y, c->z);
}

/// A read-only float32 view of `count` rows x `columns` x `channels` floats starting at `data`,
/// each element `stride` floats apart (channels of one pixel adjacent), owned by `owner`.
py::array view(const py::object& owner, const float* data, int rows, int columns, int channels, int stride) {
  std::vector<py::ssize_t> shape = {rows, columns};
  std::vector<py::ssize_t> strides = {py::ssize_t(sizeof(float)) * columns * stride,
                                      py::ssize_t(sizeof(float)) * stride};
  if (channels > 1) {
    shape.push_back(channels);
    strides.push_back(sizeof(float));
  }
  py::array a(py::dtype::of<float>(), shape, strides, data, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

/// uint32 (rows, columns) copy of integer-valued floats.
py::array_t<uint32_t> ids(const std::vector<float>& v, int rows, int columns) {
  py::array_t<uint32_t> a({rows, columns});
  uint32_t* out = a.mutable_data();
  for (size_t i = 0; i < v.size(); ++i) out[i] = uint32_t(v[i]);
  return a;
}

py::dict aov_dict(const py::object& self) {
  const RenderOutput& r = self.cast<const RenderOutput&>();
  const int h = r.film.height, w = r.film.width;
  const DataAovs& d = r.data;
  py::dict out;
  if (r.aovs.count("albedo")) out["albedo"] = view(self, d.albedo.data(), h, w, 3, 3);
  if (r.aovs.count("N")) out["N"] = view(self, d.normal.data(), h, w, 3, 3);
  if (r.aovs.count("P")) out["P"] = view(self, d.position.data(), h, w, 3, 3);
  if (r.aovs.count("Z")) out["Z"] = view(self, d.depth.data(), h, w, 1, 1);
  if (r.aovs.count("UV")) out["UV"] = view(self, d.uv.data(), h, w, 2, 2);
  if (r.aovs.count("id")) {
    out["object_id"] = ids(d.object_id, h, w);
    out["material_id"] = ids(d.material_id, h, w);
  }
  if (r.aovs.count("samples")) {
    py::array_t<uint32_t> a({h, w});
    std::copy(r.samples.begin(), r.samples.end(), a.mutable_data());
    out["samples"] = a;
  }
  if (r.aovs.count("variance")) out["variance"] = view(self, r.variance.data(), h, w, 1, 1);
  if (r.aovs.count("light"))
    for (int g = 0; g < kLightGroupCount; ++g)
      out[kLightGroupNames[g]] = view(self, r.groups.data() + 3 * g, h, w, 3, kLightGroupChannels);
  if (r.aovs.count("vector"))
    out["vector"] = view(self, r.vector.data(), h, w, kMotionVectorChannels, kMotionVectorChannels);
  if (r.aovs.count("velocity"))
    out["velocity"] = view(self, r.velocity.data(), h, w, kVelocityChannels, kVelocityChannels);
  if (!r.wireframe.empty()) out["wireframe"] = view(self, r.wireframe.data(), h, w, 1, 1);
  if (r.aovs.count("halves") && !r.halves.empty() && !d.halves.empty())
    for (int half = 0; half < 2; ++half) {
      const std::string name = half ? "odd" : "even";
      const float* f = d.halves.data() + half * kDenoiseFeatures;
      out[py::str(name)] = view(self, r.halves.data() + 3 * half, h, w, 3, kHalfChannels);
      out[py::str(name + "_albedo")] = view(self, f, h, w, 3, 2 * kDenoiseFeatures);
      out[py::str(name + "_N")] = view(self, f + 3, h, w, 3, 2 * kDenoiseFeatures);
      out[py::str(name + "_Z")] = view(self, f + 6, h, w, 1, 2 * kDenoiseFeatures);
    }
  return out;
}

py::dict stats_dict(const RenderOutput& r) {
  py::dict d;
  d["seconds"] = r.stats.seconds;
  d["threads"] = r.stats.threads;
  d["passes"] = r.stats.passes;
  d["samples"] = r.stats.samples;
  d["time_limited"] = r.stats.time_limited;
  d["camera_rays"] = r.stats.rays.camera;
  d["shadow_rays"] = r.stats.rays.shadow;
  d["reflection_rays"] = r.stats.rays.reflection;
  return d;
}

DisplayOptions display_options(const std::string& ocio_config, const std::string& display,
                               const std::string& view_name, const std::string& look, float exposure,
                               bool half_beauty, bool alpha) {
  if (!std::isfinite(exposure) || std::fabs(exposure) > 64)
    throw py::value_error("exposure must be finite and within [-64, 64]");
  DisplayOptions d;
  d.ocio_config = ocio_config;
  d.display = display;
  d.view = view_name;
  d.look = look;
  d.exposure = exposure;
  d.half_beauty = half_beauty;
  d.alpha = alpha;
  return d;
}

void check_exr_path(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".exr") throw py::value_error(path.string() + ": the output must be an .exr file");
}

/// Issues the settings a render ignored as RuntimeWarnings naming the scene's file.
void warn_ignored(const RenderOutput& r) {
  for (const auto& w : r.warnings)
    if (PyErr_WarnEx(PyExc_RuntimeWarning, (r.scene_file + ": " + w).c_str(), 1) != 0)
      throw py::error_already_set();
}

ResultPtr render(SceneSession& session, const RenderSettings& settings,
                 const std::vector<std::string>& aovs) {
  ResultPtr r;
  {
    py::gil_scoped_release release;
    r = std::make_shared<RenderOutput>(render_session(session, settings, aovs));
  }
  warn_ignored(*r);
  return r;
}

void bind_settings(py::module_& m) {
  py::class_<RenderSettings> s(
      m, "RenderSettings",
      "Render settings with `penumbra render`'s defaults; pass any of them as keywords "
      "(RenderSettings(width=320, integrator='path')) or to Scene.render directly.");
  s.def(py::init([](const py::kwargs& kw) {
     py::object o = py::cast(RenderSettings{});
     apply_keywords(o, kw);
     return o.cast<RenderSettings>();
   }))
      .def_readwrite("accel_params", &RenderSettings::accel_params, "['bvh.max_leaf_size=4', ...]")
      .def_property(
          "camera",
          [](const RenderSettings& r) -> py::object {
            if (r.camera.empty()) return py::none();
            if (r.camera.find_first_not_of("0123456789") == std::string::npos)
              return py::int_(std::stoll(r.camera));
            return py::str(r.camera);
          },
          [](RenderSettings& r, const py::object& v) {
            if (v.is_none()) {
              r.camera.clear();
            } else if (is_integer(v)) {
              r.camera = std::to_string(int_in_range(v, 0, "camera index"));
            } else if (py::isinstance<py::str>(v)) {
              const std::string name = v.cast<std::string>();
              if (name.empty()) throw py::value_error("camera name must not be empty (None: the default)");
              r.camera = name;
            } else {
              throw py::type_error("camera must be None, an index (int) or a name (str), not " +
                                   type_name(v));
            }
          },
          "index into Scene.cameras or a camera name; None: the first camera, else a view framing the bounds")
      .def_property(
          "window",
          [](const RenderSettings& r) -> py::object {
            if (r.window.empty()) return py::none();
            return py::make_tuple(r.window.x0, r.window.y0, r.window.x1, r.window.y1);
          },
          [](RenderSettings& r, const py::object& v) {
            if (v.is_none()) {
              r.window = {};
              return;
            }
            const char* expected = "window must be None or (x0, y0, x1, y1)";
            if (!py::isinstance<py::sequence>(v) || py::isinstance<py::str>(v))
              throw py::type_error(std::string(expected) + ", not " + type_name(v));
            const auto items = v.cast<py::sequence>();
            if (items.size() != 4) throw py::value_error(std::string(expected) + " (4 values)");
            std::vector<int> w;
            for (const py::object item : items) {
              if (!is_integer(item))
                throw py::type_error(std::string(expected) + " of ints, not " + type_name(item));
              w.push_back(int_in_range(item, 0, "window value"));
            }
            if (w[2] <= w[0] || w[3] <= w[1])
              throw py::value_error(
                  "window must be None or (x0, y0, x1, y1) with 0 <= x0 < x1, 0 <= y0 < y1");
            r.window = {w[0], w[1], w[2], w[3]};
          },
          "(x0, y0, x1, y1) of the frame to render (x1, y1 exclusive); None: the whole frame")
      .def_property(
          "background", [](const RenderSettings& r) { return colour_to(r.background); },
          [](RenderSettings& r, const py::object& v) { r.background = colour_from(v, "background"); },
          "whitted: radiance of escaping rays (None: black)")
      .def_property(
          "ambient", [](const RenderSettings& r) { return colour_to(r.ambient); },
          [](RenderSettings& r, const py::object& v) { r.ambient = colour_from(v, "ambient"); },
          "whitted: ambient intensity (None: 0.05)")
      .def_property(
          "env_color", [](const RenderSettings& r) { return colour_to(r.env_color); },
          [](RenderSettings& r, const py::object& v) { r.env_color = colour_from(v, "env_color"); },
          "path: constant environment radiance (None: env_map, else the file's image light, else black)")
      .def_readwrite("env_map", &RenderSettings::env_map, "path: equirectangular map file")
      .def(
          "copy",
          [](const RenderSettings& r, const py::kwargs& kw) {
            py::object o = py::cast(RenderSettings(r));  // a copy, not a reference to r
            apply_keywords(o, kw);
            return o.cast<RenderSettings>();
          },
          "A copy with the keywords changed.")
      .def("__repr__", [](const py::object& self) {
        std::string r = "penumbra.RenderSettings(";
        bool first = true;
        for (const auto& n : setting_names()) {
          r += (first ? "" : ", ") + n + "=" + std::string(py::repr(self.attr(n.c_str())));
          first = false;
        }
        return r + ")";
      });
  // Every field of the spec's table, named as the table names it.
  for (const SpecField& f : spec_fields())
    std::visit(
        [&](auto member) {
          using T = std::remove_cvref_t<decltype(RenderSettings{}.*member)>;
          s.def_property(
              f.name, [member](const RenderSettings& r) { return r.*member; },
              [member](RenderSettings& r, T v) { r.*member = v; }, f.help.c_str());
        },
        f.member);
}

void bind_result(py::module_& m) {
  py::class_<RenderOutput, ResultPtr>(m, "RenderResult",
                                      "A finished render: its arrays are read-only views into it "
                                      "(numpy.array(x) copies).")
      .def_property_readonly(
          "beauty",
          [](const py::object& self) {
            const RenderOutput& r = self.cast<const RenderOutput&>();
            return view(self, r.film.rgba.data(), r.film.height, r.film.width, 4, 4);
          },
          "float32 (height, width, 4): scene-linear RGBA, colour premultiplied by alpha (coverage); with "
          "denoise=True the denoised beauty (the noisy one with denoise_main='noisy')")
      .def_property_readonly(
          "rgb",
          [](const py::object& self) {
            const RenderOutput& r = self.cast<const RenderOutput&>();
            return view(self, r.film.rgba.data(), r.film.height, r.film.width, 3, 4);
          },
          "float32 (height, width, 3): the beauty's colour (over black)")
      .def_property_readonly(
          "aovs", &aov_dict,
          "the requested AOVs by name: albedo, N, P (float32 h x w x 3), Z (float32 h x w, "
          "inf where nothing is hit), UV (h x w x 2), object_id (glTF node + 1) and "
          "material_id (material + 1) (uint32 h x w, 0 = background), samples (uint32), "
          "variance, the light groups (emission, diffuse_direct, ...: h x w x 3) and with halves the "
          "denoiser's input: even, odd (colour of the even and odd samples), even_albedo, odd_albedo, "
          "even_N, "
          "odd_N (h x w x 3), even_Z, odd_Z (h x w)")
      .def_property_readonly(
          "noisy",
          [](const py::object& self) -> py::object {
            const RenderOutput& r = self.cast<const RenderOutput&>();
            if (!r.settings.denoise) return py::none();
            const Film& f = r.settings.denoise_main == "noisy" ? r.film : r.second;
            return view(self, f.rgba.data(), f.height, f.width, 4, 4);
          },
          "with denoise=True: the render's beauty before denoising (float32 h x w x 4); else None")
      .def_property_readonly(
          "denoised",
          [](const py::object& self) -> py::object {
            const RenderOutput& r = self.cast<const RenderOutput&>();
            if (!r.settings.denoise) return py::none();
            const Film& f = r.settings.denoise_main == "noisy" ? r.second : r.film;
            return view(self, f.rgba.data(), f.height, f.width, 4, 4);
          },
          "with denoise=True: the denoised beauty (float32 h x w x 4, alpha the render's); else None")
      .def_property_readonly("width", [](const RenderOutput& r) { return r.film.width; })
      .def_property_readonly("height", [](const RenderOutput& r) { return r.film.height; })
      .def_property_readonly(
          "frame_size", [](const RenderOutput& r) { return py::make_tuple(r.config.width, r.config.height); },
          "(width, height) of the whole frame a window lies in")
      .def_property_readonly(
          "origin", [](const RenderOutput& r) { return py::make_tuple(r.film.origin_x, r.film.origin_y); },
          "the film's top-left pixel in the frame")
      .def_property_readonly("spp", [](const RenderOutput& r) { return r.config.spp; })
      .def_property_readonly("camera", [](const RenderOutput& r) { return r.camera; })
      .def_property_readonly(
          "camera_index", [](const RenderOutput& r) { return r.camera_index; },
          "into Scene.cameras; -1: framed from the bounds")
      .def_property_readonly(
          "default_light", [](const RenderOutput& r) { return r.default_light; },
          "the scene had no light: the default key light lit it")
      .def_property_readonly("settings", [](const RenderOutput& r) { return r.settings; })
      .def_property_readonly("stats", [](const RenderOutput& r) { return stats_dict(r); })
      .def_property_readonly(
          "id_manifest",
          [](const RenderOutput& r) -> py::object {
            if (r.id_manifest.empty()) return py::none();
            return py::module_::import("json").attr("loads")(r.id_manifest);
          },
          "{'object': {id: node name}, 'material': {id: material name}} with the id AOV")
      .def(
          "write_exr",
          [](const ResultPtr& r, const std::filesystem::path& path, bool half, const std::string& compression,
             bool multipart, const std::map<std::string, std::string>& metadata) {
            check_exr_path(path);
            ExrWriteOptions o;
            o.half = half;
            o.compression = compression;
            o.multipart = multipart;
            o.metadata.assign(metadata.begin(), metadata.end());
            py::gil_scoped_release release;
            write_render_exr(*r, path, o);
          },
          py::arg("path"), py::kw_only(), py::arg("half") = true, py::arg("compression") = "zip",
          py::arg("multipart") = false, py::arg("metadata") = std::map<std::string, std::string>{},
          "Writes the EXR `penumbra render` writes (atomically): R, G, B, A (half unless half=False) and "
          "every "
          "AOV of the render with the command's channel names.")
      .def(
          "write_deep_exr",
          [](const ResultPtr& r, const std::filesystem::path& path, const std::string& compression) {
            check_exr_path(path);
            if (!r->settings.deep) throw py::value_error("write_deep_exr needs a render with deep=True");
            ExrWriteOptions o;
            o.compression = compression;
            py::gil_scoped_release release;
            write_render_deep_exr(*r, path, o);
          },
          py::arg("path"), py::kw_only(), py::arg("compression") = "zip",
          "Writes the deep EXR `penumbra render --deep` writes (atomically; needs deep=True): per pixel one "
          "sample per surface with R, G, B, A, Z, ZBack, id, N.X/Y/Z and albedo.R/G/B in float.")
      .def_property_readonly(
          "deep_samples",
          [](const RenderOutput& r) -> py::object {
            if (!r.settings.deep) return py::none();
            py::array_t<uint32_t> counts({py::ssize_t(r.deep.height), py::ssize_t(r.deep.width)});
            std::copy(r.deep.counts.begin(), r.deep.counts.end(), counts.mutable_data());
            return counts;
          },
          "with deep=True: the deep samples per pixel (uint32 h x w); else None")
      .def(
          "write_display",
          [](const ResultPtr& r, const std::filesystem::path& path, const std::string& ocio_config,
             const std::string& display, const std::string& view_name, const std::string& look,
             float exposure, bool half_beauty, bool alpha) {
            const DisplayOptions d =
                display_options(ocio_config, display, view_name, look, exposure, half_beauty, alpha);
            py::gil_scoped_release release;
            write_display_image(r->film, path, d);
          },
          py::arg("path"), py::kw_only(), py::arg("ocio_config") = "", py::arg("display") = "",
          py::arg("view") = "", py::arg("look") = "", py::arg("exposure") = 0.0f,
          py::arg("half_beauty") = false, py::arg("alpha") = false,
          "Writes the beauty through the OpenColorIO display/view transform as .png, .jpg or .tif "
          "(atomically). "
          "half_beauty rounds it to half floats first, so the image equals one made from a half EXR; alpha "
          "keeps the beauty's alpha (RGBA, straight colour; .png and .tif).")
      .def("__repr__", [](const RenderOutput& r) {
        return "<penumbra.RenderResult " + std::to_string(r.film.width) + "x" +
               std::to_string(r.film.height) + ", " + r.settings.integrator + ", " +
               std::to_string(r.config.spp) + " spp>";
      });
}

}  // namespace

namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

// A (2, h, w, channels) array (channels 1: (2, h, w)) of halves, checked; throws ValueError.
void check_halves(const FloatArray& a, const char* name, int channels, py::ssize_t h, py::ssize_t w) {
  const bool ok = channels == 1 ? a.ndim() == 3 : a.ndim() == 4 && a.shape(3) == channels;
  if (!ok || a.shape(0) != 2 || a.shape(1) != h || a.shape(2) != w)
    throw py::value_error(std::string(name) + ": expected shape (2, " + std::to_string(h) + ", " +
                          std::to_string(w) + (channels == 1 ? "" : ", " + std::to_string(channels)) +
                          "): the even and odd samples' halves");
  const float* v = a.data();
  const bool depth = channels == 1;
  for (py::ssize_t i = 0; i < a.size(); ++i)
    if (!(std::isfinite(v[i]) || (depth && v[i] > 0)))
      throw py::value_error(std::string(name) + ": non-finite value at flat index " + std::to_string(i) +
                            (depth ? " (a depth may be +inf, nothing else)" : ""));
}

void bind_denoise(py::module_& m) {
  m.def(
      "denoise",
      [](const std::filesystem::path& input, const std::filesystem::path& output,
         const std::string& denoise_main, int threads) {
        check_exr_path(output);
        if (denoise_main != "denoised" && denoise_main != "noisy")
          throw py::value_error("denoise_main must be 'denoised' or 'noisy'");
        if (threads < 0) throw py::value_error("threads must be >= 0");
        check_distinct_files({{"output", output}}, {{"input", input}});
        ExrDenoiseOptions o;
        o.noisy_main = denoise_main == "noisy";
        o.config.threads = threads;
        o.max_memory_bytes = default_memory_budget();
        py::gil_scoped_release release;
        (void)denoise_exr(input, output, o);
      },
      py::arg("input"), py::arg("output"), py::kw_only(), py::arg("denoise_main") = "denoised",
      py::arg("threads") = 0,
      "Denoises a Penumbra EXR with the halves layers (render with denoise=True or aovs=['halves']) into "
      "`output`, as `penumbra denoise` does: R, G, B denoised and the noisy beauty kept as noisy.RGBA "
      "(denoise_main='noisy': the reverse, denoised.RGBA). Raises penumbra.InputError naming the file and "
      "the missing layer.");
  m.def(
      "denoise",
      [](const py::object& color_in, const py::object& albedo_in, const py::object& normal_in,
         const py::object& depth_in, int threads, const std::string& method) {
        if (method != "nfor" && method != "cross_bilateral")
          throw py::value_error("method must be 'nfor' or 'cross_bilateral'");
        // Any array-like of numbers, copied to contiguous float32 (views and other dtypes too).
        const auto as_array = [](const py::object& o, const char* name) {
          FloatArray a = FloatArray::ensure(o);
          if (!a) throw py::value_error(std::string(name) + ": not an array of numbers");
          return a;
        };
        const FloatArray color = as_array(color_in, "color"), albedo = as_array(albedo_in, "albedo");
        const FloatArray normal = as_array(normal_in, "normal"), depth = as_array(depth_in, "depth");
        if (color.ndim() != 4) throw py::value_error("color: expected shape (2, height, width, 3)");
        const py::ssize_t h = color.shape(1), w = color.shape(2);
        check_halves(color, "color", 3, h, w);
        check_halves(albedo, "albedo", 3, h, w);
        check_halves(normal, "normal", 3, h, w);
        check_halves(depth, "depth", 1, h, w);
        if (threads < 0) throw py::value_error("threads must be >= 0");
        if (h < 1 || w < 1) throw py::value_error("color: the image is empty");
        DenoiseInput in;
        in.width = int(w);
        in.height = int(h);
        const size_t n = size_t(h) * size_t(w);
        for (size_t half = 0; half < 2; ++half) {
          in.color[half].assign(color.data() + half * n * 3, color.data() + (half + 1) * n * 3);
          in.features[half].resize(n * kDenoiseFeatures);
          for (size_t i = 0; i < n; ++i) {
            float* f = &in.features[half][i * kDenoiseFeatures];
            for (int c = 0; c < 3; ++c) {
              f[c] = albedo.data()[(half * n + i) * 3 + size_t(c)];
              f[3 + c] = normal.data()[(half * n + i) * 3 + size_t(c)];
            }
            f[6] = depth.data()[half * n + i];
          }
        }
        DenoiseConfig cfg;
        cfg.threads = threads;
        std::vector<float> out;
        {
          py::gil_scoped_release release;
          out = method == "nfor" ? denoise_nfor(in, cfg)
                                 : denoise_cross_bilateral(in, cfg.window_radius, threads);
        }
        FloatArray a({h, w, py::ssize_t(3)});
        std::copy(out.begin(), out.end(), a.mutable_data());
        return a;
      },
      py::kw_only(), py::arg("color"), py::arg("albedo"), py::arg("normal"), py::arg("depth"),
      py::arg("threads") = 0, py::arg("method") = "nfor",
      "Denoises arrays with NFOR: color, albedo and normal of shape (2, height, width, 3) and depth (2, "
      "height, width), each the means of the even and odd samples (RenderResult.aovs with halves: "
      "even/odd, even_albedo/odd_albedo, ...; colour premultiplied, depth +inf where nothing is hit). "
      "Returns the denoised colour, float32 (height, width, 3). method='cross_bilateral' runs the "
      "baseline NFOR is measured against (a 19 x 19 cross-bilateral filter on the same features). Raises "
      "ValueError for shapes that do not match or non-finite values.");
}

}  // namespace

void bind_render(py::module_& m, SceneClass& scene) {
  bind_settings(m);
  bind_result(m);
  bind_denoise(m);
  scene.def(
      "render",
      [](SceneSession& s, const py::object& settings, const std::vector<std::string>& aovs,
         const py::kwargs& kw) { return render(s, settings_from(settings, kw), aovs); },
      py::arg("settings") = py::none(), py::kw_only(), py::arg("aovs") = std::vector<std::string>{},
      "Renders into memory with `settings` (a RenderSettings, None: the defaults) and any setting as a "
      "keyword; aovs: names of data AOVs (albedo, N, P, Z, UV, id), the path tracer's layers (samples, "
      "variance, light), vector (motion vectors to the frames 1/fps before and after the scene's time), "
      "velocity (camera-space velocity in scene units per second) or 'all' (every one but vector and "
      "velocity). The GIL is released while it renders.");
  scene.def(
      "render_to_file",
      [](SceneSession& s, const std::filesystem::path& exr, const py::object& png, const py::object& settings,
         const std::vector<std::string>& aovs, bool half, const std::string& compression, bool multipart,
         const std::string& ocio_config, const std::string& display, const std::string& view_name,
         const std::string& look, float exposure, bool png_alpha, const py::kwargs& kw) {
        const RenderSettings rs = settings_from(settings, kw);
        check_exr_path(exr);
        std::optional<std::filesystem::path> png_path;
        if (!png.is_none()) png_path = png.cast<std::filesystem::path>();
        const DisplayOptions d =
            display_options(ocio_config, display, view_name, look, exposure, half, png_alpha);
        ResultPtr r;
        {
          py::gil_scoped_release release;
          if (png_path) check_display_output(*png_path, d);  // before the render, as the command does
          r = std::make_shared<RenderOutput>(render_session(s, rs, aovs));
          ExrWriteOptions o;
          o.half = half;
          o.compression = compression;
          o.multipart = multipart;
          write_render_exr(*r, exr, o);
          if (png_path) write_display_image(r->film, *png_path, d);
        }
        warn_ignored(*r);
        return r;
      },
      py::arg("exr"), py::kw_only(), py::arg("png") = py::none(), py::arg("settings") = py::none(),
      py::arg("aovs") = std::vector<std::string>{}, py::arg("half") = true, py::arg("compression") = "zip",
      py::arg("multipart") = false, py::arg("ocio_config") = "", py::arg("display") = "",
      py::arg("view") = "", py::arg("look") = "", py::arg("exposure") = 0.0f, py::arg("png_alpha") = false,
      "Renders as Scene.render, then writes the EXR (with the AOVs) and, if png is given, the display image "
      "of what the EXR holds (display, view, look, exposure, png_alpha as `penumbra render`); the display "
      "transform is checked before rendering. Any other keyword is a render setting. Returns the "
      "RenderResult.");
}

}  // namespace penumbra::python
