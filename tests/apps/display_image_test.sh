#!/usr/bin/env bash
# The display image says only what is true and records how it was made:
# - sRGB chunks (sRGB, gAMA, cHRM) for the shipped config's sRGB views, none for its Raw view (data)
#   or for a studio config's Rec.1886 display;
# - the OCIO config name, display, view, look, view colour space and exposure in tEXt chunks of
#   the PNG and in the EXR's header;
# - --png-alpha writes RGBA whose alpha is the EXR's, and is refused for JPEG before rendering;
# - a crop's PNG keeps its offset in the full frame (oFFs, in pixels).
# Usage: display_image_test.sh PENUMBRA SRC WORK_DIR
set -u
penumbra="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
source "$src/tests/apps/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
# absent PATTERN PNG: no chunk line of PNG matches PATTERN.
absent() {
  if chunks "$2" | grep -qE -- "$1"; then fail "$2 has a chunk matching '$1'"; else passes=$((passes + 1)); fi
}
chunks() { /usr/bin/python3 "$src/tests/apps/png_chunks.py" "$1"; }
scene="$src/scenes/spheres.gltf"
small=(--width 64 --height 48 -q)

"$penumbra" render "$scene" -o "$work/std.exr" "${small[@]}" --look "High Contrast" --exposure 0.5 >/dev/null
expect 0 "^sRGB 0|^sRGB 3" -- chunks "$work/std.png"
expect 0 "IHDR 64 48 8 2" -- chunks "$work/std.png"
for kv in "ocio_config=penumbra-default" "ocio_display=sRGB" "ocio_view=Standard" "ocio_look=High Contrast" \
          "ocio_colorspace=srgb_display" "exposure=0.5"; do
  expect 0 "tEXt penumbra:$kv\$" -- chunks "$work/std.png"
  key=${kv%%=*}; value=${kv#*=}
  expect 0 "penumbra:$key: \"$value\"" -- oiiotool --info -v "$work/std.exr"
done

# Raw is data: no colour tags.
"$penumbra" render "$scene" -o "$work/raw.exr" "${small[@]}" --view Raw >/dev/null
absent "^(sRGB|gAMA|cHRM)" "$work/raw.png"
expect 0 "tEXt penumbra:ocio_view=Raw" -- chunks "$work/raw.png"

# A studio config whose display is Rec.1886 (gamma 2.4), not sRGB.
cat >"$work/studio.ocio" <<'OCIO'
ocio_profile_version: 2
name: studio-rec1886
roles:
  default: linear
  scene_linear: linear
  data: raw
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  Rec.1886:
    - !<View> {name: Video, colorspace: rec1886}
active_displays: [Rec.1886]
active_views: [Video]
colorspaces:
  - !<ColorSpace>
    name: linear
    isdata: false
  - !<ColorSpace>
    name: raw
    isdata: true
  - !<ColorSpace>
    name: rec1886
    isdata: false
    from_scene_reference: !<ExponentTransform> {value: 2.4, direction: inverse}
OCIO
OCIO="$work/studio.ocio" "$penumbra" render "$scene" -o "$work/video.exr" "${small[@]}" >/dev/null
absent "^(sRGB|gAMA|cHRM)" "$work/video.png"
expect 0 "tEXt penumbra:ocio_config=studio-rec1886" -- chunks "$work/video.png"
expect 0 "tEXt penumbra:ocio_display=Rec.1886" -- chunks "$work/video.png"
expect 0 "penumbra:ocio_colorspace: \"rec1886\"" -- oiiotool --info -v "$work/video.exr"

# Alpha: RGBA, the EXR's alpha to 8 bits.
"$penumbra" render "$src/scenes/csg.gltf" -o "$work/alpha.exr" "${small[@]}" --png-alpha >/dev/null
expect 0 "IHDR 64 48 8 6" -- chunks "$work/alpha.png"
expect 0 "PASS" -- oiiotool --fail 0.0021 --warn 0.0021 "$work/alpha.png" --ch A "$work/alpha.exr" --ch A --diff
expect 0 "Stats Min: 0.000000" -- oiiotool "$work/alpha.png" --ch A --printstats
expect 2 "JPEG has no alpha channel" -- "$penumbra" render "$scene" -o "$work/a.exr" --png "$work/a.jpg" --png-alpha "${small[@]}"
[ ! -e "$work/a.exr" ] || fail "a refused --png-alpha left $work/a.exr"

# A crop keeps its place in the frame.
"$penumbra" render "$scene" -o "$work/crop.exr" "${small[@]}" --crop 10 30 5 25 >/dev/null
expect 0 "IHDR 20 20 8 2" -- chunks "$work/crop.png"
expect 0 "oFFs 10 5 0" -- chunks "$work/crop.png"
"$penumbra" render "$scene" -o "$work/tile.exr" "${small[@]}" --tile 1/3 >/dev/null
expect 0 "oFFs 0 16 0" -- chunks "$work/tile.png"

echo "display image: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
