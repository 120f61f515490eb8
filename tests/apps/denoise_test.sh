#!/usr/bin/env bash
# `penumbra render --denoise` and `penumbra denoise` end to end on the shipped default scene:
# - a whole frame rendered with --denoise is byte-identical (cmp, --reproducible) to its three
#   --tile stripes rendered with --denoise and merged (the merge denoises the frame), also with
#   --multipart;
# - `penumbra denoise` of a render made with --aov halves gives the same pixels (idiff: only the
#   settings attribute differs) as the render with --denoise;
# - --denoise-main noisy keeps R, G, B, A of the noisy render and adds denoised.*; the default
#   adds noisy.* equal to the noisy render's beauty; the display image shows the main layer;
# - a job file asks for it ("denoise": true), tiled and whole;
# - bad input exits 2 naming the file and the missing layer, and writes nothing: an EXR
#   without the halves, a denoised EXR, the output over the input, a PNG output, an infinity.
# Usage: denoise_test.sh PENUMBRA_BINARY SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
source "$(dirname "$0")/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
for tool in idiff oiiotool; do
  command -v "$tool" >/dev/null || { echo "PENUMBRA_SKIP: $tool is not installed"; exit 0; }
done
scene="$src/scenes/default.gltf"
common=(--integrator path --spp 8 --width 96 --height 64 --accel bvh --reproducible -q)

# 1. Whole frame = merged stripes, byte for byte (single- and multi-part).
for layout in single multi; do
  extra=(); [ "$layout" = multi ] && extra=(--multipart)
  "$bin" render "$scene" -o "$work/whole-$layout.exr" --denoise "${common[@]}" "${extra[@]}" >/dev/null ||
    fail "render --denoise ($layout)"
  for i in 0 1 2; do
    "$bin" render "$scene" -o "$work/stripe-$layout-$i.exr" --tile "$i/3" --denoise "${common[@]}" "${extra[@]}" \
      --no-png >/dev/null || fail "stripe $i ($layout)"
  done
  "$bin" merge "$work"/stripe-$layout-{0,1,2}.exr -o "$work/merged-$layout.exr" >/dev/null || fail "merge ($layout)"
  cmp -s "$work/whole-$layout.exr" "$work/merged-$layout.exr" ||
    fail "$layout: the merged, denoised stripes differ from the whole frame denoised"
  [ -z "$(ls -A "$work" | grep -E '\.tmp|noisy-')" ] || fail "temporaries left: $(ls -A "$work")"
done
oiiotool --info -v "$work/whole-single.exr" | grep -q 'penumbra:denoiser: "nfor"' || fail "no penumbra:denoiser attribute"
oiiotool --info -v "$work/stripe-single-0.exr" | grep -q 'penumbra:denoiser' && fail "a stripe was denoised before the merge"

# 2. `penumbra denoise` on a noisy render with the halves = render --denoise (pixels).
"$bin" render "$scene" -o "$work/halves.exr" --aov halves "${common[@]}" >/dev/null || fail "render --aov halves"
expect 0 "$work/later.exr" -- "$bin" denoise "$work/halves.exr" -o "$work/later.exr" --threads 1
idiff -q "$work/later.exr" "$work/whole-single.exr" >/dev/null || fail "denoise later differs from render --denoise"
# The noisy beauty kept, equal to the render without denoising.
oiiotool "$work/later.exr" --ch noisy.R,noisy.G,noisy.B,noisy.A --chnames R,G,B,A -o "$work/kept.exr"
oiiotool "$work/halves.exr" --ch R,G,B,A -o "$work/beauty.exr"
idiff -q "$work/kept.exr" "$work/beauty.exr" >/dev/null || fail "noisy.* is not the noisy beauty"
# The display image shows the denoised beauty: it differs from the noisy render's.
cmp -s "$work/whole-single.png" "$work/halves.png" && fail "the display image of --denoise is the noisy one"

# 3. --denoise-main noisy: R, G, B, A stay the noisy render's, denoised.* is the denoised beauty.
"$bin" render "$scene" -o "$work/noisy-main.exr" --denoise --denoise-main noisy "${common[@]}" >/dev/null ||
  fail "render --denoise-main noisy"
