#!/usr/bin/env bash
# The full benchmark suite behind benchmarks/RESULTS.md. Needs a Release build (scripts/setup.sh
# build) and, for the Stanford models, node/npm (benchmarks/fetch_models.sh is called).
#   benchmarks/run_suite.sh [OUT_DIR]       (default: build/bench-results)
# Writes, per part, a table (.txt), CSV, JSON and SVG chart, and the cost heat maps, to OUT_DIR.
# Takes about 15 minutes on 2 cores. PENUMBRA_CORPUS points at the shared corpus (default
# ../shared/corpus); corpus models are skipped when it is absent.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
BUILD_DIR="${BUILD_DIR:-build}"
out="${1:-$BUILD_DIR/bench-results}"
bench="$BUILD_DIR/benchmarks/penumbra-bench"
corpus="${PENUMBRA_CORPUS:-../shared/corpus}"
mkdir -p "$out/heatmaps"
[[ -x "$bench" ]] || { echo "run_suite: $bench not found: build first (scripts/setup.sh build)" >&2; exit 2; }

models=$(bash benchmarks/fetch_models.sh "$BUILD_DIR")
dragon=$(echo "$models" | grep dragon.gltf)
bunny=$(echo "$models" | grep bunny.gltf)
corpus_scenes=()
for m in MetalRoughSpheresNoTextures TransmissionTest DamagedHelmet WaterBottle Suzanne; do
  f=$(ls "$corpus/valid/$m"/glTF-Binary/*.glb "$corpus/valid/$m"/glTF/*.gltf 2>/dev/null | head -1 || true)
  if [[ -n "$f" ]]; then corpus_scenes+=("$f"); else echo "run_suite: $corpus/valid/$m not found: skipped" >&2; fi
done

run() {  # run NAME ARGS...: one penumbra-bench invocation, its table kept in NAME.txt
  local name="$1"; shift
  echo "== $name: penumbra-bench $*" >&2
  "$bench" "$@" --csv "$out/$name.csv" --json "$out/$name.json" --svg "$out/$name.svg" | tee "$out/$name.txt"
}

# 1. Real models, generated interiors and a terrain of 1M triangles: every structure, every ray
# kind, one thread, medians of 5 passes; builds with every core (medians of 5).
run models "$dragon" "$bunny" "${corpus_scenes[@]}" gen:atrium gen:soup gen:terrain:1000000 \
  --accel embree,bvh,kdtree,grid --threads 1 --builds 5 --repeats 5 --heatmaps "$out/heatmaps"
# 2. The BVH's other widths (the default is the CPU's widest): 4-wide SSE and the binary tree.
for w in 4 2; do
  run "bvh-width$w" "$dragon" "$bunny" gen:atrium --accel embree,bvh --accel-param "bvh.width=$w" \
    --threads 1 --builds 3 --repeats 5
done
# 2b. Spatial splits (a quality setting) against the default object splits, same run.
run bvh-spatial "$dragon" "$bunny" "${corpus_scenes[@]}" gen:atrium gen:stadium scenes/default.gltf --accel embree,bvh \
  --accel-param bvh.spatial_alpha=1e-5 --threads 1 --builds 3 --repeats 5
# 3. Where a uniform grid collapses: the teapot in a stadium (the teapot falls into a few cells)
# and long slivers (every cell along them lists them all); the hierarchical grid's default
# against its flat form (grid.max_depth=1: tens of thousands of triangle tests per ray, so
# fewer rays and smaller scenes).
run collapse gen:stadium:50000 gen:slivers:100000 --accel embree,bvh,kdtree,grid --threads 1 --builds 3 \
  --repeats 5 --width 128 --height 72 --heatmaps "$out/heatmaps"
run collapse-flat gen:stadium:50000 gen:slivers:100000 --accel grid --accel-param grid.max_depth=1 \
  --threads 1 --builds 1 --repeats 1 --width 128 --height 72
# 4. Scaling: build time and memory against N (2 threads).
run scaling gen:terrain:500000 gen:terrain:1000000 gen:terrain:2000000 \
  --accel embree,bvh,kdtree,grid --rays random,primary --threads 0 --builds 3 --repeats 3
# 5. Spatial structures side by side (RESULTS.md, "Spatial structures: memory, build, work per ray, refit"):
# memory, build with 1 thread and every core, work per ray and throughput for every structure,
# and the flat uniform grid (grid.max_depth=1) on the same scenes.
run tradeoffs "$dragon" "$bunny" gen:stadium:50000 gen:slivers:100000 gen:soup:100000 gen:terrain:1000000 \
  --tradeoffs --accel embree,bvh,kdtree,grid,octree,bsp --builds 1 --repeats 3 --width 256 --height 144
run tradeoffs-flat-grid "$dragon" "$bunny" gen:stadium:50000 gen:slivers:100000 gen:soup:100000 \
  gen:terrain:1000000 --tradeoffs --accel grid --accel-param grid.max_depth=1 --builds 1 --repeats 1 \
  --width 256 --height 144
# 6. Refit against rebuild: the BVH over 240 frames of a skinned corpus model.
brainstem="$corpus/extensions/BrainStem/glTF-Draco/BrainStem.gltf"
if [[ -f "$brainstem" ]]; then
  echo "== refit: penumbra-bench --refit $brainstem" >&2
  "$bench" --refit "$brainstem" --refit-frames 240 --width 256 --height 144 --threads 1 --csv "$out/refit.csv" |
    tee "$out/refit.txt"
else
  echo "run_suite: $brainstem not found: refit skipped" >&2
fi
echo "$out"
