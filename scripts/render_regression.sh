#!/usr/bin/env bash
# A fixed set of renders that covers the whole output path (both integrators, every
# accelerator, --aov all,cost, --multipart, crops, tiles and merge, an animation time, a
# checkpoint and its resume, a path render through the Python module, and a benchmark smoke
# run's answers), for checking that a change to the code changes no image.
#
#   scripts/render_regression.sh render PENUMBRA OUTDIR   render the set with one binary
#   scripts/render_regression.sh compare DIR_A DIR_B      exit 0 iff every EXR is identical
#
# The Python module and penumbra-bench are found beside PENUMBRA in its build tree
# (../python, ../benchmarks); where either is missing its part is left out with a note.
# IGNORE_ATTRS (a regular expression, default none) leaves header attributes out of the
# comparison, e.g. IGNORE_ATTRS=penumbra:settings when the identity's form changes on purpose.
#
# "Identical" means: the same parts, channels, types, windows and header attributes, except
# the timing attribute penumbra:render_seconds and the command line (which names each run's
# output folder), and the same value in every pixel of every channel except cost_ns.X
# (wall-clock nanoseconds per ray). Compared with oiiotool with zero tolerance.
# Corpus renders (the animation time) need ../shared/corpus or PENUMBRA_CORPUS.
set -euo pipefail

mode="${1:-}"
case "$mode" in
  render)
    bin="$2"; out="$3"
    src="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
    corpus="${PENUMBRA_CORPUS:-$src/../shared/corpus}"
    rm -rf "$out"; mkdir -p "$out"
    fixed="$bin"
    d="$src/scenes/default.gltf"
    r() { "$fixed" render "$@" -q --no-png >/dev/null; }
    for accel in embree bvh kdtree grid brute; do
      r "$d" -o "$out/whitted-$accel.exr" --width 96 --spp 4 --accel "$accel"
      r "$d" -o "$out/path-$accel.exr" --integrator path --width 64 --spp 16 --accel "$accel"
    done
    r "$d" -o "$out/whitted-aovs.exr" --width 96 --spp 4 --aov all,cost --accel bvh
    r "$d" -o "$out/path-aovs.exr" --integrator path --width 64 --spp 16 --aov all,cost --accel bvh
    r "$d" -o "$out/path-multipart.exr" --integrator path --width 64 --spp 16 --aov all --multipart --compression dwaa
    r "$d" -o "$out/path-adaptive.exr" --integrator path --width 64 --spp 64 --adaptive 0.05 --aov samples
    r "$d" -o "$out/crop.exr" --width 96 --spp 4 --crop 10 70 5 40 --aov all
    for i in 0 1 2; do r "$d" -o "$out/tile$i.exr" --integrator path --width 64 --spp 8 --tile "$i/3" --aov all; done
    "$fixed" merge "$out/tile0.exr" "$out/tile1.exr" "$out/tile2.exr" -o "$out/merged.exr" >/dev/null
    # A checkpoint after exactly one pass (a time limit below any pass), then its resume.
    r "$d" -o "$out/resumed.exr" --integrator path --width 48 --spp 32 --checkpoint 1e-9 --time-limit 1e-9
    cp "$out/resumed.exr" "$out/checkpoint.exr"
    r "$d" -o "$out/resumed.exr" --integrator path --width 48 --spp 32 --resume
    build="$(cd "$(dirname "$bin")/.." && pwd)"
    if [ -d "$build/python" ] && ls "$build"/python/penumbra*.so >/dev/null 2>&1; then
      PYTHONPATH="$build/python" python3 - "$d" "$out/python-path.exr" <<'PY'
