// The `penumbra` command: `render` a glTF scene to EXR and a display image, describe it with
// `info`, assemble farm tiles with `merge`, composite deep EXRs with `deep`, denoise an EXR with
// `denoise`, render job files with `batch` and submit them to Slurm with `submit slurm`, turn its
// implicit shapes into triangle meshes with `mesh`, ask it spatial questions with `query`, fit
// collision proxies with `proxies` and find collisions with `collide`. This file wires the
// subcommands' flags (CLI11) and maps errors to exit codes: 0 success, 2 bad input or usage, 1 a
// failure outside the input (I/O, memory); a render ended by a signal returns 128 + signal. Every
// error, a parse error included (parse_errors.h), is reported as "penumbra: error: ..." on stderr.
// Only main() exits.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <new>

#include "apps/penumbra/batch_command.h"
#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/collide_command.h"
#include "apps/penumbra/deep_command.h"
#include "apps/penumbra/info_command.h"
#include "apps/penumbra/merge_command.h"
#include "apps/penumbra/mesh_command.h"
#include "apps/penumbra/parse_errors.h"
#include "apps/penumbra/progress.h"
#include "apps/penumbra/proxies_command.h"
#include "apps/penumbra/query_command.h"
#include "apps/penumbra/render_command.h"
#include "apps/penumbra/scene_setup.h"
#include "apps/penumbra/submit_command.h"
#include "io/files/error.h"

using namespace penumbra;
using namespace penumbra::cli;

