#!/usr/bin/env bash
# PENUMBRA_shapes through `penumbra`: files with bad shapes exit 2 from render and info with the
# file, the JSON path and the field in the message and leave no output; the shipped shape scenes
# and a displaced sphere render and `info` lists their shapes; the white furnace vanishes with
# energy compensation. Usage: shapes_test.sh PENUMBRA_BINARY SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0

# expect CODE PATTERN -- command... and expect_refused NAME PATTERN count passes and failures.
source "$(dirname "$0")/expect.sh"

# A file whose one node carries the shape extension object $2, written to $work/$1.gltf.
shape_file() {
  printf '{"asset":{"version":"2.0"},"extensionsUsed":["PENUMBRA_shapes"],"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"extensions":{"PENUMBRA_shapes":%s}}]}\n' "$2" >"$work/$1.gltf"
}

ext='nodes\[0\]\.extensions\.PENUMBRA_shapes'
shape_file radius '{"type":"implicit","csg":{"type":"union","children":[{"type":"sphere"},{"type":"sphere","radius":-1}]}}'
shape_file type '{"type":"teapot"}'
shape_file key '{"type":"box","radius":1}'
shape_file unbounded '{"type":"implicit","csg":{"type":"halfSpace","normal":[0,1,0]}}'
shape_file material '{"type":"sphere","material":0}'
shape_file detail '{"type":"implicit","csg":{"type":"displace","amplitude":0.1,"detail":20,"children":[{"type":"sphere"}]}}'
shape_file rough '{"type":"implicit","csg":{"type":"displace","amplitude":0.2,"frequency":3,"noise":"ridged","children":[{"type":"sphere"}]}}'
shape_file deep "{\"type\":\"implicit\",\"csg\":$(python3 -c 'import json; j={"type":"sphere"}
for _ in range(70): j={"type":"complement","children":[j]}
print(json.dumps({"type":"intersection","children":[j,{"type":"sphere"}]}))')}"
for case in "radius|$ext\.csg\.children\[1\]\.radius: must be > 0" \
            "type|$ext\.type: unknown shape type \"teapot\"" \
            "key|$ext\.radius: does not apply to a \"box\" shape" \
            "unbounded|$ext\.csg: the shape's inside is unbounded" \
            "material|$ext\.material: index 0 out of range \(0 materials\)" \
            "detail|$ext\.csg\.detail: must be in \[0, 15\] \(got 20\)"; do
  expect_refused "${case%%|*}" "${case#*|}"
done
# Too deep for the JSON nesting limit already (each CSG level is two JSON levels).
expect 2 "nesting deeper than 64 levels" -- "$bin" info "$work/deep.gltf"

# The shipped scenes: info lists the shapes; each renders.
expect 0 "shapes       4, 4 instances" -- "$bin" info "$src/scenes/csg.gltf"
expect 0 "\[1\] nodes\[1\] 'csg part': implicit \([0-9]+ CSG nodes\), material 1 'red plastic', 1 instance" -- "$bin" info "$src/scenes/csg.gltf"
expect 0 "\[0\] nodes\[0\] 'ground': plane \(40 x 40\), material 0 'ground'" -- "$bin" info "$src/scenes/csg.gltf"
expect 0 "sphere \(radius 0.7\)" -- "$bin" info "$src/scenes/spheres.gltf"
expect 0 "capsule \(radius 0.3, height 1.2\)" -- "$bin" info "$src/scenes/spheres.gltf"
for scene in csg spheres; do
  expect 0 "$scene.png" -- "$bin" render "$src/scenes/$scene.gltf" -o "$work/$scene.exr" --width 48 --spp 1 -q
  expect 0 "$scene-bvh.png" -- "$bin" render "$src/scenes/$scene.gltf" -o "$work/$scene-bvh.exr" --width 48 --spp 1 -q --accel bvh
done
# A displaced sphere: info counts its CSG nodes; it renders with the default and the own BVH.
expect 0 "implicit \(2 CSG nodes\)" -- "$bin" info "$work/rough.gltf"
expect 0 "rough.png" -- "$bin" render "$work/rough.gltf" -o "$work/rough.exr" --width 32 --spp 1 -q
expect 0 "rough-bvh.png" -- "$bin" render "$work/rough.gltf" -o "$work/rough-bvh.exr" --width 32 --spp 1 -q --accel bvh
# Listed in extensionsRequired, the extension loads.
sed 's/"extensionsUsed"/"extensionsRequired":["PENUMBRA_shapes"],"extensionsUsed"/' "$work/key.gltf" | sed 's/"radius":1/"size":[1,2,3]/' >"$work/required.gltf"
expect 0 "box \(1 x 2 x 3\), default material, 1 instance" -- "$bin" info "$work/required.gltf"
expect 0 "required.png" -- "$bin" render "$work/required.gltf" -o "$work/required.exr" --width 32 --spp 1 -q
# The render summary and --stats-json count the placed shapes (csg.gltf: three implicit shapes
# and the analytic ground).
expect 0 "4 shapes \(4 placed\)" -- "$bin" render "$src/scenes/csg.gltf" -o "$work/csg.exr" --width 32 --spp 1 --no-png --stats-json "$work/csg.json"
expect 0 '^4$' -- python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["shapes"])' "$work/csg.json"

# The white furnace (scenes/furnace.gltf): white metal spheres of roughness 0.2 to 1 under
# environment 1 vanish with energy compensation (the image's mean and the roughest sphere's
# pixels are 1), and without it the roughest sphere is darker than its background.
if command -v oiiotool >/dev/null; then
  furnace() {  # NAME FLAGS...: renders the furnace at 96 x 54, 256 spp
    local name="$1"; shift
    "$bin" render "$src/scenes/furnace.gltf" -o "$work/$name.exr" --no-png --float -q --integrator path \
      --env 1 --width 96 --height 54 --spp 256 "$@"
  }
  avg() {  # FILE [CUT]: mean of R over the image or a region
    oiiotool "$1" --ch R ${2:+--cut "$2"} --printstats 2>/dev/null | sed -n 's/.*Avg: *\([0-9.e+-]*\).*/\1/p' | head -1
  }
  furnace furnace_on && furnace furnace_off --energy-compensation off || fails=$((fails + 1))
  rough="8x8+81+23"  # inside the roughness-1 sphere (centre x = 2 at pixel 85, radius 8 pixels)
  if python3 -c "import sys; a, r, off = map(float, sys.argv[1:]); sys.exit(0 if abs(a - 1) < 0.01 and abs(r - 1) < 0.02 and off < 0.97 else 1)" \
      "$(avg "$work/furnace_on.exr")" "$(avg "$work/furnace_on.exr" "$rough")" "$(avg "$work/furnace_off.exr" "$rough")"; then
    passes=$((passes + 1))
  else
    echo "FAIL: furnace: mean $(avg "$work/furnace_on.exr"), roughest sphere $(avg "$work/furnace_on.exr" "$rough") compensated, $(avg "$work/furnace_off.exr" "$rough") without"
    fails=$((fails + 1))
  fi
fi

echo "shapes cli: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
