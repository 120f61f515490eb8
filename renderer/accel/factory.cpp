// The accelerator factory: the one place that maps a back-end name to a builder.
#include "renderer/accel/factory.h"

#include <stdexcept>

#include "renderer/accel/brute.h"
#include "renderer/accel/embree.h"

namespace penumbra {

std::vector<std::string> accelerator_names() { return {"embree", "bvh", "kdtree", "grid", "brute"}; }

std::unique_ptr<Accelerator> make_accelerator(std::string_view name,
                                              std::span<const TriangleMeshView> meshes,
                                              const AccelConfig& config) {
  if (name == "embree") return make_embree_accelerator(meshes, config.embree);
  if (name == "bvh") return make_bvh_accelerator(meshes, config.bvh);
  if (name == "kdtree") return make_kdtree_accelerator(meshes, config.kdtree);
  if (name == "grid") return make_grid_accelerator(meshes, config.grid);
  if (name == "brute") return make_brute_accelerator(meshes);
  std::string known;
  for (const auto& n : accelerator_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown accelerator '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace penumbra
