#!/usr/bin/env bash
# `penumbra render --frames` end to end on a generated glTF (a cube moved by a translation
# animation, seen by a fixed camera): `#` patterns name each frame's files; every frame's pixels
# equal a separate --frame render of it (compared with idiff: the EXR metadata records each
# command line, so the files differ in that attribute), with the loaded scene reused and its
# instances moved (the frame's line says so), also with the camera animated too, with
# Penumbra's own BVH, with only the camera animated (the structure kept as it is), with
# vertices animated by a morph target (the BVH refitted), and on the shipped fly-through; --skip-existing keeps complete frames
# untouched and renders again exactly the missing and the truncated ones; a scene without
# animations is loaded once and gives the same frames; a --tile stripe is skipped like a frame;
# bad ranges and patterns exit 2 before anything is written.
# Usage: frames_test.sh PENUMBRA_BINARY WORK_DIR
set -u
bin="$1"; work="$2"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0

# expect CODE PATTERN -- command...: counts a pass or a failure in $passes / $fails.
source "$(dirname "$0")/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
for tool in python3 idiff; do
  command -v "$tool" >/dev/null || { echo "PENUMBRA_SKIP: $tool is not installed"; exit 0; }
done

python3 - "$work/anim.gltf" "$work/camera.gltf" "$work/camera-only.gltf" <<'PY'
import base64, json, struct, sys
pos = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
idx = [i for a, b, c, d in quads for i in (a, b, c, a, c, d)]
times = [0.0, 0.25]
moves = [(-1.0, 0.0, 0.0), (1.0, 0.0, 0.0)]
blob = b"".join(struct.pack("<3f", *p) for p in pos) + struct.pack("<36H", *idx)
blob += b"\0" * (-len(blob) % 4)
t_off = len(blob)
blob += struct.pack("<2f", *times) + b"".join(struct.pack("<3f", *m) for m in moves)
eyes = [(0.0, 0.0, 5.0), (1.5, 1.0, 4.0)]
turns = [(0.0, 0.0, 0.0, 1.0), (-0.1, 0.15, 0.0, 0.983)]
blob += b"".join(struct.pack("<3f", *e) for e in eyes) + b"".join(struct.pack("<4f", *q) for q in turns)
views = [(0, 96), (96, 72), (t_off, 8), (t_off + 8, 24), (t_off + 32, 24), (t_off + 56, 32)]
gltf = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"mesh": 0, "translation": [-1, 0, 0]}, {"camera": 0, "translation": [0, 0, 5]}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.0}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "animations": [{"samplers": [{"input": 2, "output": 3, "interpolation": "LINEAR"}],
                    "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}],
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in views],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
         "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
        {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
        {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0.0], "max": [0.25]},
        {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"},
        {"bufferView": 4, "componentType": 5126, "count": 2, "type": "VEC3"},
        {"bufferView": 5, "componentType": 5126, "count": 2, "type": "VEC4"}],
}
json.dump(gltf, open(sys.argv[1], "w"))
# The same cube, and the camera moved and turned by channels of its own.
anim = gltf["animations"][0]
anim["samplers"] += [{"input": 2, "output": 4, "interpolation": "LINEAR"},
                     {"input": 2, "output": 5, "interpolation": "LINEAR"}]
anim["channels"] += [{"sampler": 1, "target": {"node": 1, "path": "translation"}},
                     {"sampler": 2, "target": {"node": 1, "path": "rotation"}}]
json.dump(gltf, open(sys.argv[2], "w"))
# Only the camera moves: the cube's channel removed.
del anim["channels"][0]
json.dump(gltf, open(sys.argv[3], "w"))
PY
scene="$work/anim.gltf"
common=(--width 32 --spp 1 --no-png)

# The range: three frames, named by the pattern.
expect 0 "frames 1-3: 3 rendered, 0 skipped" -- "$bin" render "$scene" --frames 1-3 -o "$work/f.####.exr" "${common[@]}"
for n in 1 2 3; do
  [ -f "$work/f.000$n.exr" ] || fail "--frames 1-3 did not write $work/f.000$n.exr"
done
[ -e "$work/f.####.exr" ] && fail "the pattern was written literally"

# Each frame equals its own --frame render, and the frames differ (the cube moves).
for n in 1 2 3; do
  expect 0 "single.$n.exr" -- "$bin" render "$scene" --frame "$n" -o "$work/single.$n.exr" "${common[@]}"
  expect 0 "PASS" -- idiff -a "$work/f.000$n.exr" "$work/single.$n.exr"
