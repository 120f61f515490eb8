#!/usr/bin/env bash
# Many lights: the light tree against the power table (and Cycles 3.4, which has no light tree,
# beside them) on the generated room of make_scene.py: about 12,000 emissive triangles of
# varied power and one emissive-textured sign. For each light sampler: a reference at REF_SPP
# (the tree's; every sampler converges to the same image), renders at each of SPPS timed by the
# renderer (render only, no loading) and their RMSE of R, G, B against the reference; then the
# efficiency 1 / (RMSE^2 x seconds), whose ratio between two samplers is their ratio of times
# to equal RMSE (unbiased Monte Carlo: RMSE^2 x time is constant). Cycles renders against its
# own reference. Writes benchmarks/results/many-lights-<date>.txt.
#
# usage: benchmarks/many_lights/run.sh [PENUMBRA_BINARY]
#   env: REF_SPP=2048 SPPS="16 64 256" THREADS=2 W=320 H=180 CYCLES=1 (0: skip Cycles)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
penumbra=${1:-$root/build/apps/penumbra}
REF_SPP=${REF_SPP:-2048}
SPPS=${SPPS:-"16 64 256"}
THREADS=${THREADS:-2}
W=${W:-320} H=${H:-180}
CYCLES=${CYCLES:-1}
work=$(mktemp -d /tmp/penumbra-many-lights.XXXXXX)
out="$root/benchmarks/results/many-lights-$(date +%Y-%m-%d).txt"
scene=$(python3 "$here/make_scene.py" "$work")

rmse() { oiiotool "$1" --ch R,G,B "$2" --ch R,G,B --diff 2>&1 | awk '/RMS error/ {print $4}'; }
pen() {  # sampler out spp -> seconds
  "$penumbra" render "$scene" -o "$2" --no-png --integrator path --energy-compensation off --light-sampler "$1" \
    --spp "$3" --width "$W" --height "$H" --threads "$THREADS" --float 2>&1 |
    awk '/render [0-9.]+s/ {for (i=1;i<=NF;i++) if ($i=="render") {sub("s","",$(i+1)); print $(i+1)}}'
}
cyc() {  # out spp -> seconds
  blender -b --factory-startup -P "$root/benchmarks/cycles/render_cycles.py" -- "$scene" "$1" "$W" "$H" "$2" \
    "$THREADS" 0 2>&1 | awk '/cycles_render_seconds/ {print $2}'
}
row() {  # name spp seconds exr reference
  local e
  e=$(rmse "$4" "$5" || true)  # oiiotool --diff exits 1 when the images differ
  echo "$1 $2 $3 $e $(awk -v t="$3" -v e="$e" 'BEGIN {printf "%.4g", 1 / (e * e * t)}')" | tee -a "$out"
}

{
  echo "# Many lights: light tree vs power table vs Cycles 3.4, $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "# command: benchmarks/many_lights/run.sh  (REF_SPP=$REF_SPP SPPS=\"$SPPS\" THREADS=$THREADS, ${W}x${H}, 12 bounces, --energy-compensation off)"
  echo "# machine: $(nproc) cores; penumbra $("$penumbra" --version | awk '{print $2}')"
  echo "# columns: sampler spp render_seconds rmse_vs_reference efficiency(1/(rmse^2 s))"
} >"$out"

t=$(pen tree "$work/ref.exr" "$REF_SPP")
echo "reference tree $REF_SPP $t" | tee -a "$out"
for sampler in tree power; do
  for spp in $SPPS; do
    t=$(pen "$sampler" "$work/$sampler-$spp.exr" "$spp")
    row "$sampler" "$spp" "$t" "$work/$sampler-$spp.exr" "$work/ref.exr"
  done
done
if [ "$CYCLES" = 1 ] && command -v blender >/dev/null; then
  t=$(cyc "$work/cycles-ref.exr" "$REF_SPP")
  echo "reference cycles $REF_SPP $t" | tee -a "$out"
  for spp in $SPPS; do
    t=$(cyc "$work/cycles-$spp.exr" "$spp")
    row cycles "$spp" "$t" "$work/cycles-$spp.exr" "$work/cycles-ref.exr"
  done
fi
# The tree's advantage: the ratio of efficiencies at each spp (time to equal RMSE, power / tree).
awk '$1 == "tree" {e[$2] = $5} $1 == "power" {p[$2] = $5}
     END {for (s in e) if (p[s] > 0) printf "tree vs power at %s spp: %.2fx faster to equal RMSE\n", s, e[s] / p[s]}' \
  "$out" | sort -k5 -n | tee -a "$out"
echo "results: $out"
echo "images: $work"
