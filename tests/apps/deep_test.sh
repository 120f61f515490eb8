#!/usr/bin/env bash
# Deep EXR output end to end through `penumbra` and real clients (OpenImageIO's oiiotool, OpenEXR's
# exrheader):
# - OpenImageIO's flatten of the deep EXR equals the flat EXR's RGBA within 1e-3 on the shipped
#   scenes and on corpus models with Blend materials, with Whitted and the path tracer;
# - the holdout oracle: scenes A and B rendered apart (Whitted without shadows or mirrors, one
#   sample per pixel), deep-merged and flattened by oiiotool, equal a render of A and B together
#   within 1e-3 in colour and coverage; with shadows the sets darken each other and the oracle
#   does not hold (the check can fail); at 16 samples only pixels where both sets' edges meet
#   differ (deep samples carry no sub-pixel position);
# - OpenEXR's own reader sees a deep scanline file with the documented channels;
# - deep stripes (`--tile`) merged by `penumbra merge`, and by a tiled job, equal the whole frame
#   byte for byte; `--frames` writes a deep EXR per frame;
# - bad requests exit 2 naming the flag, writing nothing.
# Usage: deep_test.sh PENUMBRA SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
corpus="${PENUMBRA_CORPUS:-$src/../shared/corpus}"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
. "$src/tests/apps/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
pass() { passes=$((passes + 1)); }
for tool in oiiotool exrheader; do
  command -v "$tool" >/dev/null || { echo "PENUMBRA_SKIP: $tool is not installed"; exit 0; }
done

# flat_equals DEEP FLAT WHAT [PERCENT]: oiiotool's flatten of DEEP matches FLAT's RGBA within 1e-3
# (at all pixels, or all but PERCENT of them).
flat_equals() {
  local deep="$1" flat="$2" what="$3" percent="${4:-0}"
  oiiotool "$deep" --flatten -o "$work/flattened.exr" >/dev/null 2>"$work/oiio.err" || { fail "$what: oiiotool --flatten"; return; }
  if oiiotool "$work/flattened.exr" --ch R,G,B,A "$flat" --ch R,G,B,A --fail 1e-3 --failpercent "$percent" --diff \
      >"$work/diff.txt" 2>&1; then
    pass
  else
    fail "$what: flattened deep differs from the flat EXR"; sed 's/^/  | /' "$work/diff.txt" | tail -4
  fi
}

# 1. Flatten == flat, shipped scenes and corpus Blend models, both integrators.
models=("$src/scenes/default.gltf" "$src/scenes/spheres.gltf" "$src/scenes/csg.gltf" "$src/scenes/procedural.gltf")
for m in AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb LightsPunctualLamp/glTF/LightsPunctualLamp.gltf; do
  if [ -f "$corpus/valid/$m" ]; then models+=("$corpus/valid/$m"); else echo "PENUMBRA_SKIP: corpus model $m (no corpus)"; fi
done
for model in "${models[@]}"; do
  name=$(basename "${model%.*}")
  for integrator in whitted path; do
    spp=4; [ "$integrator" = path ] && spp=16
    if "$bin" render "$model" -o "$work/$name.$integrator.exr" --deep "$work/$name.$integrator.deep.exr" \
        --integrator "$integrator" --spp "$spp" --width 96 --float --no-png -q >/dev/null 2>"$work/err"; then
      flat_equals "$work/$name.$integrator.deep.exr" "$work/$name.$integrator.exr" "$name ($integrator)"
    else
      fail "render $name ($integrator) --deep"; head -3 "$work/err"
    fi
  done
done
# An environment seen past the surfaces is a sample of alpha 0 behind them.
"$bin" render "$src/scenes/spheres.gltf" -o "$work/env.exr" --deep "$work/env.deep.exr" --integrator path --spp 8 \
  --env 0.2,0.3,0.5 --width 96 --float --no-png -q >/dev/null || fail "render with --env"
flat_equals "$work/env.deep.exr" "$work/env.exr" "spheres with an environment"

