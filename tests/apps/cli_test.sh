#!/usr/bin/env bash
# End-to-end test of the `penumbra` command: exit codes (0 ok, 2 bad input/usage), messages
# that name the file and element, and the output files. Usage: cli_test.sh PENUMBRA SRC WORK
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
corpus="${PENUMBRA_CORPUS:-${PENUMBRA_CORPUS_DEFAULT:-$src/../shared/corpus}}"
fails=0; passes=0

# expect CODE PATTERN -- command...: counts a pass or a failure in $passes / $fails.
source "$(dirname "$0")/expect.sh"

expect 0 "penumbra [0-9]" -- "$bin" --version
expect 2 "render|info" -- "$bin"
expect 2 "no-such-flag" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --no-such-flag
expect 2 "missing.gltf: file not found" -- "$bin" render "$work/missing.gltf" -o "$work/a.exr"
expect 2 "must be an .exr" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.png"
expect 2 "does not exist" -- "$bin" render "$src/scenes/default.gltf" -o "$work/nodir/a.exr"
expect 2 "spp" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --spp 0
expect 2 "camera 7 does not exist \(cameras: 0 'room camera'\)" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --camera 7
expect 2 "camera 99999999999 does not exist" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --camera 99999999999
expect 2 "no camera named 'side' \(cameras: 0 'room camera'\)" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --camera side
expect 2 "background" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --background nan
# Display-output mistakes are caught before rendering, so they cost no render and write no EXR.
expect 2 "no view 'Typo' \(available: Standard, Filmic, Raw\)" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --view Typo
expect 2 "no look 'Bleach' \(available: High Contrast, Low Contrast, Plus 1 EV, Minus 1 EV\)" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --look Bleach
expect 2 "no display 'P3'" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --display P3
expect 2 "a.xyz: unsupported display image format" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --png "$work/a.xyz"
expect 2 "nope.ocio" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --ocio-config "$work/nope.ocio"
expect 2 "debug-pixel -1,-1 is outside" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --debug-pixel=-1,-1
[ ! -e "$work/a.exr" ] || { echo "FAIL: a failed run left $work/a.exr"; fails=$((fails + 1)); }

# A real render: both paths on stdout, files readable, RGBA half EXR.
expect 0 "small.png" -- "$bin" render "$src/scenes/default.gltf" -o "$work/small.exr" --width 64 --spp 1 -q
if command -v oiiotool >/dev/null; then
  expect 0 "64 x +36, 4 channel, half" -- oiiotool --info -v "$work/small.exr"
  expect 0 "R, G, B, A" -- oiiotool --info -v "$work/small.exr"
  expect 0 "64 x +36, 3 channel, uint8 png" -- oiiotool --info "$work/small.png"
fi
expect 0 "render|rays" -- "$bin" render "$src/scenes/default.gltf" -o "$work/f.exr" --float --no-png --height 20 --threads 1
[ ! -e "$work/f.png" ] || { echo "FAIL: --no-png wrote a PNG"; fails=$((fails + 1)); }
expect 0 "small-named.png" -- "$bin" render "$src/scenes/default.gltf" -o "$work/small-named.exr" --camera "room camera" --width 64 --spp 1 -q
if command -v oiiotool >/dev/null; then  # the camera chosen by name is camera 0: the same image
  expect 0 "PASS" -- oiiotool "$work/small.exr" "$work/small-named.exr" --fail 0 --diff
fi
expect 0 "pixel 10,10: R" -- "$bin" render "$src/scenes/default.gltf" -o "$work/d.exr" --debug-pixel 10,10 --width 64
expect 0 "4646 triangles" -- "$bin" info "$src/scenes/default.gltf"
expect 0 "brute" -- "$bin" info "$src/scenes/default.gltf" --accel brute
# Every accelerator renders; its statistics print; bad names and parameters exit 2 up front.
for accel in embree bvh kdtree grid; do
  expect 0 "accel $accel" -- "$bin" render "$src/scenes/default.gltf" -o "$work/acc-$accel.exr" --width 48 --spp 1 --no-png --accel "$accel"
