// The `penumbra` Python module: its initialiser, the version, the exception types and their
// translators. The io layer's InputError becomes penumbra.InputError (a ValueError) with the
// same text the command prints after "penumbra: error: "; std::invalid_argument becomes
// ValueError, other runtime errors (failed writes) RuntimeError, std::bad_alloc MemoryError.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <exception>

#include "io/files/error.h"
#include "python/bindings.h"
#include "renderer/accel/factory.h"

namespace py = pybind11;
using penumbra::InputError;

namespace {

/// penumbra.InputError, created once and kept for the translator (never freed: the
/// interpreter may still raise it while shutting down).
py::object* g_input_error = nullptr;

void register_errors(py::module_& m) {
  g_input_error = new py::object(py::reinterpret_steal<py::object>(
      PyErr_NewExceptionWithDoc("penumbra.InputError",
                                "Bad input: a malformed or missing file, an invalid value in it, an unknown "
                                "camera. str(e) is the message `penumbra` prints after 'penumbra: error: '; "
                                "e.file is the file and e.element the element (a JSON path such as "
                                "'meshes[2].primitives[0]', or '') it concerns.",
                                PyExc_ValueError, nullptr)));
  if (!g_input_error->ptr()) throw py::error_already_set();
  m.attr("InputError") = *g_input_error;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      py::object error = (*g_input_error)(e.what());
      error.attr("file") = e.file();
      error.attr("element") = e.element();
      PyErr_SetObject(g_input_error->ptr(), error.ptr());
    }
  });
}

}  // namespace

PYBIND11_MODULE(penumbra, m) {
  m.doc() =
      "Penumbra: load glTF 2.0 scenes, inspect them, and render them (Whitted or path tracing) into NumPy "
      "arrays, OpenEXR files and display images.\n\n"
      "    scene = penumbra.load('scene.gltf')\n"
      "    result = scene.render(width=320, height=180, integrator='path', spp=16, aovs=['Z', 'id'])\n"
      "    result.beauty        # float32 (180, 320, 4), premultiplied RGBA\n"
      "    result.aovs['Z']     # float32 (180, 320), camera-space depth\n"
      "    result.write_exr('out.exr'); result.write_display('out.png')\n\n"
      "Renders release the GIL; errors in input files raise penumbra.InputError.";
  m.attr("__version__") = PENUMBRA_VERSION;
  m.def("accelerator_names", &penumbra::accelerator_names,
        "The names RenderSettings.accel accepts, the default (embree) first.");
  register_errors(m);
  auto scene = penumbra::python::bind_scene(m);
  penumbra::python::bind_render(m, scene);
  penumbra::python::bind_queries(m, scene);
  penumbra::python::bind_collision(scene);
}
