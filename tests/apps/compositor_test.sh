#!/usr/bin/env bash
# Penumbra's EXRs in a real compositor (Debian's Blender 3.4, headless):
# - every layer of a render with every AOV (single-part and --multipart) appears as a pass of
#   Blender's Image node, with no "unknown channel token", "no rect set" or OpenEXR read error;
# - Blender's own Cryptomatte node picks a name's matte from Penumbra's Cryptomatte layers, and
#   the matte's total equals the coverage of that object (material, asset) in Penumbra's id AOV
#   within 1%.
# Skipped (reported by ctest as skipped) when `blender` is not installed.
# Usage: compositor_test.sh PENUMBRA SRC WORK_DIR
set -u
penumbra="$1"; src="$2"; work="$3"
if ! command -v blender >/dev/null; then
  echo "PENUMBRA_SKIP: blender is not installed"
  exit 0
fi
rm -rf "$work"; mkdir -p "$work"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
scene="$src/scenes/default.gltf"

# 1. Layers, single-part and multipart.
"$penumbra" render "$scene" -o "$work/all.exr" --width 64 --height 48 --integrator path --spp 4 \
  --aov all,cost --accel bvh -q >/dev/null || fail "render all.exr"
"$penumbra" render "$scene" -o "$work/parts.exr" --width 64 --height 48 --integrator path --spp 4 \
  --aov all,cost --accel bvh --multipart -q >/dev/null || fail "render parts.exr"
for exr in all parts; do
  blender -b --factory-startup --python-exit-code 1 --python "$src/tests/apps/blender_layers.py" \
    -- "$work/$exr.exr" >"$work/$exr.log" 2>&1 || fail "blender exited $? on $exr.exr"
  if grep -Ei "unknown channel|no rect set|bad channel|error|warning|Traceback" "$work/$exr.log"; then
    fail "blender warns about $exr.exr"
  fi
  for pass in "Combined RGBA" "Alpha VALUE" "Depth VALUE" "N RGBA" "P RGBA" "UV RGBA" "albedo RGBA" \
              "object_id VALUE" "material_id VALUE" "samples VALUE" "variance VALUE" "emission RGBA" \
              "diffuse_direct RGBA" "diffuse_indirect RGBA" "specular_direct RGBA" "specular_indirect RGBA" \
              "cost_nodes VALUE" "cost_triangles VALUE" "cost_shapes VALUE" "cost_ns VALUE" \
              "CryptoObject00 RGBA" "CryptoObject02 RGBA" "CryptoMaterial00 RGBA" "CryptoAsset02 RGBA"; do
    grep -qx "PASS $pass" "$work/$exr.log" || fail "$exr.exr: Blender's Image node has no pass '$pass'"
  done
  # Nothing but the listed layers: as many passes as Penumbra wrote layers.
  got=$(grep -c '^PASS ' "$work/$exr.log")
  [ "$got" -eq 29 ] || fail "$exr.exr: $got passes in Blender, expected 29"
done

# 2. Cryptomatte mattes against the id AOV.
W=320; H=240
"$penumbra" render "$scene" -o "$work/crypto.exr" --width $W --height $H --spp 16 \
  --aov id,crypto_object,crypto_material,crypto_asset -q >/dev/null || fail "render crypto.exr"
# fraction of pixels whose CHANNEL equals ID (ids are whole numbers: |x - id| clamped to [0, 1])
id_fraction() {
  oiiotool "$work/crypto.exr" --ch "$1" --subc "$2" --abs --clamp:min=0:max=1 --mulc -1 --addc 1 --printstats |
    awk '/Stats Avg/ {print $3}'
}
matte_total() {  # LAYER NAME: Blender's matte, averaged over the image
  blender -b --factory-startup --python-exit-code 1 --python "$src/tests/apps/blender_cryptomatte.py" \
    -- "$work/crypto.exr" "$1" "$2" "$work/matte.exr" $W $H >"$work/matte.log" 2>&1 ||
    { fail "blender's Cryptomatte node failed on $1 '$2'"; tail -5 "$work/matte.log"; echo 0; return; }
  oiiotool "$work/matte.exr" --ch R --printstats | awk '/Stats Avg/ {print $3}'
}
check() {  # LAYER NAME EXPECTED
  local got; got=$(matte_total "$1" "$2")
  echo "$1 '$2': Blender's matte $got, id AOV $3"
  awk -v g="$got" -v e="$3" 'BEGIN { exit !(e > 0.005 && (g - e) <= 0.01 * e && (e - g) <= 0.01 * e) }' ||
    fail "$1 '$2': Blender's matte covers $got of the frame, the id AOV $3"
}
# Object ids are node index + 1 (the manifest in penumbra:manifest names them).
manifest=$(oiiotool --info -v "$work/crypto.exr" | grep 'penumbra:manifest')
node_id() { echo "$manifest" | grep -o "\"[0-9]*\": \"$1\"" | head -1 | grep -o '^"[0-9]*"' | tr -d '"'; }
for name in "blue sphere" "gold sphere" "yellow box" "floor"; do
  check CryptoObject "$name" "$(id_fraction object_id.X "$(node_id "$name")")"
done
check CryptoMaterial "polished gold" "$(id_fraction material_id.X 7)"
# An asset is a root node with its descendants: "mirror frame" holds "mirror".
frame=$(id_fraction object_id.X "$(node_id "mirror frame")"); mirror=$(id_fraction object_id.X "$(node_id "mirror")")
check CryptoAsset "mirror frame" "$(awk -v a="$frame" -v b="$mirror" 'BEGIN {print a + b}')"

echo "compositor: $fails failures"
[ "$fails" -eq 0 ]
