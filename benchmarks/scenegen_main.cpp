// penumbra-scenegen: writes the benchmark's generated stress scenes, or a PLY model, as glTF.
//   penumbra-scenegen atrium out/atrium.gltf [--seed 1] [--triangles 300000]
//   penumbra-scenegen --ply dragon.ply out/dragon.gltf
//   penumbra-scenegen --list
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>

#include "benchmarks/scenegen.h"
#include "io/files/error.h"
#include "io/gltf/gltf_writer.h"
#include "io/mesh/ply_loader.h"

using namespace penumbra;

int main(int argc, char** argv) {
  CLI::App app{"penumbra-scenegen: seeded benchmark scenes and PLY models as glTF"};
  std::string name, out, ply;
  uint64_t seed = 1, triangles = 0;
  bool list = false;
  app.add_option("scene", name, "generated scene name (see --list)");
  app.add_option("output", out, "output .gltf (a .bin is written beside it)");
  app.add_option("--ply", ply, "convert this PLY file instead of generating");
  app.add_option("--seed", seed, "generator seed (default 1)");
  app.add_option("--triangles", triangles, "approximate triangle count (default: the generator's)");
  app.add_flag("--list", list, "list the generators and exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (list) {
    for (const auto& g : bench::generators())
      std::printf("%-8s %9llu triangles  %s\n", g.name.c_str(),
                  static_cast<unsigned long long>(g.default_triangles), g.description.c_str());
    return 0;
  }
  if (!ply.empty()) {  // --ply IN OUT: the single positional is the output
    if (!out.empty() || name.empty()) {
      std::fprintf(stderr, "penumbra-scenegen: error: usage: penumbra-scenegen --ply IN.ply OUT.gltf\n");
      return 2;
    }
    out = name;
  }
  if (out.empty() || std::filesystem::path(out).extension() != ".gltf") {
    std::fprintf(stderr, "penumbra-scenegen: error: an output file ending in .gltf is required\n");
    return 2;
  }
  const auto dir =
      std::filesystem::path(out).has_parent_path() ? std::filesystem::path(out).parent_path() : ".";
  if (!std::filesystem::is_directory(dir)) {
    std::fprintf(stderr, "penumbra-scenegen: error: %s: directory '%s' does not exist\n", out.c_str(),
                 dir.string().c_str());
    return 2;
  }
  try {
    const Scene scene = ply.empty() ? bench::generate_scene(name, seed, triangles) : load_ply(ply);
    write_gltf(scene, out);
    std::printf("%s: %llu triangles\n", out.c_str(), static_cast<unsigned long long>(count_triangles(scene)));
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "penumbra-scenegen: error: %s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "penumbra-scenegen: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "penumbra-scenegen: error: %s\n", e.what());
    return 1;
  }
}