namespace {

void add_merge_options(CLI::App& merge, MergeArgs& a) {
  merge.add_option("parts", a.parts, "part EXRs (together covering the frame once)")->required();
  merge.add_option("-o,--output", a.output, "full-frame EXR (written atomically)")->required();
  merge.add_option("--max-memory", a.max_memory,
                   "budget for the decoded full frame, e.g. 4G (default: half the RAM)");
  merge.add_flag(
      "--force", a.force,
      "merge parts without Penumbra's scene and settings metadata, or with differing metadata (parts "
      "cut by other tools); the windows and channels are still checked");
}

void add_denoise_options(CLI::App& denoise, DenoiseArgs& a) {
  denoise
      .add_option("input", a.input,
                  "a Penumbra EXR with the halves layers (render --denoise or --aov halves)")
      ->required();
  denoise.add_option("-o,--output", a.output, "the denoised EXR (written atomically)")->required();
  denoise
      .add_option("--denoise-main", a.denoise_main,
                  "the main layer (R, G, B, A): denoised (default; the noisy beauty kept as noisy.RGBA) or "
                  "noisy (the denoised beauty written as denoised.RGBA)")
      ->check(CLI::IsMember({"denoised", "noisy"}));
  denoise.add_option("--threads", a.threads, "worker threads (default: all; does not change pixels)")
      ->check(CLI::Range(0, 1024));
  denoise.add_option(
      "--max-memory", a.max_memory,
      "budget for the file's pixels and the denoiser's buffers, e.g. 4G (default: half the RAM)");
  denoise.add_option("--progress", a.progress, progress_option_help())
      ->check(CLI::IsMember(progress_modes()));
  denoise.add_flag("-q,--quiet", a.quiet, "no progress");
}

void add_mesh_options(CLI::App& mesh, MeshArgs& a) {
  mesh.add_option("scene", a.scene_file, "glTF scene (.gltf or .glb)")->required();
  mesh.add_option("-o,--output", a.output, "the meshes as .glb, or .gltf with OUT.bin beside it (atomically)")
      ->required();
  mesh.add_option("--resolution", a.resolution,
                  "marching-cubes cells along the longest axis of each shape's bounds (1 to 4096)")
      ->required();
  mesh.add_option("--node", a.node, "only the implicit shapes of this glTF node (index or name)");
  mesh.add_option("--scene", a.scene, "glTF scene index")->check(CLI::Range(0, 1 << 30));
  mesh.add_option(
      "--max-memory", a.max_memory,
      "one budget for the scene, the sampling grids and the meshes, e.g. 4G (default: half the RAM)");
  mesh.add_flag("--allow-external-uris", a.allow_external,
                "let buffer URIs reach files outside the scene's folder");
  mesh.add_flag("-q,--quiet", a.quiet, "no warnings or summary");
}

void add_proxies_options(CLI::App& proxies, ProxiesArgs& a) {
  proxies.add_option("scene", a.scene_file, "glTF scene (.gltf or .glb)")->required();
  proxies
      .add_option(
          "--kind", a.kind,
          "sphere (minimal, Welzl), ritter (Ritter's sphere), aabb, obb, capsule, hull (convex, Qhull), "
          "kdop, composite (a hull per connected part)")
      ->required();
  proxies.add_option("--node", a.node,
                     "one proxy for this glTF node and the nodes below it (index or name); "
                     "default: one per node that places a mesh");
  proxies.add_option("-o,--output", a.output,
                     "write the proxies as PENUMBRA_shapes to a .glb, or .gltf with OUT.bin beside it "
                     "(atomically), with the scene's cameras and lights");
  proxies.add_flag("--overlay", a.overlay,
                   "the output keeps the scene's geometry, proxies translucent over it");
  proxies.add_option("--kdop", a.kdop, "k of --kind kdop: 6, 14, 18 or 26 (default 26)");
  proxies
      .add_option(
          "--samples", a.samples,
          "proxy surface samples measuring the Hausdorff distance (default 20000; 0: not measured; at "
          "most 10^7, 96 bytes each charged to --max-memory)")
      ->check(CLI::Range(0, 10000000));
  proxies.add_option("--threads", a.threads, "worker threads (default: all; does not change results)")
      ->check(CLI::Range(0, 1024));
  proxies.add_flag("--json", a.json, "the report as JSON on stdout");
  proxies.add_option("--scene", a.scene, "glTF scene index")->check(CLI::Range(0, 1 << 30));
  proxies.add_option("--max-memory", a.max_memory,
                     "one budget for the scene and the fitting, e.g. 4G (default: half the RAM)");
  proxies.add_flag("--allow-external-uris", a.allow_external,
                   "let buffer URIs reach files outside the scene's folder");
  proxies.add_flag("-q,--quiet", a.quiet, "no warnings");
}

void add_collide_options(CLI::App& collide, CollideArgs& a) {
  collide.add_option("scene", a.scene_file, "glTF scene (.gltf or .glb)")->required();
  collide.add_option("--proxy", a.proxy,
                     "the narrow phase: mesh (the triangles, exact; default) or a proxy kind fitted to each "
                     "node (sphere, ritter, aabb, obb, capsule, hull, kdop, composite), which also gives the "
                     "penetration depth");
  collide.add_option("--kdop", a.kdop, "k of --proxy kdop: 6, 14, 18 or 26 (default 26)");
  collide.add_option(
      "--frames", a.frames,
      "test frames A to B inclusive (A-B, A-B:STEP or N), each at time N / --fps; default: the "
      "file's static pose");
  collide.add_option("--fps", a.fps, "frames per second of --frames (default 24)");
  collide.add_flag("--include-children", a.include_children,
                   "also test pairs the node hierarchy or a skin joins (one node below the other; a skinned "
                   "mesh and the nodes at or below its joints)");
  collide.add_flag(
      "--volumes", a.volumes,
      "also the volume each contact's pair shares: exact for polyhedral proxies and two spheres, "
      "else (meshes, which must be closed; capsules) with a stated error bound");
  collide.add_flag(
      "--continuous", a.continuous,
      "also the first contact between each frame and the next: on meshes, of every node whose vertices move "
      "(each on a straight line; exact vertex-face and edge-edge times), on proxies, of nodes that move "
      "rigidly "
      "(conservative advancement); needs --frames with two frames or more");
  collide.add_flag("--json", a.json, "the report as JSON on stdout");
  collide.add_option("--scene", a.scene, "glTF scene index")->check(CLI::Range(0, 1 << 30));
  collide.add_option("--max-memory", a.max_memory,
                     "one budget for the scene and the tests, e.g. 4G (default: half the RAM)");
  collide.add_flag("--allow-external-uris", a.allow_external,
                   "let buffer URIs reach files outside the scene's folder");
  collide.add_flag("-q,--quiet", a.quiet, "no warnings");
}

/// A CLI11 check refusing an empty value (which would read as the option not given).
std::string non_empty(const std::string& value) {
  return value.empty() ? "the value is empty" : "";
}

void add_batch_options(CLI::App& batch, BatchArgs& a) {
  batch.add_option("job", a.job_file, "job file (.json): the shots to render")->required();
  auto* list = batch.add_flag(
      "--list", a.list, "print the work units, one per line: UNIT SHOT FRAME TILE OUTPUT (tab-separated)");
  auto* unit =
      batch.add_option("--unit", a.unit, "render work unit N only (0 = the first listed)")->excludes(list);
  batch.add_flag("--merge", a.merge, "merge every tiled frame from its stripes and write its display image")
      ->excludes(list)
      ->excludes(unit);
  batch
      .add_option("--tiles", a.tiles,
                  "split every frame of shots without \"tiles\" into N stripes (default 1)")
      ->check(CLI::Range(1, kMaxJobTiles));
  batch.add_flag("--skip-existing", a.skip_existing,
                 "keep outputs that already are complete EXRs (frames, stripes, merged frames)");
  batch.add_flag("-q,--quiet", a.quiet, "no progress, warnings or summaries on stderr");
  batch.add_option("--progress", a.progress, progress_option_help())->check(CLI::IsMember(progress_modes()));
  batch.add_option("--threads", a.threads, "render --threads for shots whose settings give none")
      ->check(CLI::Range(1, 1024));
  batch.add_option("--max-memory", a.max_memory, "render --max-memory for shots whose settings give none");
  batch
      .add_option("--output-root", a.output_root,
                  "folder every file of the job must be written in (default: the job file's folder)")
      ->check(non_empty);
}

void add_submit_slurm_options(CLI::App& slurm, SubmitArgs& a) {
  slurm.add_option("job", a.job_file, "job file (.json)")->required();
  slurm
      .add_option("--tiles", a.tiles,
                  "split every frame of shots without \"tiles\" into N stripes (default 1)")
      ->check(CLI::Range(1, kMaxJobTiles));
  slurm.add_option("--partition", a.partition, "Slurm partition (default: the cluster's)");
  slurm.add_flag("--dry-run", a.dry_run, "print the sbatch scripts and commands; write and submit nothing");
  slurm.add_option("--threads", a.threads, "CPUs per task for shots whose settings give no threads")
      ->check(CLI::Range(1, 1024));
  slurm.add_option("--max-memory", a.max_memory, "memory budget for shots whose settings give none, e.g. 4G");
  slurm.add_option("--retries", a.retries, "runs of a failed unit after the first, per task (default 2)")
      ->check(CLI::Range(0, 100));
  slurm
      .add_option("--output-root", a.output_root,
                  "folder every file of the job must be written in (default: the job file's folder)")
      ->check(non_empty);
  slurm.add_option("--scripts", a.scripts,
                   "folder for the scripts and logs (default: JOB.slurm beside the job)");
  slurm.add_option("--time", a.time_limit,
                   "Slurm time limit per task, e.g. 2:00:00 (default: the partition's)");
}

int report(const char* kind, const char* what, int code) {
  std::fprintf(stderr, "penumbra: %s: %s\n", kind, what);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Penumbra: glTF 2.0 batch renderer (Embree + TBB, OpenEXR + OpenColorIO output)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("penumbra " PENUMBRA_VERSION));
  RenderArgs render_args;
  auto* render =
      app.add_subcommand("render", "Render a glTF scene to a scene-linear EXR and a display image");
  add_render_options(*render, render_args);
  InfoArgs info_args;
  auto* info =
      app.add_subcommand("info", "Describe a glTF scene: scenes, meshes, materials, cameras, lights, bounds");
  add_info_options(*info, info_args);
  MergeArgs merge_args;
  auto* merge = app.add_subcommand(
      "merge", "Assemble the EXRs of --crop/--tile renders into the full frame (bit for bit)");
  add_merge_options(*merge, merge_args);
  DeepArgs deep_args;
  const DeepCommands deep = add_deep_command(app, deep_args);
  DenoiseArgs denoise_args;
  auto* denoise = app.add_subcommand(
      "denoise", "Denoise a path-traced EXR from its halves layers (NFOR feature regression)");
  add_denoise_options(*denoise, denoise_args);
  BatchArgs batch_args;
  auto* batch = app.add_subcommand(
      "batch", "Render the shots of a job file, or list its work units and render one of them (farms)");
  add_batch_options(*batch, batch_args);
  SubmitArgs submit_args;
  auto* submit = app.add_subcommand("submit", "Submit a job file's work units to a farm scheduler");
  submit->require_subcommand(1);
  auto* submit_slurm = submit->add_subcommand(
      "slurm", "Submit as a Slurm array job (one work unit per task) and a merge job for tiled frames");
  add_submit_slurm_options(*submit_slurm, submit_args);
  MeshArgs mesh_args;
  auto* mesh = app.add_subcommand(
      "mesh",
      "Extract the implicit shapes of a glTF scene as triangle meshes (marching cubes) into a .glb or .gltf");
  add_mesh_options(*mesh, mesh_args);
  ProxiesArgs proxies_args;
  auto* proxies = app.add_subcommand(
      "proxies", "Fit bounding proxies (spheres, boxes, capsules, convex hulls, k-DOPs) to a scene's nodes");
  add_proxies_options(*proxies, proxies_args);
  CollideArgs collide_args;
  auto* collide = app.add_subcommand(
      "collide", "List the nodes of a glTF scene that touch or interpenetrate, at its pose or at each frame");
  add_collide_options(*collide, collide_args);
  QueryArgs query_args;
  auto* query = add_query_command(app, query_args);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version: on stdout
    for (const std::string& message : parse_error_messages(app, e, argc, argv))
      report("error", message.c_str(), kExitInput);
    return kExitInput;
  }
  note_given_options(*render, argc, argv, render_args);
  try {
    if (*render) return run_render(render_args);
    if (*merge) return run_merge(merge_args);
    if (*deep.deep) return run_deep(deep, deep_args);
    if (*denoise) return run_denoise(denoise_args);
    if (*batch) return run_batch(batch_args);
    if (*submit) return run_submit_slurm(submit_args);
    if (*mesh) return run_mesh(mesh_args);
    if (*info) return run_info(info_args);
    if (*query) return run_query(*query, query_args);
    if (*proxies) return run_proxies(proxies_args);
    if (*collide) return run_collide(collide_args);
  } catch (const InputError& e) {
    return report("error", e.what(), kExitInput);
  } catch (const UsageError& e) {
    return report("error", e.what(), kExitInput);
  } catch (const std::invalid_argument& e) {
    return report("error", e.what(), kExitInput);
  } catch (const std::bad_alloc&) {
    // Outputs are written atomically: nothing half-written is left behind.
    std::fprintf(
        stderr,
        "penumbra: error: out of memory while %s; no file is left half-written (a lower --max-memory refuses "
        "oversized inputs up front)\n",
        current_phase());
    return kExitInternal;
  } catch (const std::runtime_error& e) {
    // A failed write, sync or rename (full disk, permissions): the message names the file.
    return report("error", e.what(), kExitInternal);
  } catch (const std::exception& e) {
    return report("error", (std::string("internal error: ") + e.what()).c_str(), kExitInternal);
  }
  return kExitInternal;
}