oiiotool "$work/noisy-main.exr" --ch R,G,B,A -o "$work/noisy-main-beauty.exr"
idiff -q "$work/noisy-main-beauty.exr" "$work/beauty.exr" >/dev/null || fail "--denoise-main noisy changed R, G, B, A"
oiiotool "$work/noisy-main.exr" --ch denoised.R,denoised.G,denoised.B --chnames R,G,B -o "$work/d1.exr"
oiiotool "$work/whole-single.exr" --ch R,G,B -o "$work/d2.exr"
idiff -q "$work/d1.exr" "$work/d2.exr" >/dev/null || fail "denoised.* differs from the denoised main layer"
cmp -s "$work/noisy-main.png" "$work/halves.png" || fail "--denoise-main noisy: the display image is not the noisy beauty"

# 4. A job file: one tiled shot, one whole.
cat >"$work/job.json" <<JSON
{"version": 1,
 "defaults": {"integrator": "path", "spp": 8, "width": 96, "height": 64, "accel": "bvh", "denoise": true},
 "shots": [{"name": "tiled", "scene": "$scene", "output": "job/tiled.exr", "tiles": 2},
           {"name": "whole", "scene": "$scene", "output": "job/whole.exr", "settings": {"denoise-main": "noisy"}}]}
JSON
"$bin" batch "$work/job.json" -q >/dev/null || fail "batch with denoise"
for f in tiled whole; do
  oiiotool --info -v "$work/job/$f.exr" 2>/dev/null | grep -q 'penumbra:denoiser' || fail "job: $f.exr is not denoised"
done
idiff -q "$work/job/tiled.exr" "$work/whole-single.exr" >/dev/null || fail "job: the tiled shot differs from render --denoise"

# 5. Bad input: exit 2, the file and what is missing named, nothing written.
mkdir -p "$work/bad"
"$bin" render "$scene" -o "$work/plain.exr" "${common[@]}" >/dev/null
expect 2 "plain.exr: lacks the layers the denoiser needs: even, even_N, even_Z, even_albedo, odd" -- \
  "$bin" denoise "$work/plain.exr" -o "$work/bad/out.exr"
expect 2 "already denoised" -- "$bin" denoise "$work/whole-single.exr" -o "$work/bad/out.exr"
expect 2 "would overwrite input" -- "$bin" denoise "$work/halves.exr" -o "$work/halves.exr"
expect 2 "must be an .exr" -- "$bin" denoise "$work/halves.exr" -o "$work/bad/out.png"
expect 2 "no-such.exr" -- "$bin" denoise "$work/no-such.exr" -o "$work/bad/out.exr"
oiiotool "$work/halves.exr" --ch "R,G,B,A,even.R,even.G,even.B" -o "$work/few.exr"
expect 2 "few.exr: lacks the layers the denoiser needs: even_N, even_Z, even_albedo, odd, odd_N" -- \
  "$bin" denoise "$work/few.exr" -o "$work/bad/out.exr"
# An infinity in the odd half's green: odd.G times 1e60 (every other channel times 1).
channels=$(oiiotool --info -v "$work/halves.exr" | sed -n 's/^ *channel list: //p' | sed 's/ ([a-z]*)//g; s/,//g')
factors=$(for c in $channels; do [ "$c" = odd.G ] && printf '1e30,' || printf '1,'; done)
oiiotool "$work/halves.exr" --mulc "${factors%,}" --mulc "${factors%,}" -o "$work/with-inf.exr" 2>/dev/null
if oiiotool --info "$work/with-inf.exr" >/dev/null 2>&1 && [ -n "$channels" ]; then
  expect 2 "with-inf.exr: odd.G: holds (inf|nan) at pixel" -- "$bin" denoise "$work/with-inf.exr" -o "$work/bad/out.exr"
else
  fail "could not make the file with an infinity"
fi
expect 2 "denoise needs integrator 'path'" -- "$bin" render "$scene" -o "$work/bad/w.exr" --denoise --spp 2 -q
expect 2 "denoise needs spp >= 2" -- "$bin" render "$scene" -o "$work/bad/w.exr" --integrator path --denoise --spp 1 -q
expect 2 "denoise_main needs denoise" -- "$bin" render "$scene" -o "$work/bad/w.exr" --integrator path --denoise-main noisy -q
expect 2 "'halves' needs integrator 'path'|halves needs --integrator path" -- "$bin" render "$scene" -o "$work/bad/w.exr" --aov halves -q
[ -z "$(ls -A "$work/bad")" ] || fail "a refused run wrote $(ls -A "$work/bad")"

echo "denoise: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