# 2. OpenEXR's reader: a deep scanline file with the documented channels, samples in 32-bit float.
exrheader "$work/default.whitted.deep.exr" >"$work/header.txt" 2>&1 || fail "exrheader cannot read the deep EXR"
grep -q 'type (type string): "deepscanline"' "$work/header.txt" && pass || fail "exrheader: not deepscanline"
grep -q 'flags 0x800' "$work/header.txt" && pass || fail "exrheader: no non-image (deep) flag"
for ch in R G B A Z ZBack id N.X N.Y N.Z albedo.R albedo.G albedo.B; do
  grep -qE "^    $ch, 32-bit floating-point" "$work/header.txt" && pass || fail "exrheader: no channel $ch"
done
grep -q 'penumbra:settings' "$work/header.txt" && pass || fail "the deep EXR lacks the render identity"
oiiotool --stats "$work/default.whitted.deep.exr" >"$work/stats.txt" 2>&1
grep -q "Pixels with deep samples" "$work/stats.txt" && pass || fail "oiiotool --stats reads no deep samples"

# 3. The holdout oracle.
python3 "$src/tests/apps/deep_scenes.py" "$work" || fail "deep_scenes.py"
holdout() {  # holdout TAG FLAGS...: renders a, b, ab with FLAGS; leaves $work/TAG.{a,b,ab}*.exr
  local tag="$1"; shift
  for s in a b ab; do
    "$bin" render "$work/$s.gltf" -o "$work/$tag.$s.exr" --deep "$work/$tag.$s.deep.exr" --width 150 --float \
      --no-png -q "$@" >/dev/null 2>"$work/err" || { fail "holdout render $tag $s"; head -3 "$work/err"; }
  done
  oiiotool "$work/$tag.a.deep.exr" "$work/$tag.b.deep.exr" --deepmerge -o "$work/$tag.merged.exr" >/dev/null 2>&1 \
    || fail "oiiotool --deepmerge ($tag)"
}
holdout exact --integrator whitted --spp 1 --shadows off --max-depth 0
flat_equals "$work/exact.merged.exr" "$work/exact.ab.exr" "holdout: A and B merged deep vs A and B rendered together"
# The toolbox: its merge and flatten agree with oiiotool's, and A held out by B plus B held out by
# A is the two rendered together.
expect 0 "merged_p.exr" -- "$bin" deep merge "$work/exact.a.deep.exr" "$work/exact.b.deep.exr" -o "$work/merged_p.exr"
flat_equals "$work/merged_p.exr" "$work/exact.ab.exr" "holdout: penumbra deep merge vs A and B rendered together"
expect 0 "flat_p.exr" -- "$bin" deep flatten "$work/exact.merged.exr" -o "$work/flat_p.exr"
oiiotool "$work/exact.merged.exr" --flatten -o "$work/flat_o.exr" >/dev/null 2>&1
oiiotool "$work/flat_p.exr" --ch R,G,B,A "$work/flat_o.exr" --ch R,G,B,A --fail 1e-5 --diff >/dev/null 2>&1 \
  && pass || fail "penumbra deep flatten differs from oiiotool --flatten"
expect 0 "a_held.exr" -- "$bin" deep holdout "$work/exact.a.deep.exr" --by "$work/exact.b.deep.exr" -o "$work/a_held.exr"
expect 0 "b_held.exr" -- "$bin" deep holdout "$work/exact.b.deep.exr" --by "$work/exact.a.deep.exr" -o "$work/b_held.exr"
oiiotool "$work/a_held.exr" "$work/b_held.exr" --add -o "$work/held_sum.exr" >/dev/null 2>&1 || fail "oiiotool --add"
if oiiotool "$work/held_sum.exr" --ch R,G,B,A "$work/exact.ab.exr" --ch R,G,B,A --fail 1e-3 --diff >"$work/diff.txt" 2>&1; then
  pass
else
  fail "A held out by B plus B held out by A differs from A and B rendered together"; tail -3 "$work/diff.txt"
fi
# A alone is not what A held out by B is: B hides parts of it.
oiiotool "$work/a_held.exr" --ch R,G,B,A "$work/exact.a.exr" --ch R,G,B,A --fail 1e-2 --diff >/dev/null 2>&1 \
  && fail "holding A out by B changed nothing" || pass
# The same with shadows: the sets shade each other, which no deep merge can know.
holdout shadowed --integrator whitted --spp 1 --max-depth 0
oiiotool "$work/shadowed.merged.exr" --flatten -o "$work/shadowed.flat.exr" >/dev/null 2>&1
if oiiotool "$work/shadowed.flat.exr" --ch R,G,B,A "$work/shadowed.ab.exr" --ch R,G,B,A --fail 1e-2 --diff >/dev/null 2>&1; then
  fail "holdout with shadows: the sets should darken each other (the oracle's scenes do not interact)"
