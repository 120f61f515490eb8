#!/usr/bin/env bash
# Depth of field through Blender Cycles on the same camera: a corpus model (the Avocado, 6 cm
# tall, seen from above at 12 cm through a 50 mm lens, so that its top is in focus and its base
# and sides blur by several pixels) rendered by Penumbra with --fstop/--focus-distance and by
# Cycles with the DOF settings made from the same numbers. What is compared is alpha, the
# coverage of the camera rays: it depends on the geometry, the camera, the lens and the pixel
# filter only, not on the two renderers' materials and lights.
#
# The mapping (Blender 3.4's Cycles: blender/camera.cpp, kernel/camera/camera.h,
# kernel/sample/mapping.h), each the same quantity on both sides:
# - the camera: Penumbra --look-at EYE TARGET (up +Y) --focal-length 50 --sensor 36, and a Blender
#   camera at the same place (glTF's (x, y, z) is Blender's (x, -z, y)) tracked at the target,
#   lens 50, sensor_width 36, sensor_fit AUTO: the sensor spans the image's larger side in both,
#   here its height (a portrait image);
# - the aperture: Cycles' radius is lens_mm * 1e-3 / (2 * aperture_fstop) scene units, Penumbra's
#   --fstop N gives focal_mm * 1e-3 / (2 N); glTF and Blender's default unit scale are metres;
# - the focus: Cycles meets the plane in focus at D * focus_distance / D.z for the camera-space
#   ray D, a depth along the view axis, as --focus-distance;
# - the anamorphic ratio: Cycles multiplies the aperture sample's x by 1 / aperture_ratio,
#   Penumbra divides it by --aperture-ratio (both: A times as tall as wide);
# - the blades: both put the polygon's corners at the rotation + 180/N + k 360/N degrees, so
#   Cycles' aperture_rotation is --aperture-rotation;
# - the pixel filter: a 1-pixel box in both, so that coverage differs only through the lens.
#
# Tolerance. Both renderers are unbiased estimators of the same coverage, so the RMS of
# P - C is the square root of the sum of their noise variances. Each renderer's variance is
# measured from two of its renders with different seeds (RMS(P1 - P2)^2 = 2 var_P), which gives
# the RMS difference expected of P against C if they agree: noise = sqrt((RMS(P1 - P2)^2 +
# RMS(C1 - C2)^2) / 2), from the round aperture (the three-bladed pair, blurred as much, is held
# to the same bound). A match must be within 1.3 x noise: room for the spread of the measured
# RMS values themselves (thousands of blurred edge pixels: a few per cent), while a systematic
# difference as large as 0.83 x the noise fails (so does a three-bladed aperture turned 60
# degrees from Cycles': about 1.9 x noise). The lens settings that are
# wrong on purpose (a pinhole, twice the f-number, a round aperture for a three-bladed one, the
# anamorphic ratio inverted) must miss by more than twice that bound, so the check tells a wrong
# aperture from noise.
#
# Usage: blender_dof_test.sh PENUMBRA SRC WORK_DIR   (corpus from $PENUMBRA_CORPUS, else
# $PENUMBRA_CORPUS_DEFAULT, else SRC/../shared/corpus). Skipped (PENUMBRA_SKIP) without blender,
# oiiotool or the corpus model.
set -u
penumbra="$1"; src="$2"; work="$3"
corpus="${PENUMBRA_CORPUS:-${PENUMBRA_CORPUS_DEFAULT:-$src/../shared/corpus}}"
model=$corpus/valid/Avocado/glTF/Avocado.gltf
cycles=$src/benchmarks/cycles/render_cycles.py
command -v blender >/dev/null || { echo "PENUMBRA_SKIP: blender is not installed"; exit 0; }
command -v oiiotool >/dev/null || { echo "PENUMBRA_SKIP: oiiotool is not installed"; exit 0; }
[ -f "$model" ] || { echo "PENUMBRA_SKIP: no corpus model at $model (set PENUMBRA_CORPUS)"; exit 0; }
rm -rf "$work"; mkdir -p "$work"

W=128 H=192 SPP=64
eye=0.0388,0.1071,0.0833 target=0,0.03,0   # 12 cm from the middle, 40 degrees above it
focus=0.1 fstop=1.4                          # the top in focus; 50 mm at f/1.4: radius 17.9 mm
fails=0