done
if command -v oiiotool >/dev/null; then
  for accel in bvh kdtree grid; do  # same image as Embree (half-float EXR; ties aside, bit-identical)
    expect 0 "PASS" -- oiiotool "$work/acc-embree.exr" "$work/acc-$accel.exr" --warn 0.004 --fail 0.004 --diff
  done
fi
expect 0 "SAH cost" -- "$bin" info "$src/scenes/default.gltf" --accel bvh
# Instancing: the default scene's "wall" mesh (floor, ceiling, front wall) is stored once; --flatten
# gives each node its own world-space copy, and both render the same image.
expect 0 "instances    11 \(8 in world space, 3 placed by a transform\)" -- "$bin" info "$src/scenes/default.gltf"
expect 0 "instances  3 \(two levels\)" -- "$bin" info "$src/scenes/default.gltf" --accel kdtree
expect 0 "instances    11 \(11 in world space, 0 placed" -- "$bin" info "$src/scenes/default.gltf" --flatten
expect 0 "accel bvh" -- "$bin" render "$src/scenes/default.gltf" -o "$work/flat.exr" --width 48 --spp 1 --no-png --accel bvh --flatten
if command -v oiiotool >/dev/null; then
  expect 0 "PASS" -- oiiotool "$work/acc-bvh.exr" "$work/flat.exr" --warn 0.004 --fail 0.004 --diff
fi
expect 0 "max_leaf_size 2, bin_count 32" -- "$bin" info "$src/scenes/default.gltf" --accel bvh --accel-param bvh.max_leaf_size=2 --accel-param bvh.bin_count=32
expect 0 "empty .* leaves" -- "$bin" info "$src/scenes/default.gltf" --accel kdtree
# Traversal-cost AOV: EXR channels and a heat map (time for Embree, which keeps no counts);
# unknown AOVs and a stray --cost-png are refused up front.
expect 2 "unknown AOV 'normals'" -- "$bin" render "$src/scenes/default.gltf" -o "$work/c.exr" --aov normals --accel bvh
expect 2 "--cost-png needs --aov cost" -- "$bin" render "$src/scenes/default.gltf" -o "$work/c.exr" --cost-png "$work/c.png"
expect 2 "directory '$work/nodir' does not exist" -- "$bin" render "$src/scenes/default.gltf" -o "$work/c.exr" --aov cost --accel bvh --cost-png "$work/nodir/c.png"
[ ! -e "$work/c.exr" ] || { echo "FAIL: a refused --aov run left $work/c.exr"; fails=$((fails + 1)); }
for accel in embree bvh kdtree grid; do
  expect 0 "cost-$accel.cost.png" -- "$bin" render "$src/scenes/default.gltf" -o "$work/cost-$accel.exr" --width 64 --spp 1 -q --aov cost --accel "$accel"
done
if command -v oiiotool >/dev/null; then
  expect 0 "cost_nodes.X \(float\), cost_ns.X \(float\), cost_shapes.X \(float\), cost_triangles.X \(float\)" -- oiiotool --info -v "$work/cost-bvh.exr"
  expect 0 "A \(half\), cost_ns.X \(float\)" -- oiiotool --info -v "$work/cost-embree.exr"
  expect 0 "64 x +[0-9]+, 3 channel, uint8 png" -- oiiotool --info "$work/cost-grid.cost.png"
