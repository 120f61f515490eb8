// penumbra_consumer SCENE.gltf OUT.exr OUT.png: loads a glTF scene through the installed
// Penumbra::io, prints its triangle counts as `penumbra info` does, renders it 32x18 with the
// Whitted integrator over Embree and writes the EXR and a display image (shipped OCIO config).
// Prints "lit pixels N" (pixels with non-zero colour). Exits 2 on any error, naming it.
#include <cstdio>
#include <exception>

#include "io/gltf/loader.h"
#include "io/image/image_output.h"
#include "renderer/integrators/render.h"
#include "renderer/scene/camera.h"
#include "renderer/scene/scene.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: penumbra_consumer SCENE.gltf OUT.exr OUT.png\n");
    return 2;
  }
  try {
    penumbra::LoadedScene loaded = penumbra::load_gltf(argv[1]);
    const penumbra::Scene& scene = loaded.scene;
    std::printf("triangles rendered %llu\n",
                static_cast<unsigned long long>(penumbra::count_triangles(scene)));
    std::printf("triangles stored %llu\n",
                static_cast<unsigned long long>(penumbra::count_stored_triangles(scene)));

    penumbra::RenderConfig config;
    config.width = 32;
    config.height = 18;
    config.spp = 1;
    config.threads = 1;
    penumbra::validate(config);
    const penumbra::Camera camera = scene.cameras.empty()
                                        ? penumbra::frame_bounds(penumbra::compute_bounds(scene),
                                                                 float(config.width) / float(config.height))
                                        : scene.cameras.front();
    const auto accel = penumbra::make_scene_accelerator("embree", scene);
    const penumbra::Film film = penumbra::render_whitted(scene, *accel, camera, config);

    penumbra::write_exr(film, argv[2], penumbra::ExrOptions{});
    penumbra::write_display_image(film, argv[3], penumbra::DisplayOptions{});
    int lit = 0;
    for (int y = 0; y < film.height; ++y)
      for (int x = 0; x < film.width; ++x) {
        const float* p = film.pixel(x, y);
        if (p[0] > 0 || p[1] > 0 || p[2] > 0) ++lit;
      }
    std::printf("lit pixels %d\n", lit);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "penumbra_consumer: %s\n", e.what());
    return 2;
  }
  return 0;
}
