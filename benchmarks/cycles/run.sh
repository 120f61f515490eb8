#!/usr/bin/env bash
# Penumbra's path tracer against Blender Cycles (CPU) on the same scenes, camera, resolution,
# spp, threads and constant world, in the same run on the same machine (the path tracer's benchmark).
# For each scene and renderer: a REF_SPP reference (with another seed), then renders at 1 spp
# and at each of SPPS, timed by the renderer itself (render only, no loading; the median of
# REPEATS runs), with the RMSE of R, G, B against its own reference (oiiotool --diff). The
# 1-spp time is each renderer's fixed cost (Cycles' includes Blender's scene set-up), so
# N spp minus 1 spp is the marginal cost of N - 1 samples. Writes
# benchmarks/results/cycles-<date>.txt and prints the summary table of summarize.py.
#
# usage: benchmarks/cycles/run.sh [PENUMBRA_BINARY]
#   env: REF_SPP=1024 SPPS="16 64 256" THREADS=2 REPEATS=3 SCENES="cornell helmet ..." (default: every scene)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
penumbra=${1:-$root/build/apps/penumbra}
corpus=${PENUMBRA_CORPUS:-$root/../shared/corpus}
REF_SPP=${REF_SPP:-1024}
SPPS=${SPPS:-"16 64 256"}
THREADS=${THREADS:-2}
REPEATS=${REPEATS:-3}
SCENES=${SCENES:-}
W=640 H=360
work=$(mktemp -d /tmp/penumbra-cycles.XXXXXX)
out="$root/benchmarks/results/cycles-$(date +%Y-%m-%d).txt"
command -v blender >/dev/null || { echo "blender not installed (apt-get install blender python3-numpy)"; exit 2; }

# name, file, eye x y z, yfov, pitch (degrees about +X), world radiance. Each camera looks down
# -Z at the centre of the model's bounds, far enough back that the model fills most of the height.
v=$corpus/valid
scenes=(
  "cornell|$v/CornellBox-Vinc3r/glTF/cornellBox-2.80-Eevee-gltf.gltf|0 1.5 5.6|0.75|0|0"
  "helmet|$v/DamagedHelmet/glTF-Binary/DamagedHelmet.glb|0 0 2.7|0.75|0|1"
  "bottle|$v/WaterBottle/glTF/WaterBottle.gltf|0 0 0.37|0.75|0|1"
  "avocado|$v/Avocado/glTF/Avocado.gltf|0 0.031 0.1|0.75|0|1"
  "suzanne|$v/Suzanne/glTF/Suzanne.gltf|0 0 3.3|0.75|0|1"
  "duck|$v/Duck/glTF-Binary/Duck.glb|0.13 0.87 2.6|0.75|0|1"
  "transmission|$v/TransmissionTest/glTF-Binary/TransmissionTest.glb|0 0.75 1.5|0.75|-22|1"
  "shoe|$corpus/extensions/MaterialsVariantsShoe/glTF/MaterialsVariantsShoe.gltf|0 0.12 0.32|0.75|-8|1"
)

rmse() { oiiotool "$1" --ch R,G,B "$2" --ch R,G,B --diff 2>&1 | awk '/RMS error/ {print $4}'; }
pen() {  # scene out spp bg [seed] -> seconds
  "$penumbra" render "$1" -o "$2" --no-png --integrator path --energy-compensation off --spp "$3" --seed "${5:-0}" --width $W --height $H --camera bench \
    --threads "$THREADS" --env "$4" --float 2>&1 | awk '/render [0-9.]+s/ {for (i=1;i<=NF;i++) if ($i=="render") {sub("s","",$(i+1)); print $(i+1)}}'
}
cyc() {  # scene out spp bg [seed] -> seconds
  blender -b --factory-startup -P "$here/render_cycles.py" -- "$1" "$2" $W $H "$3" "$THREADS" "$4" "seed=${5:-0}" 2>&1 |
    awk '/cycles_render_seconds/ {print $2}'
}

{
  echo "# Penumbra path tracer vs Blender Cycles, $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "# command: benchmarks/cycles/run.sh  (REF_SPP=$REF_SPP SPPS=\"$SPPS\" THREADS=$THREADS, ${W}x${H})"
  echo "# machine: $(nproc) cores of $(awk -F': ' '/model name/ {print $2; exit}' /proc/cpuinfo), $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo); $(blender --version 2>/dev/null | head -1); penumbra $("$penumbra" --version | awk '{print $2}')"
  echo "# pixels: $((W * H)); render_seconds: median of $REPEATS runs"
  echo "# columns: scene renderer spp render_seconds samples_per_second rmse_vs_own_reference"
} > "$out"

for s in "${scenes[@]}"; do
  IFS='|' read -r name file eye fov pitch bg <<<"$s"
  [ -z "$SCENES" ] || [[ " $SCENES " == *" $name "* ]] || continue
  scene=$(python3 "$here/add_camera.py" "$file" "$work/$name" $eye "$fov" "$pitch")
  for r in penumbra cycles; do
    f=$([ $r = penumbra ] && echo pen || echo cyc)
    # The reference with another seed, so that it shares no samples with the renders it measures.
    t=$($f "$scene" "$work/$name-$r-ref.exr" "$REF_SPP" "$bg" 1)
    echo "$name $r $REF_SPP $t reference" | tee -a "$out"
    for spp in 1 $SPPS; do
      t=$(for i in $(seq "$REPEATS"); do $f "$scene" "$work/$name-$r-$spp.exr" "$spp" "$bg"; done | sort -g |
        awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}')
      sps=$(awk -v t="$t" -v n=$((W * H * spp)) 'BEGIN {printf "%.0f", n / t}')
      echo "$name $r $spp $t $sps $(rmse "$work/$name-$r-$spp.exr" "$work/$name-$r-ref.exr")" | tee -a "$out"
    done
  done
done
python3 "$here/summarize.py" "$out" | tee -a "$out"
echo "results: $out"
echo "images: $work"