fi
expect 0 "resolution [0-9]+x[0-9]+x[0-9]+" -- "$bin" info "$src/scenes/default.gltf" --accel grid --accel-param grid.lambda=2
expect 2 "unknown accelerator 'quadtree' \(known: embree, bvh, kdtree, grid, octree, bsp, brute\)" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --accel quadtree
expect 2 "unknown key 'grid.lamda'" -- "$bin" render "$src/scenes/default.gltf" -o "$work/a.exr" --accel grid --accel-param grid.lamda=2
expect 2 "lambda must be in" -- "$bin" info "$src/scenes/default.gltf" --accel grid --accel-param grid.lambda=-1
expect 2 "'2x' is not a valid" -- "$bin" info "$src/scenes/default.gltf" --accel-param bvh.bin_count=2x
expect 2 "expected key=value" -- "$bin" info "$src/scenes/default.gltf" --accel-param bvh
# The path tracer: its options, their mistakes, environment maps and the deterministic replay.
d="$src/scenes/default.gltf"
expect 2 "needs --integrator path" -- "$bin" render "$d" -o "$work/p.exr" --env 1
expect 2 "needs --integrator path" -- "$bin" render "$d" -o "$work/p.exr" --adaptive 0.01
expect 2 "--env-intensity needs --integrator path" -- "$bin" render "$d" -o "$work/p.exr" --env-intensity 2
expect 2 "--light-samples needs --integrator path" -- "$bin" render "$d" -o "$work/p.exr" --light-samples 4
expect 2 "--light-sampler needs --integrator path" -- "$bin" render "$d" -o "$work/p.exr" --light-sampler tree
expect 2 "--background applies to --integrator whitted" -- "$bin" render "$d" -o "$work/p.exr" --integrator path --background 1
expect 2 "integrator" -- "$bin" render "$d" -o "$work/p.exr" --integrator bidir
expect 2 "unknown filter 'mitchell'" -- "$bin" render "$d" -o "$work/p.exr" --integrator path --filter mitchell
expect 2 "filter-width" -- "$bin" render "$d" -o "$work/p.exr" --integrator path --filter-width 100
expect 2 "env: values must be finite" -- "$bin" render "$d" -o "$work/p.exr" --integrator path --env=-1
expect 2 "sky.exr: --env: file not found" -- "$bin" render "$d" -o "$work/p.exr" --integrator path --env "$work/sky.exr"
expect 2 "clamp-indirect" -- "$bin" render "$d" -o "$work/p.exr" --integrator path --clamp-indirect nan
expect 2 "time-limit" -- "$bin" render "$d" -o "$work/p.exr" --integrator path --time-limit=-1
expect 2 "image 16384x16384 \(path\) needs [0-9.]+ GiB for the film and output buffers, over the 1.0 GiB budget" -- "$bin" render "$d" -o "$work/p.exr" --integrator path --width 16384 --height 16384 --max-memory 1G
[ ! -e "$work/p.exr" ] || { echo "FAIL: a refused path render left $work/p.exr"; fails=$((fails + 1)); }
expect 0 "path max-depth 12, filter blackman-harris 1.5 px" -- "$bin" render "$d" -o "$work/p.exr" --integrator path --width 48 --spp 4
expect 0 "path max-depth 3, filter gaussian 3 px" -- "$bin" render "$d" -o "$work/q.exr" --integrator path --width 48 --spp 4 \
  --max-depth 3 --filter gaussian --sampler independent --light-sampling bsdf --clamp-indirect 10 --env 0.2,0.3,0.4
expect 0 "stopped by --time-limit" -- "$bin" render "$d" -o "$work/t.exr" --integrator path --width 48 --spp 4096 --time-limit 0.000001 --no-png
expect 0 "adaptive" -- "$bin" render "$d" -o "$work/ad.exr" --integrator path --width 48 --spp 64 --adaptive 0.05 --no-png
if command -v oiiotool >/dev/null; then
  # An environment map: a 16 x 8 EXR sky made by oiiotool, rotated and scaled.
  oiiotool --pattern fill:top=4,4,5:bottom=0.2,0.1,0 16x8 3 -d float -o "$work/sky.exr" >/dev/null 2>&1
  expect 0 "sky.png" -- "$bin" render "$d" -o "$work/sky.exr.out.exr" --png "$work/sky.png" --integrator path --width 48 --spp 4 --env "$work/sky.exr" --env-rotation 45 --env-intensity 2
  expect 0 "penumbra:integrator: \"path\"" -- oiiotool --info -v "$work/p.exr"
  # --debug-pixel replays exactly the pixel of the full render.
  "$bin" render "$d" -o "$work/dp.exr" --integrator path --width 48 --spp 4 --filter box --no-png --float -q >/dev/null
  want=$(oiiotool "$work/dp.exr" --cut 1x1+20+14 --printstats 2>/dev/null | awk '/Stats Avg/ {print $3}')
  got=$("$bin" render "$d" -o "$work/dp2.exr" --integrator path --width 48 --spp 4 --filter box --debug-pixel 20,14 | awk '{print $4}')
  if awk -v a="$want" -v b="$got" 'BEGIN {d = a - b; exit !(a > 0 && d * d <= 1e-10 * a * a)}'; then passes=$((passes + 1));
  else echo "FAIL: --debug-pixel 20,14 gave R $got, the render has $want"; fails=$((fails + 1)); fi
