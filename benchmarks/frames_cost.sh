#!/usr/bin/env bash
# What `--frames` saves over one process a frame: renders the 240 frames of
# scenes/flythrough.gltf (a camera flying round the room for 10 s at 24 fps, the yellow box
# turning) as one `penumbra render --frames 1-240` and as 240 `penumbra render --frame N`
# processes, RUNS times each, alternating, at a small resolution and 1 spp so that starting,
# loading and building weigh against rendering. Prints the median wall time of each way, their
# difference per frame, and the median load and build seconds per frame of each way (from the
# --stats-json files of the last run; with --frames the first frame loads and builds, the others
# pose the loaded scene and move its instances).
# Usage: benchmarks/frames_cost.sh [BUILD_DIR] [RUNS] [FRAMES] [render flags...]
# (defaults: RUNS 3, FRAMES 240, flags --width 160 --spp 1).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-$here/../build}"
runs="${2:-3}"
frames="${3:-240}"
shift $(( $# > 3 ? 3 : $# ))
penumbra="$build/apps/penumbra"
scene="$here/../scenes/flythrough.gltf"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
[ $# -gt 0 ] || set -- --width 160 --spp 1
flags=(--no-png --quiet "$@")
now() { date +%s.%N; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
one_run() {  # one process for the range
  rm -rf "$work/one"; mkdir "$work/one"
  local t0; t0="$(now)"
  "$penumbra" render "$scene" --frames "1-$frames" -o "$work/one/f.####.exr" --stats-json "$work/one/s.####.json" \
    "${flags[@]}" >/dev/null
  awk -v a="$t0" -v b="$(now)" 'BEGIN { print b - a }'
}
separate_run() {  # one process a frame
  rm -rf "$work/sep"; mkdir "$work/sep"
  local t0; t0="$(now)"
  for n in $(seq "$frames"); do
    "$penumbra" render "$scene" --frame "$n" -o "$work/sep/f.####.exr" --stats-json "$work/sep/s.####.json" \
      "${flags[@]}" >/dev/null
  done
  awk -v a="$t0" -v b="$(now)" 'BEGIN { print b - a }'
}
# The median of one phase's seconds over a folder's per-frame statistics.
phase() { python3 -c 'import glob, json, sys
print("\n".join(str(json.load(open(f))["seconds"][sys.argv[2]]) for f in glob.glob(sys.argv[1] + "/s.*.json")))' "$1" "$2" | median; }
: > "$work/one.txt"
: > "$work/sep.txt"
one_run > /dev/null  # warm-up
for _ in $(seq "$runs"); do
  one_run >> "$work/one.txt"
  separate_run >> "$work/sep.txt"
done
o="$(median < "$work/one.txt")"
s="$(median < "$work/sep.txt")"
echo "scene: scenes/flythrough.gltf, $frames frames; flags: ${flags[*]}; $runs runs each, alternating"
echo "--frames 1-$frames, one process: median ${o}s wall over $runs runs: $(tr '\n' ' ' < "$work/one.txt")"
echo "$frames processes, --frame N:      median ${s}s wall over $runs runs: $(tr '\n' ' ' < "$work/sep.txt")"
ol="$(phase "$work/one" load)"; ob="$(phase "$work/one" build)"
sl="$(phase "$work/sep" load)"; sb="$(phase "$work/sep" build)"
first="$(python3 -c 'import json, sys; s = json.load(open(sys.argv[1]))["seconds"]; print("load %gs build %gs" % (s["load"], s["build"]))' "$work/one/s.0001.json")"
echo "per frame (medians): --frames load ${ol}s build ${ob}s (its first frame: $first); separate processes load ${sl}s build ${sb}s"
awk -v o="$o" -v s="$s" -v n="$frames" -v sl="$sl" -v sb="$sb" 'BEGIN {
  d = (s - o) / n
  printf "difference per frame: %.4fs (separate processes - --frames); load + build per frame of a process: %.4fs\n", d, sl + sb
  printf "--frames beats %d processes by at least the per-frame load + build time: %s\n", n, (d >= sl + sb) ? "yes" : "no"
}'