else
  pass
fi
# 16 samples per pixel: everything but pixels where both sets' edges meet (at most 2%).
holdout smooth --integrator whitted --spp 16 --shadows off --max-depth 0
flat_equals "$work/smooth.merged.exr" "$work/smooth.ab.exr" "holdout at 16 spp" 2

# 4. Stripes merged byte for byte (Whitted and the path tracer), by `merge` and by a tiled job.
for integrator in whitted path; do
  common=(--integrator "$integrator" --spp 8 --width 80 --no-png -q --reproducible)
  "$bin" render "$src/scenes/default.gltf" -o "$work/whole.exr" --deep "$work/whole.deep.exr" "${common[@]}" >/dev/null \
    || fail "whole frame ($integrator)"
  parts=()
  for t in 0 1 2; do
    "$bin" render "$src/scenes/default.gltf" -o "$work/part$t.exr" --deep "$work/part$t.deep.exr" --tile "$t/3" \
      "${common[@]}" >/dev/null || fail "stripe $t ($integrator)"
    parts+=("$work/part$t.deep.exr")
  done
  expect 0 "merged.deep.exr" -- "$bin" merge "${parts[@]}" -o "$work/merged.deep.exr"
  cmp -s "$work/merged.deep.exr" "$work/whole.deep.exr" && pass || fail "merged deep stripes differ from the whole frame ($integrator)"
done
expect 2 "is not a deep image" -- "$bin" merge "$work/part0.deep.exr" "$work/part1.exr" -o "$work/mixed.exr"
[ -e "$work/mixed.exr" ] && fail "a refused merge left its output"

cat >"$work/job.json" <<JSON
{"version": 1,
 "defaults": {"integrator": "path", "spp": 4, "width": 64},
 "shots": [
  {"name": "tiled", "scene": "$src/scenes/spheres.gltf", "output": "shots/tiled.exr", "deep": "shots/tiled_deep.exr", "tiles": 3},
  {"name": "whole", "scene": "$src/scenes/spheres.gltf", "output": "shots/whole.exr", "deep": "shots/whole_deep.exr"}]}
JSON
expect 0 "" -- "$bin" batch "$work/job.json" -q
cmp -s "$work/shots/tiled_deep.exr" "$work/shots/whole_deep.exr" && pass || fail "a tiled job's deep frame differs from the whole frame's"
ls "$work/shots" | grep -q "\.tile-" && fail "the job left its deep stripes: $(ls "$work/shots")"
printf '{"version": 1, "shots": [{"name": "x", "scene": "%s", "output": "o.exr", "deep": 3}]}' \
  "$src/scenes/spheres.gltf" >"$work/bad_job.json"
expect 2 'deep.*must be a string' -- "$bin" batch "$work/bad_job.json" -q

# A frame whose deep EXR is missing is not complete: --skip-existing and a job render it again.
rm "$work/shots/whole_deep.exr"
expect 0 "" -- "$bin" batch "$work/job.json" -q --skip-existing
cmp -s "$work/shots/tiled_deep.exr" "$work/shots/whole_deep.exr" && pass || fail "a job did not render a missing deep EXR again"
rm "$work/shots/tiled_deep.exr"
expect 0 "" -- "$bin" batch "$work/job.json" -q --skip-existing
[ -e "$work/shots/tiled_deep.exr" ] && pass || fail "a tiled job did not render a missing deep frame again"

