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
#include <map>
#include <string>
#include <type_traits>
#include <variant>

#include "python/bindings.h"
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

/// A copy of `settings` (None: the defaults) with the keywords applied. TypeError unless
/// `settings` is None or a RenderSettings.
RenderSettings settings_from(const py::object& settings, const py::kwargs& kw) {
  if (!settings.is_none() && !py::isinstance<RenderSettings>(settings))
    throw py::type_error("settings must be a penumbra.RenderSettings or None, not " + type_name(settings));
  py::object s = settings.is_none() ? py::cast(RenderSettings{}) : py::cast(settings.cast<RenderSettings>());
  apply_keywords(s, kw);
  return s.cast<RenderSettings>();
}

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
          "float32 (height, width, 4): scene-linear RGBA, colour premultiplied by alpha (coverage)")
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
          "variance, and the light groups (emission, diffuse_direct, ...: h x w x 3)")
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

void bind_render(py::module_& m, SceneClass& scene) {
  bind_settings(m);
  bind_result(m);
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