done
idiff -a "$work/f.0001.exr" "$work/f.0003.exr" >/dev/null 2>&1 && fail "frames 1 and 3 have equal pixels"

# Only instances move: later frames reuse the loaded scene and move the cube's instance. At
# frame 3 (t = 0.125) the cube passes through the origin, an identity placement, so the structure
# is built again rather than updated; the pixels are the same either way.
expect 0 "frame 2 \(2 of 3\) -> .*m.0002.exr \(animated scene: loaded scene reused, instances moved, top level rebuilt\)" -- "$bin" render "$scene" --frames 1-3 -o "$work/m.####.exr" "${common[@]}"
grep -qE "frame 3 \(3 of 3\) -> .*m.0003.exr \(animated scene: loaded scene reused, instances moved, acceleration structure rebuilt\)" "$work/err" || fail "frame 3 did not say the structure was rebuilt"
grep -qE "frame 1 \(1 of 3\) -> .*m.0001.exr$" "$work/err" || fail "frame 1 did not load the scene"

# The camera moves too: each frame sees the cube from its own camera, as --frame does; the
# same with Penumbra's own BVH (its two-level wrapper moves the instance).
for accel in embree bvh; do
  expect 0 "frame 2 \(2 of 3\) -> .*c.$accel.0002.exr \(animated scene: loaded scene reused, instances moved, top level rebuilt\)" -- "$bin" render "$work/camera.gltf" --frames 1-3 -o "$work/c.$accel.####.exr" --accel "$accel" "${common[@]}"
  for n in 1 2 3; do
    expect 0 "cs.$accel.$n.exr" -- "$bin" render "$work/camera.gltf" --frame "$n" -o "$work/cs.$accel.$n.exr" --accel "$accel" "${common[@]}"
    expect 0 "PASS" -- idiff -a "$work/c.$accel.000$n.exr" "$work/cs.$accel.$n.exr"
  done
done
idiff -a "$work/c.embree.0002.exr" "$work/f.0002.exr" >/dev/null 2>&1 && fail "the moving camera sees what the still one sees"

# The shipped fly-through: still meshes (in world space, and instanced walls) beside the turning
# box and the flying camera; with Embree the still placements sit in a scene of their own.
fly="$(cd "$(dirname "$0")/../.." && pwd)/scenes/flythrough.gltf"
expect 0 "frame 60 \(2 of 2\) -> .*fly.0060.exr \(animated scene: loaded scene reused, instances moved, top level rebuilt\)" -- "$bin" render "$fly" --frames 30-60:30 -o "$work/fly.####.exr" "${common[@]}"
for n in 30 60; do
  expect 0 "flys.$n.exr" -- "$bin" render "$fly" --frame "$n" -o "$work/flys.$n.exr" "${common[@]}"
  expect 0 "PASS" -- idiff -a "$work/fly.00$n.exr" "$work/flys.$n.exr"
done

# Only the camera moves: the acceleration structure is kept as it is.
expect 0 "frame 3 \(3 of 3\) -> .*o.0003.exr \(animated scene: loaded scene reused, cameras and lights moved, acceleration structure reused\)" -- "$bin" render "$work/camera-only.gltf" --frames 1-3 -o "$work/o.####.exr" "${common[@]}"
for n in 1 3; do
  expect 0 "os.$n.exr" -- "$bin" render "$work/camera-only.gltf" --frame "$n" -o "$work/os.$n.exr" "${common[@]}"
  expect 0 "PASS" -- idiff -a "$work/o.000$n.exr" "$work/os.$n.exr"
done

