#!/usr/bin/env bash
# What `--deep` costs: renders the shipped scenes with Whitted and the path tracer, each RUNS
# times with `--deep --stats-json`, and prints a Markdown table of the medians: the beauty's
# render seconds, the deep pass's (tracing the camera samples again and merging them per pixel),
# writing the flat EXR and the deep EXR, the deep samples per pixel, and both files' sizes.
# Usage: benchmarks/deep_output.sh [BUILD_DIR] [RUNS] [render flags...]
# (defaults: RUNS 3, flags --width 640 --spp 16).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-$here/../build}"
runs="${2:-3}"
shift $(( $# > 2 ? 2 : $# ))
penumbra="$build/apps/penumbra"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
[ $# -gt 0 ] || set -- --width 640 --spp 16
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
field() { python3 -c 'import json, sys
s = json.load(open(sys.argv[1]))
v = s["seconds"].get(sys.argv[2], 0) if sys.argv[2] != "deep_samples" else s["deep_samples"] / (s["width"] * s["height"])
if sys.argv[2] == "write": v -= s["seconds"]["deep_write"]  # the flat EXR and display image alone
print(v)' "$1" "$2"; }
echo "flags: $*; medians of $runs runs"
echo
echo "| scene | integrator | render s | deep pass s | flat write s | deep write s | deep samples / pixel | flat EXR | deep EXR | deep / flat size |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for scene in default spheres csg procedural; do
  for integrator in whitted path; do
    for run in $(seq "$runs"); do
      "$penumbra" render "$here/../scenes/$scene.gltf" -o "$work/flat.exr" --deep "$work/deep.exr" --no-png -q \
        --integrator "$integrator" --stats-json "$work/s$run.json" "$@" >/dev/null
    done
    row="| $scene | $integrator"
    for key in render deep write deep_write deep_samples; do
      row="$row | $(for run in $(seq "$runs"); do field "$work/s$run.json" "$key"; done | median | xargs printf '%.3g')"
    done
    flat=$(stat -c %s "$work/flat.exr"); deep=$(stat -c %s "$work/deep.exr")
    row="$row | $(numfmt --to=iec "$flat")B | $(numfmt --to=iec "$deep")B | $(awk -v d="$deep" -v f="$flat" 'BEGIN { printf "%.1f", d / f }') |"
    echo "$row"
  done
done
