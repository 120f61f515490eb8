#!/usr/bin/env bash
# Penumbra's path tracer against Blender Cycles on the KHR material extension test models: the
# same camera (added to a copy of each file), resolution, spp, bounces and constant white world,
# no other light than the file's own. Writes, for each model, benchmarks/results/materials-<name>.png
# (Penumbra left, Cycles right, sRGB) and one line per model of benchmarks/results/materials.txt
# with the RMSE of R, G, B between the two renders (oiiotool --diff) and each renderer's time.
#
# usage: benchmarks/cycles/materials.sh [PENUMBRA_BINARY]
#   env: SPP=256 THREADS=2 MODELS="ClearCoatTest SheenCloth ..." (default: the six below)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
penumbra=${1:-$root/build/apps/penumbra}
corpus=${PENUMBRA_CORPUS:-$root/../shared/corpus}/extensions
SPP=${SPP:-256}
THREADS=${THREADS:-2}
MODELS=${MODELS:-}
W=480 H=270
work=$(mktemp -d /tmp/penumbra-materials.XXXXXX)
results=$root/benchmarks/results
out=$results/materials.txt
command -v blender >/dev/null || { echo "blender not installed (apt-get install blender python3-numpy)"; exit 2; }

# name, file, camera eye x y z (looking down -Z, 0.75 rad vertical field of view, 16:9): each
# eye is over the centre of the model's bounds, far enough back for the model to fill the frame.
models=(
  "ClearCoatTest|ClearCoatTest/glTF-Binary/ClearCoatTest.glb|-2.13 0.30 19.4"
  "SheenCloth|SheenCloth/glTF/SheenCloth.gltf|0.0087 0.020 0.085"
  "AttenuationTest|AttenuationTest/glTF-Binary/AttenuationTest.glb|0 0 28.7"
  "TransmissionRoughnessTest|TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb|0 0 1.92"
  "AnisotropyStrengthTest|AnisotropyStrengthTest/glTF-Binary/AnisotropyStrengthTest.glb|-0.385 2.71 10.5"
  "IridescenceSuzanne|IridescenceSuzanne/glTF-Binary/IridescenceSuzanne.glb|0 -0.016 7.6"
)

rmse() { oiiotool "$1" --ch R,G,B "$2" --ch R,G,B --diff 2>&1 | awk '/RMS error/ {print $4}'; }

{
  echo "# Penumbra path tracer vs Blender Cycles on the KHR material test models, $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "# command: benchmarks/cycles/materials.sh  (SPP=$SPP THREADS=$THREADS, ${W}x${H}, white world of radiance 1)"
  echo "# machine: $(nproc) cores; $(blender --version 2>/dev/null | head -1); penumbra $("$penumbra" --version | awk '{print $2}')"
  echo "# columns: model rmse_rgb_penumbra_vs_cycles penumbra_seconds cycles_seconds [what Blender's importer reported dropping]"
} > "$out"

for m in "${models[@]}"; do
  IFS='|' read -r name file eye <<<"$m"
  [ -z "$MODELS" ] || [[ " $MODELS " == *" $name "* ]] || continue
  scene=$(python3 "$here/add_camera.py" "$corpus/$file" "$work/$name" $eye 0.75 0)
  # Blender's copy: nothing required, so that its importer loads what it can and drops the rest.
  cscene=$(python3 "$here/add_camera.py" "$corpus/$file" "$work/$name-cycles" $eye 0.75 0 --optional-extensions)
  t0=$(date +%s.%N)
  "$penumbra" render "$scene" -o "$work/$name-penumbra.exr" --png "$work/$name-penumbra.png" --integrator path --energy-compensation off \
    --spp "$SPP" --width $W --height $H --camera bench --threads "$THREADS" --env 1 --quiet
  t1=$(date +%s.%N)
  blender -b --factory-startup -P "$here/render_cycles.py" -- "$cscene" "$work/$name-cycles.exr" $W $H "$SPP" \
    "$THREADS" 1 > "$work/$name-cycles.log" 2>&1
  # What Blender's importer said it could not map.
  dropped=$(grep -o "Extension [A-Za-z_]* is not available[^\"]*\|not supported[^\"]*" "$work/$name-cycles.log" | sort -u | tr '\n' ';' || true)
  t2=$(date +%s.%N)
  oiiotool "$work/$name-cycles.exr" --ch R,G,B --colorconvert linear sRGB -d uint8 -o "$work/$name-cycles.png"
  oiiotool "$work/$name-penumbra.png" --ch R,G,B "$work/$name-cycles.png" --mosaic 2x1 -o "$results/materials-$name.png"
  printf '%s %s %.1f %.1f %s\n' "$name" "$(rmse "$work/$name-penumbra.exr" "$work/$name-cycles.exr")" \
    "$(echo "$t1 - $t0" | bc)" "$(echo "$t2 - $t1" | bc)" "${dropped:-}" | tee -a "$out"
done
echo "results: $out"
echo "images: $work"
