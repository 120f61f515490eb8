#!/usr/bin/env bash
# Gaussian splats (KHR_gaussian_splatting) end to end through `penumbra`:
# - the shipped scene (splats among meshes, a mirror) renders with Whitted in every structure to
#   the same image, with the path tracer and the raster preview; `info` counts its splats;
# - a splat-only scene cut from it: the raster preview and the ray tracer agree within the
#   documented tolerance (oiiotool's mean difference below 0.003);
# - a deep EXR holds the splats' samples (oiiotool's flatten equals the flat beauty);
# - malformed splats exit 2 naming the accessor, writing nothing.
# Usage: splats_test.sh PENUMBRA SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
. "$src/tests/apps/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
pass() { passes=$((passes + 1)); }
for tool in oiiotool python3; do
  command -v "$tool" >/dev/null || { echo "PENUMBRA_SKIP: $tool is not installed"; exit 0; }
done
scene="$src/scenes/splats.gltf"

# Mean absolute difference of two images' RGBA, from oiiotool --diff.
mean_diff() {
  oiiotool "$1" "$2" --diff 2>&1 | sed -n 's/.*Mean error = *\([0-9.e+-]*\).*/\1/p' | head -1
}
below() { python3 -c "import sys; sys.exit(0 if float('$1') < float('$2') else 1)"; }

# 1. The shipped scene: every structure the same image (up to rounding), path and raster.
for accel in embree bvh kdtree grid octree bsp; do
  expect 0 "splats_$accel.exr" -- "$bin" render "$scene" -o "$work/splats_$accel.exr" --accel "$accel" \
    --width 128 --spp 2 --aov id --no-png
done
for accel in bvh kdtree grid octree bsp; do
  m=$(mean_diff "$work/splats_$accel.exr" "$work/splats_embree.exr")
  [ -n "$m" ] && below "$m" 1e-4 && pass || fail "--accel $accel differs from embree by a mean of '$m'"
done
expect 0 "splats_path.exr" -- "$bin" render "$scene" -o "$work/splats_path.exr" --integrator path --width 96 --spp 4 --no-png
expect 0 "splats_raster.exr" -- "$bin" render "$scene" -o "$work/splats_raster.exr" --integrator raster --width 96 --no-png
expect 0 "splats       2512 in 2 placements of 2 clouds" -- "$bin" info "$scene"
"$bin" info "$scene" --json | python3 -c "import json, sys; assert json.load(sys.stdin)['splats']['placed'] == 2512" &&
  pass || fail "info --json does not count 2512 splats"

# 2. The splat sphere alone (and the camera): raster and trace agree within 0.003.
python3 - "$scene" "$work/sphere.gltf" <<'P'
import json, sys
g = json.load(open(sys.argv[1]))
keep = [i for i, n in enumerate(g["nodes"]) if n["name"] in ("splat sphere", "camera")]
g["scenes"][0]["nodes"] = keep
json.dump(g, open(sys.argv[2], "w"))
P
expect 0 "sphere_trace.exr" -- "$bin" render "$work/sphere.gltf" -o "$work/sphere_trace.exr" --width 128 --spp 4 --no-png
expect 0 "sphere_raster.exr" -- "$bin" render "$work/sphere.gltf" -o "$work/sphere_raster.exr" --integrator raster \
  --width 128 --spp 4 --no-png
m=$(mean_diff "$work/sphere_trace.exr" "$work/sphere_raster.exr")
[ -n "$m" ] && below "$m" 0.003 && pass || fail "raster and trace of the splat sphere differ by a mean of '$m'"
oiiotool "$work/sphere_trace.exr" --printstats 2>&1 | grep -q "Stats Max: 0\.0* 0\.0* 0\.0* 0\.0*" &&
  fail "the splat sphere renders black" || pass

# 3. Deep: the splats' samples flatten to the flat beauty.
expect 0 "flat.exr" -- "$bin" render "$work/sphere.gltf" -o "$work/flat.exr" --width 64 --spp 2 --deep "$work/deep.exr" \
  --no-png
oiiotool "$work/deep.exr" --flatten --ch R,G,B,A -o "$work/flattened.exr" >/dev/null 2>&1
m=$(mean_diff "$work/flattened.exr" "$work/flat.exr")
[ -n "$m" ] && below "$m" 1e-3 && pass || fail "the deep splats flatten to a mean difference of '$m'"

# 4. Malformed splats: exit 2 naming the accessor, nothing written.
python3 - "$work" <<'P'
import base64, json, math, struct, sys
w = sys.argv[1]
E = "KHR_gaussian_splatting"
def gltf(name, rot=(0, 0, 0, 1), scale=(0.1, 0.1, 0.1), opacity=0.5, dc=(0, 0, 0), space="srgb_rec709_display"):
    blob = bytearray()
    acc, views = [], []
    def add(vals, type_):
        data = struct.pack(f"<{len(vals)}f", *vals)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob.extend(data)
        acc.append({"bufferView": len(views) - 1, "componentType": 5126, "count": 1, "type": type_})
        return len(acc) - 1
    attrs = {"POSITION": add([0, 0, 0], "VEC3"), f"{E}:ROTATION": add(list(rot), "VEC4"),
             f"{E}:SCALE": add(list(scale), "VEC3"), f"{E}:OPACITY": add([opacity], "SCALAR"),
             f"{E}:SH_DEGREE_0_COEF_0": add(list(dc), "VEC3")}
    prim = {"attributes": attrs, "mode": 0, "extensions": {E: {"kernel": "ellipse", "colorSpace": space}}}
    g = {"asset": {"version": "2.0"}, "extensionsUsed": [E], "scene": 0, "scenes": [{"nodes": [0]}],
         "nodes": [{"mesh": 0}], "meshes": [{"primitives": [prim]}], "accessors": acc, "bufferViews": views,
         "buffers": [{"byteLength": len(blob),
                      "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}]}
    json.dump(g, open(f"{w}/{name}.gltf", "w"))
gltf("quaternion", rot=(0, 0, 0, 2))
gltf("scale", scale=(0.1, -0.1, 0.1))
gltf("opacity", opacity=1.5)
gltf("nan", dc=(0, math.nan, 0))
gltf("space", space="acescg")
gltf("good")
P
ext='KHR_gaussian_splatting'
expect_refused quaternion "meshes\[0\]\.primitives\[0\]\.attributes\.$ext:ROTATION\[0\]: .*unit quaternion"
expect_refused scale "meshes\[0\]\.primitives\[0\]\.attributes\.$ext:SCALE\[0\]: .*not a finite number >= 0"
expect_refused opacity "meshes\[0\]\.primitives\[0\]\.attributes\.$ext:OPACITY\[0\]: .*not in \[0, 1\]"
expect_refused nan "meshes\[0\]\.primitives\[0\]\.attributes\.$ext:SH_DEGREE_0_COEF_0\[0\]: .*NaN"
expect_refused space "meshes\[0\]\.primitives\[0\]\.extensions\.$ext\.colorSpace: .*'acescg' is not known"
expect 0 "splats       1 in 1 placements" -- "$bin" info "$work/good.gltf"

echo "splats: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