# Vertices animated (a morph target lifts the cube's top face): posing cannot move vertices, so
# each later frame loads the file at its time and refits the previous frame's BVH to it (built
# anew when refitting is off, and by the back ends that do not refit); every frame's pixels
# equal its --frame render, whose BVH is built from scratch.
python3 - "$scene" "$work/morph.gltf" <<'PY'
import base64, json, struct, sys
g = json.load(open(sys.argv[1]))
blob = base64.b64decode(g["buffers"][0]["uri"].split(",", 1)[1])
blob += b"\0" * (-len(blob) % 4)
lift = [(0.0, 0.7 if y > 0 else 0.0, 0.0) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
d_off = len(blob)
blob += b"".join(struct.pack("<3f", *d) for d in lift)
w_off = len(blob)
blob += struct.pack("<2f", 0.0, 1.0)
g["buffers"][0] = {"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}
g["bufferViews"] += [{"buffer": 0, "byteOffset": d_off, "byteLength": 96}, {"buffer": 0, "byteOffset": w_off, "byteLength": 8}]
n = len(g["accessors"])
g["accessors"] += [{"bufferView": len(g["bufferViews"]) - 2, "componentType": 5126, "count": 8, "type": "VEC3",
                    "min": [0, 0, 0], "max": [0, 0.7, 0]},
                   {"bufferView": len(g["bufferViews"]) - 1, "componentType": 5126, "count": 2, "type": "SCALAR"}]
g["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": n}]
g["meshes"][0]["weights"] = [0.0]
g["nodes"][0]["translation"] = [0, -0.3, 0]
g["animations"] = [{"samplers": [{"input": 2, "output": n + 1, "interpolation": "LINEAR"}],
                    "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}]
json.dump(g, open(sys.argv[2], "w"))
PY
morph="$work/morph.gltf"
expect 0 "frame 2 \(2 of 3\) -> .*v.0002.exr \(animated vertices: scene loaded anew, acceleration structure refitted or rebuilt\)" -- "$bin" render "$morph" --frames 1-3 -o "$work/v.####.exr" --accel bvh --stats-json "$work/v.####.json" "${common[@]}"
[ "$(grep -c 'refitted bvh (SAH cost [0-9.]*x its last build' "$work/err")" = 2 ] || fail "frames 2 and 3 did not refit the BVH"
grep -q '"accelerator_update": "refitted"' "$work/v.0003.json" || fail "frame 3's statistics do not say the BVH was refitted"
grep -q '"accelerator_update": "built"' "$work/v.0001.json" || fail "frame 1's statistics do not say the BVH was built"
for n in 1 2 3; do
  expect 0 "vs.$n.exr" -- "$bin" render "$morph" --frame "$n" -o "$work/vs.$n.exr" --accel bvh "${common[@]}"
  expect 0 "PASS" -- idiff -a "$work/v.000$n.exr" "$work/vs.$n.exr"
done
idiff -a "$work/v.0001.exr" "$work/v.0003.exr" >/dev/null 2>&1 && fail "the morph target did not change the pixels"
expect 0 "rebuilt bvh \(refitting is off \(bvh.refit_max_growth=0\)\)" -- "$bin" render "$morph" --frames 1-2 -o "$work/r.####.exr" --accel bvh --accel-param bvh.refit_max_growth=0 "${common[@]}"
expect 0 "PASS" -- idiff -a "$work/r.0002.exr" "$work/vs.2.exr"
expect 0 "rebuilt kdtree \(the kdtree back end does not refit\)" -- "$bin" render "$morph" --frames 1-2 -o "$work/k.####.exr" --accel kdtree "${common[@]}"
expect 2 "refit_max_growth must be 0 or in \[1, 1000\], got 0.5" -- "$bin" render "$morph" --frames 1-2 -o "$work/k.####.exr" --accel bvh --accel-param bvh.refit_max_growth=0.5 "${common[@]}"

# A scene without animations is loaded and built once; its frames equal a --frame render.
python3 -c 'import json,sys; g=json.load(open(sys.argv[1])); del g["animations"]; json.dump(g, open(sys.argv[2], "w"))' "$scene" "$work/static.gltf"
expect 0 "frame 3 \(3 of 3\) -> .*static.0003.exr \(static scene: loaded scene and acceleration structure reused\)" -- "$bin" render "$work/static.gltf" --frames 1-3 -o "$work/static.####.exr" "${common[@]}"
expect 0 "static.1.exr" -- "$bin" render "$work/static.gltf" --frame 1 -o "$work/static.1.exr" "${common[@]}"
for n in 1 2 3; do
  expect 0 "PASS" -- idiff -a "$work/static.000$n.exr" "$work/static.1.exr"
done

# --frame with a pattern substitutes its number; a step skips frames; negative frames keep a sign.
expect 0 "one.0002.exr" -- "$bin" render "$scene" --frame 2 -o "$work/one.####.exr" "${common[@]}"
expect 0 "PASS" -- idiff -a "$work/one.0002.exr" "$work/single.2.exr"
expect 0 "2 rendered" -- "$bin" render "$scene" --frames 1-3:2 -o "$work/s.##.exr" "${common[@]}"
[ -f "$work/s.01.exr" ] && [ -f "$work/s.03.exr" ] && [ ! -e "$work/s.02.exr" ] || fail "--frames 1-3:2 wrote the wrong frames"
expect 0 "n.-01.exr" -- "$bin" render "$scene" --frames -1 -o "$work/n.###.exr" "${common[@]}"

# --skip-existing: nothing to do on a complete range; the files stay untouched.
sha() { sha256sum "$work"/f.000[123].exr; }
before="$(sha)"
touch -d '2001-01-01' "$work"/f.000[123].exr
expect 0 "frames 1-3: 0 rendered, 3 skipped" -- "$bin" render "$scene" --frames 1-3 -o "$work/f.####.exr" "${common[@]}" --skip-existing
[ "$(sha)" = "$before" ] || fail "--skip-existing changed complete frames"
[ -n "$(find "$work" -name 'f.000[123].exr' -newermt '2001-01-02')" ] && fail "--skip-existing rewrote a complete frame"

# A deleted and a truncated frame are rendered again, with a warning for the truncated one.
rm "$work/f.0001.exr"
size=$(stat -c %s "$work/f.0003.exr")
truncate -s $((size / 2)) "$work/f.0003.exr"
expect 0 "frames 1-3: 2 rendered, 1 skipped" -- "$bin" render "$scene" --frames 1-3 -o "$work/f.####.exr" "${common[@]}" --skip-existing
grep -q "warning: frame 3: .*f.0003.exr" "$work/err" || fail "no warning for the truncated frame 3"
grep -q "frame 1 (1 of 3)" "$work/err" || fail "frame 1 was not rendered again"
[ -n "$(find "$work" -name 'f.0002.exr' -newermt '2001-01-02')" ] && fail "the complete frame 2 was rewritten"
for n in 1 3; do
  expect 0 "PASS" -- idiff -a "$work/f.000$n.exr" "$work/single.$n.exr"
done
# A --tile stripe's EXR counts as complete too.
expect 0 "t.0002.exr" -- "$bin" render "$scene" --frames 2 --tile 0/2 -o "$work/t.####.exr" "${common[@]}"
expect 0 "frames 2: 0 rendered, 1 skipped" -- "$bin" render "$scene" --frames 2 --tile 0/2 -o "$work/t.####.exr" "${common[@]}" --skip-existing
expect 0 "replace existing" -- "$bin" render --help
expect 0 "frames 1-1: 1 rendered" -- "$bin" render "$scene" --frames 1-1 -o "$work/f.####.exr" "${common[@]}" --overwrite

# Bad input exits 2 with the reason, before any file is written.
rm -rf "$work/bad"; mkdir "$work/bad"
expect 2 "is empty: the last frame comes before the first" -- "$bin" render "$scene" --frames 5-2 -o "$work/bad/b.####.exr" "${common[@]}"
expect 2 "the step must be an integer >= 1" -- "$bin" render "$scene" --frames 1-3:0 -o "$work/bad/b.####.exr" "${common[@]}"
expect 2 "needs a run of '#' in -o" -- "$bin" render "$scene" --frames 1-3 -o "$work/bad/out.exr" "${common[@]}"
expect 2 "needs a run of '#' in --stats-json" -- "$bin" render "$scene" --frames 1-3 -o "$work/bad/b.####.exr" --stats-json "$work/bad/s.json" "${common[@]}"
expect 2 "'x' is not a frame range" -- "$bin" render "$scene" --frames x -o "$work/bad/b.####.exr" "${common[@]}"
expect 2 "more than 100000" -- "$bin" render "$scene" --frames 1-100001 -o "$work/bad/b.####.exr" "${common[@]}"
expect 2 "frame numbers must lie within" -- "$bin" render "$scene" --frames 1-99999999999999999999 -o "$work/bad/b.####.exr" "${common[@]}"
expect 2 "excludes" -- "$bin" render "$scene" --frames 1-3 --frame 2 -o "$work/bad/b.####.exr" "${common[@]}"
expect 2 "excludes" -- "$bin" render "$scene" --frames 1-3 --time 0.5 -o "$work/bad/b.####.exr" "${common[@]}"
expect 2 "excludes" -- "$bin" render "$scene" --frames 1-3 --skip-existing --overwrite -o "$work/bad/b.####.exr" "${common[@]}"
expect 2 "'#' in -o needs --frame or --frames" -- "$bin" render "$scene" -o "$work/bad/b.####.exr" "${common[@]}"
[ -z "$(ls -A "$work/bad")" ] || fail "a refused run wrote $(ls -A "$work/bad")"

echo "frames: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
