#!/usr/bin/env bash
# PENUMBRA_procedural through `penumbra`: files with bad procedural materials exit 2 from render
# and info with the file, the JSON path, the field and the material in the message and leave no
# output; the shipped procedural scene renders, and `info` describes its procedural materials.
# Usage: procedural_test.sh PENUMBRA_BINARY SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0

# expect CODE PATTERN -- command... and expect_refused NAME PATTERN count passes and failures.
source "$(dirname "$0")/expect.sh"

# A file with one analytic sphere whose material 'stone' carries the extension object $2,
# written to $work/$1.gltf.
procedural_file() {
  printf '{"asset":{"version":"2.0"},"extensionsUsed":["PENUMBRA_shapes","PENUMBRA_procedural"],"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"extensions":{"PENUMBRA_shapes":{"type":"sphere","material":0}}}],"materials":[{"name":"stone","extensions":{"PENUMBRA_procedural":%s}}]}\n' "$2" >"$work/$1.gltf"
}

ext='materials\[0\]\.extensions\.PENUMBRA_procedural'
procedural_file detail '{"pattern":{"type":"noise","detail":99}}'
procedural_file key '{"pattern":{"type":"voronoi","lacunarity":2}}'
procedural_file ramp '{"baseColor":{"ramp":[{"position":0.8,"color":[1,1,1]},{"position":0.2,"color":[0,0,0]}]}}'
procedural_file unknown '{"colour":[1,0,0]}'
for case in "detail|$ext\.pattern\.detail: must be in \[0, 15\] \(got 99\) \(material 'stone'\)" \
            "key|$ext\.pattern\.lacunarity: does not apply to pattern type \"voronoi\"" \
            "ramp|$ext\.baseColor\.ramp\[1\]\.position: positions must not decrease" \
            "unknown|$ext\.colour: unknown key"; do
  expect_refused "${case%%|*}" "${case#*|}"
done

# Listed in extensionsRequired, the extension loads; info describes the texture.
procedural_file good '{"space":"world","pattern":{"type":"wave","wave":"rings"},"baseColor":{},"bump":{"height":0.01}}'
sed 's/"extensionsUsed"/"extensionsRequired":["PENUMBRA_procedural"],"extensionsUsed"/' "$work/good.gltf" >"$work/required.gltf"
expect 0 "procedural: wave \(fbm\) in world space, seed 0; drives base colour, bump" -- "$bin" info "$work/required.gltf"
expect 0 "required.png" -- "$bin" render "$work/required.gltf" -o "$work/required.exr" --width 32 --spp 1 -q

# The shipped showcase: every material is procedural; it renders with both integrators.
expect 0 "\[1\] marble: .*" -- "$bin" info "$src/scenes/procedural.gltf"
expect 0 "procedural: voronoi in world space, seed 0; drives base colour, roughness, bump" -- "$bin" info "$src/scenes/procedural.gltf"
expect 0 "procedural.png" -- "$bin" render "$src/scenes/procedural.gltf" -o "$work/procedural.exr" --width 48 --spp 1 -q
expect 0 "procedural-path.png" -- "$bin" render "$src/scenes/procedural.gltf" -o "$work/procedural-path.exr" --width 48 --spp 2 -q --integrator path

echo "procedural cli: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
