// Writes a test glTF (embedded buffers) into a fresh temporary folder and loads it back.
#pragma once

#include <string>

#include "io/gltf/loader.h"
#include "support/gltf_writer.h"
#include "support/test_util.h"

namespace penumbra::test {

inline LoadedScene write_and_load(GltfWriter& w, const std::string& name, GltfLoadOptions opt = {}) {
  const auto dir = temp_dir(name);
  w.write_embedded(dir / "scene.gltf");
  return load_gltf(dir / "scene.gltf", opt);
}

}  // namespace penumbra::test