pen() {  # OUT [flags...]
  local out=$1; shift
  "$penumbra" render "$model" -o "$work/$out.exr" --no-png --float --integrator path --env 0.8 --energy-compensation off \
    --max-depth 0 --spp $SPP --width $W --height $H --threads 2 --filter box --filter-width 1 \
    --look-at $eye $target --focal-length 50 --sensor 36 "$@" >"$work/$out.log" 2>&1 ||
    { echo "FAIL: penumbra render $out"; tail -5 "$work/$out.log"; exit 1; }
}
cyc() {  # OUT [key=value...]
  local out=$1; shift
  blender -b --factory-startup --python-exit-code 1 -P "$cycles" -- "$model" "$work/$out.exr" $W $H $SPP 2 0.8 \
    look_at=$eye:$target lens=50 sensor=36 transparent=1 filter=box filter_width=1 bounces=0 "$@" \
    >"$work/$out.log" 2>&1 && [ -f "$work/$out.exr" ] ||
    { echo "FAIL: cycles render $out"; tail -20 "$work/$out.log"; exit 1; }
}
rms() {  # RMS difference of the alpha channels
  oiiotool "$work/$1.exr" --ch A "$work/$2.exr" --ch A --diff 2>&1 | awk '/RMS error/ {print $4; exit}'
}
within() {  # WHAT VALUE BOUND: VALUE <= BOUND
  if awk -v v="$2" -v b="$3" 'BEGIN {exit !(v != "" && v <= b)}'; then echo "ok: $1: $2 <= $3"
  else echo "FAIL: $1: $2 > $3"; fails=$((fails + 1)); fi
}
beyond() {  # WHAT VALUE BOUND: VALUE > BOUND
  if awk -v v="$2" -v b="$3" 'BEGIN {exit !(v != "" && v > b)}'; then echo "ok: $1: $2 > $3"
  else echo "FAIL: $1: $2 <= $3 (not told apart from the noise)"; fails=$((fails + 1)); fi
}

t0=$(date +%s)
# A round aperture.
pen p1 --fstop $fstop --focus-distance $focus --seed 1
pen p2 --fstop $fstop --focus-distance $focus --seed 2
pen pinhole
pen f2x --fstop "$(awk -v n=$fstop 'BEGIN {print 2 * n}')" --focus-distance $focus
cyc c1 fstop=$fstop focus=$focus seed=1
cyc c2 fstop=$fstop focus=$focus seed=2
# Three blades turned by 15 degrees, twice as tall as wide.
pen tri --fstop $fstop --focus-distance $focus --aperture-blades 3 --aperture-rotation 15 --aperture-ratio 2 --seed 1
pen triwide --fstop $fstop --focus-distance $focus --aperture-blades 3 --aperture-rotation 15 --aperture-ratio 0.5
cyc ctri fstop=$fstop focus=$focus blades=3 rotation=15 ratio=2 seed=2

noise=$(awk -v a="$(rms p1 p2)" -v b="$(rms c1 c2)" 'BEGIN {printf "%.6g", sqrt((a * a + b * b) / 2)}')
bound=$(awk -v n="$noise" 'BEGIN {printf "%.6g", 1.3 * n}')
miss=$(awk -v b="$bound" 'BEGIN {printf "%.6g", 2 * b}')
echo "alpha noise (RMS expected of Penumbra - Cycles if they agree): $noise; bound $bound; a wrong lens must exceed $miss"
within "f/$fstop Penumbra seed 1 vs Cycles seed 1" "$(rms p1 c1)" "$bound"
within "f/$fstop Penumbra seed 2 vs Cycles seed 2" "$(rms p2 c2)" "$bound"
within "3 blades, ratio 2: Penumbra vs Cycles" "$(rms tri ctri)" "$bound"
beyond "Penumbra pinhole vs Cycles f/$fstop" "$(rms pinhole c1)" "$miss"
beyond "Penumbra at twice the f-number vs Cycles f/$fstop" "$(rms f2x c1)" "$miss"
beyond "Penumbra 3 blades vs Cycles round" "$(rms tri c1)" "$miss"
beyond "Penumbra 3 blades, ratio 1/2 vs Cycles ratio 2" "$(rms triwide ctri)" "$miss"
echo "blender dof: $fails failures ($(($(date +%s) - t0)) s)"
[ "$fails" -eq 0 ]