import sys, penumbra
scene = penumbra.load(sys.argv[1], quiet=True)
result = scene.render(penumbra.RenderSettings(integrator="path", width=64, spp=16, accel="bvh"), aovs=["all"])
result.write_exr(sys.argv[2], metadata={})
PY
    else
      echo "note: no Python module beside $bin: the Python render is left out" >&2
    fi
    if [ -x "$build/benchmarks/penumbra-bench" ]; then
      # The answers only (structure, rays, memory, SAH, count, wrong, ties), not the times.
      "$build/benchmarks/penumbra-bench" "$d" --builds 1 --repeats 1 --threads 1 --width 64 --height 36 \
        --accel embree,bvh,kdtree,grid,octree,bsp,brute | awk '$2 ~ /^(embree|bvh|kdtree|grid|octree|bsp|brute)$/ {
        if ($2 == "embree") { $5 = "-"; $6 = "-" }  # Embree allocations vary from run to run
        print $1, $2, $3, $5, $6, $7, $8, $9, $10 }' > "$out/bench.txt"
    else
      echo "note: no penumbra-bench beside $bin: the benchmark smoke run is left out" >&2
    fi
    if [ -d "$corpus/valid" ]; then
      r "$corpus/valid/InterpolationTest/glTF-Binary/InterpolationTest.glb" -o "$out/anim-whitted.exr" --width 96 --spp 4 --time 0.7
      r "$corpus/valid/InterpolationTest/glTF-Binary/InterpolationTest.glb" -o "$out/anim-path.exr" --integrator path --width 64 --spp 8 --frame 17 --fps 24
      r "$corpus/valid/DamagedHelmet/glTF-Binary/DamagedHelmet.glb" -o "$out/helmet.exr" --integrator path --width 64 --spp 8 --aov all
    else
      echo "note: no corpus at $corpus: the animation and textured renders are left out" >&2
    fi
    ls "$out"/*.exr | wc -l | xargs echo "rendered EXRs:" >&2
    ;;
  compare)
    a="$2"; b="$3"; fails=0; count=0
    header() {  # every attribute but the run's timing and command line
      oiiotool -a --info -v "$1" 2>&1 | grep -vE 'render_seconds|command_line|DateTime|^'"$1" |
        awk -v re="${IGNORE_ATTRS:-}" 'skip { if ($0 ~ /"$/) skip = 0; next }
          re != "" && $0 ~ "^ *(" re "):" { if ($0 !~ /"$/ || $0 ~ /: "$/) skip = 1; next } { print }' |
        sed "s|$(dirname "$1")/||g"
    }
    for fa in "$a"/*.exr; do
      name=$(basename "$fa"); fb="$b/$name"; count=$((count + 1))
      if [ ! -e "$fb" ]; then echo "MISSING: $name"; fails=$((fails + 1)); continue; fi
      if ! diff <(header "$fa") <(header "$fb") >/dev/null; then
        echo "HEADER DIFFERS: $name"; diff <(header "$fa") <(header "$fb") | head -6 || true; fails=$((fails + 1)); continue
      fi
      sel=()
      # grep reads all of oiiotool's output: with -q it stops early, and pipefail would fail the test.
      if oiiotool --info -v "$fa" | grep 'cost_ns' >/dev/null; then  # single-part files only carry cost
        chans=$(oiiotool --info -v "$fa" | sed -n 's/^ *channel list: //p' | head -1 | tr -d ' ' | sed 's/([a-z0-9]*)//g' | tr ',' '\n' | grep -v '^cost_ns\.X$' | paste -sd,)
        sel=(--ch "$chans")
      fi
      if ! oiiotool -a "$fa" "${sel[@]}" "$fb" "${sel[@]}" --fail 0 --failpercent 0 --diff >/dev/null 2>&1; then
        echo "PIXELS DIFFER: $name"; fails=$((fails + 1))
      fi
    done
    for fb in "$b"/*.exr; do [ -e "$a/$(basename "$fb")" ] || { echo "EXTRA: $(basename "$fb")"; fails=$((fails + 1)); }; done
    for fa in "$a"/*.txt; do
      [ -e "$fa" ] || continue
      count=$((count + 1))
      if ! cmp -s "$fa" "$b/$(basename "$fa")"; then echo "TEXT DIFFERS: $(basename "$fa")"; fails=$((fails + 1)); fi
    done
    echo "compared $count files: $((count - fails)) identical, $fails different"
    [ "$fails" -eq 0 ]
    ;;
  *)
    echo "usage: scripts/render_regression.sh render PENUMBRA OUTDIR | compare DIR_A DIR_B" >&2; exit 2 ;;
esac
