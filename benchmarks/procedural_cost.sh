#!/usr/bin/env bash
# What procedural textures cost in the path tracer: renders scenes/procedural.gltf and its
# image-textured twin (benchmarks/make_textured_twin.py) RUNS times each, alternating, and prints
# the median render time of each (penumbra's own "render" figure, which excludes loading) and
# their ratio. With PENUMBRA_UNDISPLACED=1 both scenes lose their noise displacement (see
# make_textured_twin.py --undisplaced), which isolates the textures' cost.
# Usage: benchmarks/procedural_cost.sh [BUILD_DIR] [RUNS] [render flags...]
# (default flags: --spp 64 --width 640).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-$here/../build}"
runs="${2:-5}"
shift $(( $# > 2 ? 2 : $# ))
penumbra="$build/apps/penumbra"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
twin_flags=()
[ "${PENUMBRA_UNDISPLACED:-0}" = 1 ] && twin_flags=(--undisplaced)
python3 "$here/make_textured_twin.py" "${twin_flags[@]}" "$here/../scenes/procedural.gltf" "$work" >/dev/null
[ $# -gt 0 ] || set -- --spp 64 --width 640
flags=(--integrator path --no-png "$@")
render_seconds() {
  "$penumbra" render "$1" -o "$work/out.exr" "${flags[@]}" 2>&1 |
    sed -n 's/.* render \([0-9.]*\)s .*/\1/p'
}
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
: > "$work/procedural.txt"
: > "$work/textured.txt"
render_seconds "$work/procedural.gltf" > /dev/null  # warm-up
for _ in $(seq "$runs"); do
  render_seconds "$work/procedural.gltf" >> "$work/procedural.txt"
  render_seconds "$work/twin.gltf" >> "$work/textured.txt"
done
p="$(median < "$work/procedural.txt")"
t="$(median < "$work/textured.txt")"
echo "flags: ${flags[*]}${twin_flags:+ (both scenes ${twin_flags[*]})}"
echo "procedural render median ${p}s over $runs runs: $(tr '\n' ' ' < "$work/procedural.txt")"
echo "textured   render median ${t}s over $runs runs: $(tr '\n' ' ' < "$work/textured.txt")"
awk -v p="$p" -v t="$t" 'BEGIN { printf "ratio procedural / textured: %.2f (target <= 2)\n", p / t }'
