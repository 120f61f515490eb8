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
for m in MetalRoughSpheresNoTextures TransmissionTest DamagedHelmet; do
  f="$corpus/valid/$m/glTF-Binary/$m.glb"
  if [[ -f "$f" ]]; then corpus_scenes+=("$f"); else echo "run_suite: $f not found: skipped" >&2; fi
done

run() {  # run NAME ARGS...: one penumbra-bench invocation, its table kept in NAME.txt
  local name="$1"; shift
  echo "== $name: penumbra-bench $*" >&2
  "$bench" "$@" --csv "$out/$name.csv" --json "$out/$name.json" --svg "$out/$name.svg" | tee "$out/$name.txt"
}

# 1. Real models and generated interiors: every structure, every ray kind, 1 and 2 threads.
run models "$dragon" "$bunny" "${corpus_scenes[@]}" gen:atrium gen:soup \
  --accel embree,bvh,kdtree,grid --threads 1,2 --builds 5 --repeats 3 --heatmaps "$out/heatmaps"
# 2. The binary BVH against the 4-wide one on the dragon.
run bvh-width "$dragon" --accel embree,bvh --accel-param bvh.width=2 --accel-param bvh.traversal_cost=1 \
  --threads 1,2 --builds 5 --repeats 3
# 3. Where a uniform grid collapses: the teapot in a stadium (the teapot falls into a few cells)
# and long slivers (every cell along them lists them all): tens of thousands of triangle tests per
# ray, so fewer rays and smaller scenes.
run collapse gen:stadium:50000 gen:slivers:100000 --accel embree,bvh,kdtree,grid --threads 1,2 --builds 3 \
  --repeats 3 --width 128 --height 72 --heatmaps "$out/heatmaps"
# 4. Scaling: build time and memory against N up to 5.2M triangles (2 threads).
run scaling gen:terrain:500000 gen:terrain:1000000 gen:terrain:2000000 gen:terrain:5200000 \
  --accel embree,bvh,kdtree,grid --rays random,primary --threads 0 --builds 3 --repeats 3
echo "$out"
