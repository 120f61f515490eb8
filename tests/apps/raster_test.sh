#!/usr/bin/env bash
# `penumbra render --integrator raster` end to end: the EXR with every data AOV and the display
# image, the AOVs' ids agreeing with the ray tracer's away from silhouettes (compared by
# oiiotool), shadows by rays, maps or none, --debug-pixel equal to the full render's pixel,
# farm stripes merging into the whole frame byte for byte, --frames, and the refusals of raster
# options given to the other integrators.
# Usage: raster_test.sh PENUMBRA SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
source "$src/tests/apps/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
scene="$src/scenes/default.gltf"
small=(--width 96 --height 54 --spp 1 -q)

# The EXR holds the beauty and every data AOV; the PNG is written.
expect 0 "raster.exr" -- "$bin" render "$scene" -o "$work/raster.exr" --integrator raster "${small[@]}" --aov all
expect 0 "penumbra:integrator: \"raster\"" -- oiiotool --info -v "$work/raster.exr"
for ch in albedo.R N.X P.X Z UV.U object_id material_id; do
  expect 0 "$ch" -- oiiotool --info -v "$work/raster.exr"
done
[ -s "$work/raster.png" ] && passes=$((passes + 1)) || fail "no raster.png"

# The same ids as the ray tracer on most pixels (they differ only along silhouettes).
"$bin" render "$scene" -o "$work/traced.exr" "${small[@]}" --aov id --no-png >/dev/null
"$bin" render "$scene" -o "$work/rid.exr" --integrator raster "${small[@]}" --aov id --no-png >/dev/null
differ=$(oiiotool "$work/traced.exr" --ch object_id "$work/rid.exr" --ch object_id --absdiff --mulc 1000 --clamp:min=0:max=1 \
         --printstats 2>/dev/null | sed -n 's/.*Avg: *\([0-9.e+-]*\).*/\1/p' | head -1)
if [ -n "$differ" ] && python3 -c "import sys; sys.exit(0 if float('$differ') < 0.05 else 1)"; then
  passes=$((passes + 1))
else
  fail "raster and traced object ids differ on a share of '$differ' of the pixels"
fi

# Shadows: rays, maps and none all render; none is the brightest.
for mode in ray map none; do
  expect 0 "s_$mode.exr" -- "$bin" render "$scene" -o "$work/s_$mode.exr" --integrator raster "${small[@]}" \
    --raster-shadows "$mode" --no-png
done
expect 0 "s_map.exr" -- "$bin" render "$scene" -o "$work/s_map.exr" --integrator raster "${small[@]}" \
  --raster-shadows map --shadow-map-size 512 --no-png
mean() { oiiotool "$1" --ch R --printstats 2>/dev/null | sed -n 's/.*Avg: *\([0-9.e+-]*\).*/\1/p' | head -1; }
if python3 -c "import sys; sys.exit(0 if float('$(mean "$work/s_none.exr")') > float('$(mean "$work/s_ray.exr")') else 1)"; then
  passes=$((passes + 1))
else
  fail "unshadowed raster image not brighter than the shadowed one"
fi

# --debug-pixel prints the full render's pixel.
"$bin" render "$scene" -o "$work/dbg.exr" --integrator raster --width 96 --height 54 --spp 4 -q --no-png --float >/dev/null
want=$(oiiotool "$work/dbg.exr" --ch R --cut 1x1+40+30 --printstats 2>/dev/null | sed -n 's/.*Avg: *\([0-9.e+-]*\).*/\1/p' | head -1)
"$bin" render "$scene" -o "$work/dbg2.exr" --integrator raster --width 96 --height 54 --spp 4 --debug-pixel 40,30 >"$work/out" 2>/dev/null
got=$(sed -n 's/.*R \([0-9.e+-]*\) .*/\1/p' "$work/out")
if python3 -c "import sys; sys.exit(0 if abs(float('$got') - float('$want')) <= 1e-5 * max(1, abs(float('$want'))) else 1)"; then
  passes=$((passes + 1))
else
  fail "--debug-pixel 40,30: R $got, the full render has $want"
fi

# Farm stripes merge into the whole frame, byte for byte.
"$bin" render "$scene" -o "$work/whole.exr" --integrator raster "${small[@]}" --aov all --reproducible --no-png >/dev/null
parts=()
for i in 0 1 2; do
  "$bin" render "$scene" -o "$work/part$i.exr" --integrator raster "${small[@]}" --aov all --reproducible \
    --tile $i/3 --no-png >/dev/null
  parts+=("$work/part$i.exr")
done
expect 0 "merged.exr" -- "$bin" merge "${parts[@]}" -o "$work/merged.exr"
if cmp -s "$work/whole.exr" "$work/merged.exr"; then passes=$((passes + 1)); else fail "merged stripes differ from the whole frame"; fi

# A frame range with the raster integrator.
expect 0 "f0002.exr" -- "$bin" render "$src/scenes/flythrough.gltf" -o "$work/f####.exr" --integrator raster \
  --raster-shadows none "${small[@]}" --frames 1-2 --no-png

# Refusals: raster options elsewhere, and options the raster integrator has no use for.
expect 2 "--raster-shadows needs --integrator raster" -- "$bin" render "$scene" -o "$work/x.exr" --raster-shadows map
expect 2 "--shadow-map-size needs --integrator raster" -- "$bin" render "$scene" -o "$work/x.exr" --shadow-map-size 512
expect 2 "--shadow-map-size needs --raster-shadows map" -- "$bin" render "$scene" -o "$work/x.exr" --integrator raster --shadow-map-size 512
expect 2 "--max-depth does not apply to --integrator raster" -- "$bin" render "$scene" -o "$work/x.exr" --integrator raster --max-depth 2
expect 2 "raster-shadows" -- "$bin" render "$scene" -o "$work/x.exr" --integrator raster --raster-shadows soft
expect 2 "shadow-map-size" -- "$bin" render "$scene" -o "$work/x.exr" --integrator raster --raster-shadows map --shadow-map-size 9
[ -e "$work/x.exr" ] && fail "a refused render left x.exr" || passes=$((passes + 1))

echo "raster: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