fi
expect 0 "filmic.png" -- "$bin" render "$d" -o "$work/filmic.exr" --png "$work/filmic.png" --view Filmic --look "High Contrast" --width 48 --spp 1 -q
# Interrupt and resume: SIGINT ends the render after a whole pass, writes the finished passes
# and the resume state; --resume completes it to exactly the uninterrupted image.
ra=(render "$d" --integrator path --width 16 --height 9 --spp 2048 --float --no-png)
expect 0 "whole-r.exr" -- "$bin" "${ra[@]}" -o "$work/whole-r.exr" -q
"$bin" "${ra[@]}" -o "$work/int.exr" >"$work/out" 2>"$work/err" &
pid=$!
# Interrupt once rendering has started (the first progress line), not during start-up.
for _ in $(seq 200); do grep -q "^render" "$work/err" 2>/dev/null && break; sleep 0.05; done
kill -INT $pid 2>/dev/null
wait $pid; rc=$?
if [ -e "$work/int.exr.resume" ]; then  # interrupted in time (a very fast machine may finish first)
  if [ "$rc" -eq 130 ] && grep -q "interrupted by signal 2" "$work/err" && [ -e "$work/int.exr" ]; then passes=$((passes + 1));
  else echo "FAIL: interrupted render: exit $rc"; sed 's/^/  | /' "$work/err" | tail -3; fails=$((fails + 1)); fi
  expect 2 "int.exr.resume: was written for other settings" -- "$bin" "${ra[@]}" -o "$work/int.exr" --resume --seed 7
  expect 0 "resuming" -- "$bin" "${ra[@]}" -o "$work/int.exr" --resume
  [ ! -e "$work/int.exr.resume" ] || { echo "FAIL: a completed resume left its state file"; fails=$((fails + 1)); }
else
  echo "note: the render finished before the interrupt; resume not exercised"
fi
if command -v oiiotool >/dev/null; then
  expect 0 "PASS" -- oiiotool "$work/whole-r.exr" "$work/int.exr" --fail 0 --diff
fi
expect 0 "cp.exr" -- "$bin" render "$d" -o "$work/cp.exr" --integrator path --width 16 --spp 64 --checkpoint 0.000001 --no-png -q
[ ! -e "$work/cp.exr.resume" ] || { echo "FAIL: a completed checkpointed render left its state file"; fails=$((fails + 1)); }
expect 2 "--resume needs --integrator path" -- "$bin" render "$d" -o "$work/cp.exr" --resume
expect 0 "st.exr" -- "$bin" render "$d" -o "$work/st.exr" --integrator path --width 16 --spp 4 --no-png -q --stats-json "$work/st.json"
json_field() {  # json_field FILE PYTHON-EXPRESSION-OVER-j: prints the value
  python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))' "$1" "$2"
}
expect 0 '^camera 576 shadow [0-9]+ bounce [0-9]+$' -- json_field "$work/st.json" '"camera %d shadow %d bounce %d" % (j["rays"]["camera"], j["rays"]["shadow"], j["rays"]["bounce"])'
expect 0 '^True$' -- json_field "$work/st.json" 'all(isinstance(j["seconds"][k], float) and j["seconds"][k] >= 0 for k in ("load", "build", "render", "write"))' 
expect 2 "--stats-json .*nodir" -- "$bin" render "$d" -o "$work/st.exr" --stats-json "$work/nodir/s.json"
# AOVs: names, refusals, the layers and metadata as compositors read them (oiiotool, exrheader).
expect 2 "unknown AOV 'depth' \(known: albedo, N, P, Z, UV, id, samples, variance, light, halves, cost, crypto_object, crypto_material, crypto_asset, vector, velocity, all\)" -- "$bin" render "$d" -o "$work/v.exr" --aov depth
expect 2 "--aov samples needs --integrator path" -- "$bin" render "$d" -o "$work/v.exr" --aov albedo,samples
expect 0 "wa.exr" -- "$bin" render "$d" -o "$work/wa.exr" --width 48 --spp 2 --aov all -q --no-png
expect 0 "pa.exr" -- "$bin" render "$d" -o "$work/pa.exr" --integrator path --width 48 --spp 4 --aov all -q --no-png
if command -v oiiotool >/dev/null; then
  expect 0 "R \(half\), G \(half\), B \(half\), A \(half\), Z \(float\), CryptoAsset00.R \(float\)" -- oiiotool --info -v "$work/wa.exr"
  for layer in "albedo.R (half)" "P.Z (float)" "UV.V (float)" "object_id.X (float)" "material_id.X (float)" "CryptoObject02.A (float)" \
               "CryptoMaterial00.R (float)"; do
    expect 0 "$(printf '%s' "$layer" | sed 's/[()]/\\&/g')" -- oiiotool --info -v "$work/wa.exr"
  done
  for layer in "samples.X (float)" "variance.X (float)" "emission.R (half)" "diffuse_direct.G (half)" "diffuse_indirect.B (half)" \
               "specular_direct.R (half)" "specular_indirect.G (half)"; do
    expect 0 "$(printf '%s' "$layer" | sed 's/[()]/\\&/g')" -- oiiotool --info -v "$work/pa.exr"
  done
  expect 0 'penumbra:manifest: ".*"object": \{"1": "floor"' -- oiiotool --info -v "$work/pa.exr"
  expect 0 "penumbra:command_line: .*--aov all" -- oiiotool --info -v "$work/pa.exr"
