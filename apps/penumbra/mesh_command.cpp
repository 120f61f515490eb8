// `penumbra mesh`.
#include "apps/penumbra/mesh_command.h"

#include <cctype>
#include <cstdio>
#include <filesystem>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/path_render.h"
#include "apps/penumbra/scene_setup.h"
#include "io/files/atomic_file.h"
#include "io/gltf/gltf_writer.h"
#include "renderer/scene/shape_mesh.h"

namespace penumbra::cli {

namespace fs = std::filesystem;

namespace {

bool places_implicit_shape(const Scene& scene, int node) {
  for (const Instance& inst : scene.instances)
    if (inst.shape >= 0 && (node < 0 || inst.node == node) &&
        scene.shapes[size_t(inst.shape)].shape.kind == ShapeKind::Implicit)
      return true;
  return false;
}

}  // namespace

int run_mesh(const MeshArgs& a) {
  const fs::path out(a.output);
  std::string ext = out.extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".glb" && ext != ".gltf")
    throw UsageError("-o " + a.output + ": the output must be a .glb or .gltf file");
  if (a.resolution < 1 || a.resolution > kMaxMarchingCubesResolution)
    throw UsageError("--resolution " + std::to_string(a.resolution) + ": outside [1, " +
                     std::to_string(kMaxMarchingCubesResolution) + "]");
  if (a.node && a.node->empty())
    throw UsageError(
        "--node: the value is empty (give a node index or name, or leave --node out for every "
        "implicit shape)");
  std::vector<std::pair<std::string, fs::path>> outputs{{"-o", out}};
  if (ext == ".gltf")
    outputs.push_back({"the buffer beside -o", out.parent_path() / (out.stem().string() + ".bin")});
  for (const auto& [name, path] : outputs) resolve_output(path, name);
  check_distinct_files(outputs, {{"the scene", a.scene_file}});
  const uint64_t budget = memory_budget(a.max_memory);
  install_signal_handlers();  // a signal removes the temporaries being written

  set_phase("loading the scene");
  const LoadedScene loaded = load_scene(a.scene_file, a.scene, a.allow_external, false, budget, a.quiet);
  std::vector<std::pair<std::string, fs::path>> inputs;
  for (const auto& f : loaded.info.source_files) inputs.push_back({"the scene's file", f});
  check_distinct_files(outputs, inputs);
  ShapeMeshConfig config;
  config.resolution = a.resolution;
  if (a.node) config.node = find_gltf_node(loaded.info, *a.node, a.scene_file);
  if (!places_implicit_shape(loaded.scene, config.node))
    throw UsageError(a.scene_file + ": " +
                     (config.node < 0 ? std::string("the scene places no implicit shape")
                                      : "node '" + loaded.info.node_names[size_t(config.node)] +
                                            "' places no implicit shape"));
  const uint64_t scene_bytes = scene_memory_bytes(loaded.scene);
  config.max_bytes = budget - std::min(budget, scene_bytes);

  set_phase("meshing the shapes");
  ShapeMeshes meshes;
  try {
    meshes = mesh_implicit_shapes(loaded.scene, config);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string(e.what()) + " (--max-memory)");
  }
  set_phase("writing the mesh");
  if (ext == ".glb")
    write_glb(meshes.scene, out);
  else
    write_gltf(meshes.scene, out);
  if (!a.quiet) {
    std::fprintf(stderr, "penumbra: %zu shapes meshed at resolution %d: %s vertices, %s triangles\n",
                 meshes.scene.meshes.size(), a.resolution,
                 human_count([&] {
                   uint64_t v = 0;
                   for (const Mesh& m : meshes.scene.meshes) v += m.positions.size();
                   return v;
                 }())
                     .c_str(),
                 human_count(count_stored_triangles(meshes.scene)).c_str());
    if (meshes.skipped_analytic > 0)
      std::fprintf(stderr, "penumbra: %d analytic shapes skipped (only implicit shapes are meshed)\n",
                   meshes.skipped_analytic);
  }
  std::printf("%s\n", a.output.c_str());
  return kExitOk;
}

}  // namespace penumbra::cli