# An interrupted path render writes its flat image and no deep one, keeping its resume state even
# after its last pass; --resume completes both, the deep image equal to an uninterrupted render's.
ra=(render "$src/scenes/default.gltf" --integrator path --width 16 --height 9 --spp 2048 --no-png --reproducible)
"$bin" "${ra[@]}" -o "$work/whole-r.exr" --deep "$work/whole-r.deep.exr" -q >/dev/null || fail "uninterrupted render"
"$bin" "${ra[@]}" -o "$work/int.exr" --deep "$work/int.deep.exr" >"$work/out" 2>"$work/err" &
pid=$!
for _ in $(seq 200); do grep -q "^render" "$work/err" 2>/dev/null && break; sleep 0.05; done
kill -INT $pid 2>/dev/null
wait $pid; rc=$?
if [ -e "$work/int.exr.resume" ]; then  # interrupted in time (a very fast machine may finish first)
  [ "$rc" -eq 130 ] && [ -e "$work/int.exr" ] && [ ! -e "$work/int.deep.exr" ] && pass \
    || fail "interrupted --deep render: exit $rc, deep image $(ls "$work"/int.deep.exr 2>&1)"
  expect 0 "int.deep.exr" -- "$bin" "${ra[@]}" -o "$work/int.exr" --deep "$work/int.deep.exr" --resume -q
  cmp -s "$work/int.deep.exr" "$work/whole-r.deep.exr" && pass || fail "the resumed deep image differs from the whole render's"
else
  echo "note: the render finished before the interrupt; resume not exercised"
fi

# 5. Frames: one deep EXR per frame.
expect 0 "anim_deep.0002.exr" -- "$bin" render "$src/scenes/motion.gltf" -o "$work/anim.####.exr" \
  --deep "$work/anim_deep.####.exr" --frames 1-2 --width 48 --spp 2 --no-png -q
for f in 0001 0002; do
  exrheader "$work/anim_deep.$f.exr" 2>/dev/null | grep -q deepscanline && pass || fail "frame $f has no deep EXR"
done
expect 2 "needs a run of '#' in --deep" -- "$bin" render "$src/scenes/motion.gltf" -o "$work/anim.####.exr" \
  --deep "$work/anim_deep.exr" --frames 1-2 --width 48 --spp 2 --no-png -q

# 6. Bad requests: exit 2, nothing written.
expect 2 "covers another window" -- "$bin" deep merge "$work/exact.a.deep.exr" "$work/part0.deep.exr" -o "$work/bad.exr"
expect 2 "is not a deep OpenEXR image" -- "$bin" deep flatten "$work/exact.a.exr" -o "$work/bad.exr"
expect 2 "the output must be an .exr" -- "$bin" deep flatten "$work/exact.a.deep.exr" -o "$work/bad.png"
expect 2 "input 1" -- "$bin" deep flatten "$work/exact.a.deep.exr" -o "$work/exact.a.deep.exr"
expect 2 "over the .* limit" -- "$bin" deep merge "$work/exact.a.deep.exr" "$work/exact.b.deep.exr" -o "$work/bad.exr" --max-memory 1K
expect 2 "penumbra: error:" -- "$bin" deep holdout "$work/exact.a.deep.exr" -o "$work/bad.exr"
printf 'not an exr' >"$work/junk.exr"
expect 2 "junk.exr" -- "$bin" deep flatten "$work/junk.exr" -o "$work/bad.exr"
rm -f "$work/bad.exr" "$work/bad.deep.exr"
expect 2 "deep needs integrator .whitted. or .path." -- "$bin" render "$src/scenes/default.gltf" -o "$work/bad.exr" \
  --deep "$work/bad.deep.exr" --integrator raster --width 32
expect 2 "--deep .*must be an .exr" -- "$bin" render "$src/scenes/default.gltf" -o "$work/bad.exr" \
  --deep "$work/bad.png" --width 32
expect 2 "--deep" -- "$bin" render "$src/scenes/default.gltf" -o "$work/bad.exr" --deep "$work/bad.exr" --width 32
expect 2 "deep_merge_tolerance must be in" -- "$bin" render "$src/scenes/default.gltf" -o "$work/bad.exr" \
  --deep "$work/bad.deep.exr" --deep-merge-tolerance 2 --width 32
expect 2 "deep_merge_tolerance needs deep" -- "$bin" render "$src/scenes/default.gltf" -o "$work/bad.exr" \
  --deep-merge-tolerance 0.1 --width 32
expect 2 "deep image needs more than .* --max-memory" -- "$bin" render "$src/scenes/default.gltf" \
  -o "$work/bad.exr" --deep "$work/bad.deep.exr" --width 160 --spp 64 --deep-merge-tolerance 0 --max-memory 40M --no-png
for f in bad.exr bad.deep.exr bad.png; do [ -e "$work/$f" ] && fail "a refused render left $f"; done

echo "deep: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