fi
if command -v exrheader >/dev/null; then
  expect 0 "worldToCamera \(type m44f\)" -- exrheader "$work/wa.exr"
  expect 0 "worldToNDC \(type m44f\)" -- exrheader "$work/wa.exr"
  expect 0 "object_id.X, 32-bit floating-point" -- exrheader "$work/wa.exr"
  expect 0 "penumbra:yfov_degrees \(type float\)" -- exrheader "$work/wa.exr"
fi
# Farm tiles and crops: data windows, and `merge` reassembles the frame exactly.
expect 2 "--crop and --tile exclude each other" -- "$bin" render "$d" -o "$work/t.exr" --crop 0 10 0 10 --tile 0/2
expect 2 "--tile: expected i/N" -- "$bin" render "$d" -o "$work/t.exr" --tile 3/3
expect 2 "--crop: empty region" -- "$bin" render "$d" -o "$work/t.exr" --crop 10 10 0 5
expect 2 "--crop: fraction 1.5 is outside" -- "$bin" render "$d" -o "$work/t.exr" --crop 0 1.5 0 5
expect 2 "--aov cost renders the whole frame" -- "$bin" render "$d" -o "$work/t.exr" --crop 0 10 0 5 --aov cost
tiles=()
for i in 0 1 2; do
  expect 0 "tile$i.exr" -- "$bin" render "$d" -o "$work/tile$i.exr" --integrator path --width 48 --spp 2 --aov all --tile $i/3 -q --no-png
  tiles+=("$work/tile$i.exr")
done
expect 0 "whole.exr" -- "$bin" render "$d" -o "$work/whole.exr" --integrator path --width 48 --spp 2 --aov all -q --no-png
expect 0 "merged.exr" -- "$bin" merge "${tiles[@]}" -o "$work/merged.exr"
expect 2 "merged.png: the output must be an .exr" -- "$bin" merge "${tiles[@]}" -o "$work/merged.png"
expect 2 "directory .*nodir' does not exist" -- "$bin" merge "${tiles[@]}" -o "$work/nodir/m.exr"
expect 2 "pixel 0,9 is missing" -- "$bin" merge "$work/tile0.exr" "$work/tile2.exr" -o "$work/gap.exr"
[ ! -e "$work/gap.exr" ] || { echo "FAIL: a refused merge wrote gap.exr"; fails=$((fails + 1)); }
# Multi-part: one part per layer, data parts lossless under a lossy codec; tiles merge exactly.
mp=(render "$d" --integrator path --width 40 --spp 2 --aov all -q --no-png --multipart)
expect 0 "mp.exr" -- "$bin" "${mp[@]}" -o "$work/mp.exr"
for i in 0 1; do expect 0 "mp$i.exr" -- "$bin" "${mp[@]}" -o "$work/mp$i.exr" --tile $i/2; done
expect 0 "mpm.exr" -- "$bin" merge "$work/mp0.exr" "$work/mp1.exr" -o "$work/mpm.exr"
expect 0 "mpd.exr" -- "$bin" "${mp[@]}" -o "$work/mpd.exr" --compression dwaa
if command -v oiiotool >/dev/null; then
  expect 0 "24 subimages" -- oiiotool --info "$work/mp.exr"
  for k in 0 2 6 13 23; do expect 0 "PASS" -- oiiotool -a "$work/mp.exr" --subimage $k "$work/mpm.exr" --subimage $k --fail 0 --diff; done
