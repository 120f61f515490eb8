// The pieces of the `penumbra` Python module, one function per concern, called by the module's
// initialiser (penumbra_module.cpp): the Scene with its inspection records (scene_bindings.cpp),
// render settings, renders and their files (render_bindings.cpp), spatial queries and picking
// (query_bindings.cpp).
#pragma once

#include <pybind11/pybind11.h>

#include <mutex>

#include "python/render_session.h"

namespace penumbra::python {

namespace py = pybind11;

/// Holds a session's lock, waiting for it with the GIL released: a render in another thread
/// holds the lock without the GIL for as long as it runs.
class SessionLock {
 public:
  explicit SessionLock(SceneSession& session) : m_lock(session.mutex, std::defer_lock) {
    py::gil_scoped_release release;
    m_lock.lock();
  }

 private:
  std::unique_lock<std::mutex> m_lock;
};

using SceneClass = py::class_<SceneSession, std::shared_ptr<SceneSession>>;

/// penumbra.load, penumbra.Scene and the Mesh, Shape, Instance, Camera, Light and Material
/// records it lists. Returns the Scene class for bind_render.
SceneClass bind_scene(py::module_& m);

/// penumbra.RenderSettings, penumbra.RenderResult, Scene.render and Scene.render_to_file.
void bind_render(py::module_& m, SceneClass& scene);

/// A copy of `settings` (None: the defaults) with the keywords applied as render settings.
/// TypeError unless `settings` is None or a RenderSettings, or for an unknown keyword.
RenderSettings settings_from(const py::object& settings, const py::kwargs& kw);

/// penumbra.load_points, Scene.nearest, Scene.within, Scene.overlap, Scene.intersect and
/// Scene.pick.
void bind_queries(py::module_& m, SceneClass& scene);

/// Scene.proxies and Scene.collide.
void bind_collision(SceneClass& scene);

}  // namespace penumbra::python
