#!/usr/bin/env bash
# Gaussian splats (KHR_gaussian_splatting) end to end through `penumbra`:
# - the shipped scene (splats among meshes, a mirror) renders with Whitted in every structure to
#   the same image, with the path tracer and the raster preview; `info` counts its splats;
# - a splat-only scene cut from it: the raster preview and the ray tracer agree within the
#   documented tolerance (oiiotool's mean difference below 0.003);
# - a deep EXR holds the splats' samples (oiiotool's flatten equals the flat beauty);
# - the splat sphere shows its colour 0.5 + 0.5 n facing the camera in every integrator, and a
#   frame range follows its animated node as single frames do;
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

# Mean absolute difference of two images' RGBA, from oiiotool --diff (which prints no error
# figures for identical images).
mean_diff() {
  local out; out=$(oiiotool "$1" "$2" --diff 2>&1)
  if ! grep -q "Mean error" <<<"$out" && grep -qx "PASS" <<<"$out"; then echo 0; return; fi
  sed -n 's/.*Mean error = *\([0-9.e+-]*\).*/\1/p' <<<"$out" | head -1
}
below() { python3 -c "import sys; sys.exit(0 if float('$1') < float('$2') else 1)"; }
# pixel FILE X Y: the pixel's R G B A, from oiiotool --printstats of a 1 x 1 cut.
pixel() {
  oiiotool "$1" --cut "1x1+$2+$3" --printstats 2>&1 | sed -n 's/.*Stats Avg: *\([-0-9.e+]*\) *\([-0-9.e+]*\) *\([-0-9.e+]*\) *\([-0-9.e+]*\).*/\1 \2 \3 \4/p' | head -1
}
# near "R G B A" R G B TOL: true when the first three are within TOL of R G B.
near() {
  python3 - "$1" "$2" "$3" "$4" "$5" <<'P'
import sys
got = [float(v) for v in sys.argv[1].split()[:3]]
want = [float(v) for v in sys.argv[2:5]]
sys.exit(0 if len(got) == 3 and all(abs(a - b) <= float(sys.argv[5]) for a, b in zip(got, want)) else 1)
P
}

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
expect 0 "splats_whitted.exr" -- "$bin" render "$scene" -o "$work/splats_whitted.exr" --width 96 --no-png
# The ray from the eye (0, 1.6, 4.6) to the sphere's centre (0, 0.75, 0) falls on pixel (48, 21)
# of 96 x 54 (4.5 degrees above the view axis, tilted 15 degrees down, vertical fov 0.75): the
# splats there face the eye, colour 0.5 + 0.5 n = (0.5, 0.592, 0.992), unlit, in every integrator.
command -v exrheader >/dev/null &&
  expect 0 "splats_crypto.exr" -- "$bin" render "$scene" -o "$work/splats_crypto.exr" --width 96 --spp 2 \
    --aov crypto_object,crypto_material --no-png &&
  { exrheader "$work/splats_crypto.exr" | grep -q 'splat sphere' && exrheader "$work/splats_crypto.exr" | grep -q '"splats"' &&
    pass || fail "the Cryptomatte manifests do not name the splat clouds"; }
for integrator in whitted path raster; do
  p=$(pixel "$work/splats_$integrator.exr" 48 21)
  near "$p" 0.5 0.592 0.992 0.06 && pass || fail "$integrator: the splat sphere's front is '$p', not 0.5 + 0.5 n"
done
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

# A frame range over the sphere moved by an animated node: each frame as the single frame.
python3 - "$work/sphere.gltf" "$work/moving.gltf" <<'P'
import base64, json, struct, sys
g = json.load(open(sys.argv[1]))
buf = g["buffers"][0]
head, data = buf["uri"].split(",", 1)
blob = bytearray(base64.b64decode(data))
def add(values, type_):
    while len(blob) % 4:
        blob.append(0)
    raw = struct.pack(f"<{len(values)}f", *values)
    g["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(raw)})
    blob.extend(raw)
    n = {"SCALAR": 1, "VEC3": 3}[type_]
    acc = {"bufferView": len(g["bufferViews"]) - 1, "componentType": 5126, "count": len(values) // n, "type": type_}
    if type_ == "SCALAR":
        acc["min"], acc["max"] = [min(values)], [max(values)]
    g["accessors"].append(acc)
    return len(g["accessors"]) - 1
node = next(i for i, n in enumerate(g["nodes"]) if n["name"] == "splat sphere")
times = add([0, 1], "SCALAR")
moves = add([0, 0.75, 0, 0.6, 0.75, 0], "VEC3")
g["animations"] = [{"samplers": [{"input": times, "output": moves}],
                    "channels": [{"sampler": 0, "target": {"node": node, "path": "translation"}}]}]
buf["uri"] = head + "," + base64.b64encode(bytes(blob)).decode()
buf["byteLength"] = len(blob)
json.dump(g, open(sys.argv[2], "w"))
P
expect 0 "" -- "$bin" render "$work/moving.gltf" -o "$work/moving_#.exr" --frames 0-1 --fps 1 --width 64 --spp 1 --no-png
expect 0 "" -- "$bin" render "$work/moving.gltf" -o "$work/single1.exr" --frame 1 --fps 1 --width 64 --spp 1 --no-png
m=$(mean_diff "$work/moving_1.exr" "$work/single1.exr")
[ -n "$m" ] && below "$m" 1e-7 && pass || fail "frame 1 of the range differs from the single frame by '$m'"
m=$(mean_diff "$work/moving_0.exr" "$work/moving_1.exr")
[ -n "$m" ] && ! below "$m" 0.01 && pass || fail "the animated splat sphere did not move between frames ('$m')"

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