fi
if command -v exrheader >/dev/null; then
  expect 0 'name \(type string\): "rgba"' -- exrheader "$work/mp.exr"
  expect 0 'name \(type string\): "object_id"' -- exrheader "$work/mp.exr"
  # Under dwaa the beauty part is lossy, the N part stays zip.
  expect 0 'dwa, small scanline blocks' -- exrheader "$work/mpd.exr"
  expect 0 'zip, multi-scanline blocks[[:space:]]+name \(type string\): "N"' -- bash -c "exrheader '$work/mpd.exr' | grep -E 'compression|^name' | tr '\n' ' '"
fi
expect 0 "crop.exr" -- "$bin" render "$d" -o "$work/crop.exr" --crop 0.25 0.75 3 20 --width 48 --spp 2 -q --no-png
if command -v oiiotool >/dev/null; then
  expect 0 "PASS" -- oiiotool "$work/whole.exr" "$work/merged.exr" --fail 0 --diff
  expect 0 "pixel data origin: x=0, y=9" -- oiiotool --info -v "$work/tile1.exr"
  expect 0 "full/display size: 48 x 27" -- oiiotool --info -v "$work/crop.exr"
  expect 0 "pixel data origin: x=12, y=3" -- oiiotool --info -v "$work/crop.exr"
fi
[ -z "$(ls -A "$work" | grep '\.tmp-')" ] || { echo "FAIL: temporaries left behind"; fails=$((fails + 1)); }

# Hostile files from the shared corpus (skipped visibly without it).
if [ -d "$corpus/invalid" ]; then
  expect 2 "nodes\[0\]: is part of a node cycle" -- "$bin" render "$corpus/invalid/validator/base/node/node_loop.gltf" -o "$work/x.exr"
  expect 2 "cameras\[0\]: orthographic.ymag" -- "$bin" info "$corpus/invalid/validator/base/camera/orthographic_xy.gltf"
  expect 2 "GLB" -- "$bin" render "$corpus/invalid/validator/base/glb/length_mismatch.glb" -o "$work/x.exr"
  expect 0 "m.exr" -- "$bin" render "$corpus/valid/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf" -o "$work/m.exr" --width 32
  expect 0 "lines        19 segments" -- "$bin" info "$corpus/valid/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf"
  expect 0 "points       7 " -- "$bin" info "$corpus/valid/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf"
  # --camera by name picks the same instance as by index (the second camera is orthographic).
  cams="$corpus/valid/Cameras/glTF/Cameras.gltf"
  expect 0 "cam1.exr" -- "$bin" render "$cams" -o "$work/cam1.exr" --camera 1 --width 48 --spp 1 -q --no-png
  expect 0 "camn.exr" -- "$bin" render "$cams" -o "$work/camn.exr" --camera "cameras[1]" --width 48 --spp 1 -q --no-png
  expect 0 "cam0.exr" -- "$bin" render "$cams" -o "$work/cam0.exr" --camera "cameras[0]" --width 48 --spp 1 -q --no-png
  if command -v oiiotool >/dev/null; then
    expect 0 "PASS" -- oiiotool "$work/cam1.exr" "$work/camn.exr" --fail 0 --diff
    expect 1 "FAILURE" -- oiiotool "$work/cam0.exr" "$work/camn.exr" --fail 0.01 --diff
  fi
  [ ! -e "$work/x.exr" ] || { echo "FAIL: an error left $work/x.exr"; fails=$((fails + 1)); }
else
  echo "PENUMBRA_SKIP: corpus checks skipped ($corpus not found)"
fi

echo "cli: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
