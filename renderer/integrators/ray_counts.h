// Rays traced by the integrators, by kind: the numbers behind the render statistics and the
// Mrays/s figures.
#pragma once

#include <cstdint>

namespace penumbra {

struct RayCounts {
  uint64_t camera = 0, shadow = 0, reflection = 0;  ///< reflection: every bounce ray
  uint64_t total() const { return camera + shadow + reflection; }
  RayCounts& operator+=(const RayCounts& o) {
    camera += o.camera;
    shadow += o.shadow;
    reflection += o.reflection;
    return *this;
  }
};

}  // namespace penumbra
