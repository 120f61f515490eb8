#!/usr/bin/env bash
# Many lights: the light tree against the power table (and Cycles 3.4, which has no light tree,
# beside them) on the generated room of make_scene.py: about 12,000 emissive triangles of
# varied power and one emissive-textured sign. For each light sampler: a reference at REF_SPP
# (the tree's; every sampler converges to the same image), renders at each of SPPS timed by the
# renderer (render only, no loading) and their RMSE of R, G, B against the reference; then the
# efficiency 1 / (RMSE^2 x seconds), whose ratio between two samplers is their ratio of times
# to equal RMSE (unbiased Monte Carlo: RMSE^2 x time is constant). Cycles renders against its
# own reference. Penumbra's renders also give the RMSE of the reflected light alone (the beauty
# minus its emission light group: what the light sampler decides, without the pixel noise of
# emitters seen directly), and a third configuration chooses LIGHT_SAMPLES lights per vertex
# with the tree. Writes benchmarks/results/many-lights-<date>[-depthN].txt.
#
# usage: benchmarks/many_lights/run.sh [PENUMBRA_BINARY]
#   env: REF_SPP=2048 SPPS="16 64 256" THREADS=2 W=320 H=180 DEPTH=12 LIGHT_SAMPLES=4
#        CYCLES=1 (0: skip Cycles)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
penumbra=${1:-$root/build/apps/penumbra}
REF_SPP=${REF_SPP:-2048}
SPPS=${SPPS:-"16 64 256"}
THREADS=${THREADS:-2}
W=${W:-320} H=${H:-180}
DEPTH=${DEPTH:-12}
LIGHT_SAMPLES=${LIGHT_SAMPLES:-4}
CYCLES=${CYCLES:-1}
work=$(mktemp -d /tmp/penumbra-many-lights.XXXXXX)
suffix=$([ "$DEPTH" = 12 ] || echo "-depth$DEPTH")
out="$root/benchmarks/results/many-lights-$(date +%Y-%m-%d)$suffix.txt"
scene=$(python3 "$here/make_scene.py" "$work")

rmse() { oiiotool "$1" --ch R,G,B "$2" --ch R,G,B --diff 2>&1 | awk '/RMS error/ {print $4}'; }
# The reflected light of a Penumbra EXR: R, G, B minus the emission light group.
reflected() { oiiotool "$1" --ch R,G,B "$1" --ch emission.R,emission.G,emission.B --chnames R,G,B --sub -o "$2"; }
pen() {  # sampler out spp [light samples] [seed] -> seconds
  "$penumbra" render "$scene" -o "$2" --no-png --integrator path --energy-compensation off --light-sampler "$1" \
    --light-samples "${4:-1}" --seed "${5:-0}" --max-depth "$DEPTH" --aov light \
    --spp "$3" --width "$W" --height "$H" --threads "$THREADS" --float 2>&1 |
    awk '/render [0-9.]+s/ {for (i=1;i<=NF;i++) if ($i=="render") {sub("s","",$(i+1)); print $(i+1)}}'
}
cyc() {  # out spp [seed] -> seconds
  blender -b --factory-startup -P "$root/benchmarks/cycles/render_cycles.py" -- "$scene" "$1" "$W" "$H" "$2" \
    "$THREADS" 0 "seed=${3:-0}" 2>&1 | awk '/cycles_render_seconds/ {print $2}'
}
efficiency() {  # rmse seconds -> 1 / (rmse^2 seconds), or - when either is missing or zero
  awk -v e="$1" -v t="$2" 'BEGIN {if (e + 0 > 0 && t + 0 > 0) printf "%.4g", 1 / (e * e * t); else print "-"}'
}
row() {  # name spp seconds exr reference [reflected exr, reference]
  local e r="-" re="-"
  e=$(rmse "$4" "$5" || true)  # oiiotool --diff exits 1 when the images differ
  if [ $# -ge 7 ]; then
    r=$(rmse "$6" "$7" || true)
    re=$(efficiency "$r" "$3")
  fi
  echo "$1 $2 $3 $e $(efficiency "$e" "$3") $r $re" | tee -a "$out"
}

{
  echo "# Many lights: light tree vs power table vs Cycles 3.4, $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "# command: benchmarks/many_lights/run.sh  (REF_SPP=$REF_SPP SPPS=\"$SPPS\" THREADS=$THREADS DEPTH=$DEPTH LIGHT_SAMPLES=$LIGHT_SAMPLES, ${W}x${H}, --energy-compensation off)"
  echo "# machine: $(nproc) cores; penumbra $("$penumbra" --version | awk '{print $2}')"
  echo "# columns: sampler spp render_seconds rmse_vs_reference efficiency(1/(rmse^2 s)) reflected_rmse reflected_efficiency"
} >"$out"

# The reference with another seed: sharing the measured renders' first samples would hide their error.
t=$(pen tree "$work/ref.exr" "$REF_SPP" 1 1)
reflected "$work/ref.exr" "$work/ref-reflected.exr"
echo "reference tree $REF_SPP $t" | tee -a "$out"
for config in tree power "tree-x$LIGHT_SAMPLES"; do
  sampler=${config%%-*}
  n=1
  [ "$config" = "$sampler" ] || n=$LIGHT_SAMPLES
  for spp in $SPPS; do
    t=$(pen "$sampler" "$work/$config-$spp.exr" "$spp" "$n")
    reflected "$work/$config-$spp.exr" "$work/$config-$spp-reflected.exr"
    row "$config" "$spp" "$t" "$work/$config-$spp.exr" "$work/ref.exr" \
      "$work/$config-$spp-reflected.exr" "$work/ref-reflected.exr"
  done
done
if [ "$CYCLES" = 1 ] && [ "$DEPTH" = 12 ] && command -v blender >/dev/null; then
  t=$(cyc "$work/cycles-ref.exr" "$REF_SPP" 1)
  echo "reference cycles $REF_SPP $t" | tee -a "$out"
  for spp in $SPPS; do
    t=$(cyc "$work/cycles-$spp.exr" "$spp")
    row cycles "$spp" "$t" "$work/cycles-$spp.exr" "$work/cycles-ref.exr"
  done
fi
# The tree's advantage: the ratio of efficiencies at each spp (time to equal RMSE, power / tree),
# of the whole image and of the reflected light.
awk -v x="tree-x$LIGHT_SAMPLES" '$1 == "tree" || $1 == x {e[$1, $2] = $5; r[$1, $2] = $7; s[$2] = 1}
     $1 == "power" {p[$2] = $5; q[$2] = $7}
     END {for (k in s) if (p[k] > 0) {
            printf "tree vs power at %s spp: %.2fx faster to equal RMSE, %.2fx on the reflected light\n", k, e["tree", k] / p[k], r["tree", k] / q[k]
            printf "%s vs power at %s spp: %.2fx faster to equal RMSE, %.2fx on the reflected light\n", x, k, e[x, k] / p[k], r[x, k] / q[k]}}' \
  "$out" | sort -k5 -n | tee -a "$out"
echo "results: $out"
echo "images: $work"
