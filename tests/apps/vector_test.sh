#!/usr/bin/env bash
# `penumbra render --aov vector` end to end on a generated glTF (a 2 x 2 quad moved along +x by
# a translation animation at 1.5 units per second, seen by a still camera 5 units away): the EXR
# holds vector.X, .Y, .Z, .W; on the quad X and Z equal minus the displacement of one frame in
# pixels (computed here from the pinhole formula) for each integrator, twice as large at half
# the --fps, and the same with --motion-blur; Y and W are 0; the background is 0; a render
# without --time or --frame warns and writes zeros; the velocity layer beside it holds the quad's
# camera-space velocity; a turntable's vectors reproject the still quad through its neighbouring
# orbits; --help lists both layers.
# Usage: vector_test.sh PENUMBRA_BINARY WORK_DIR
set -u
bin="$1"; work="$2"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0

# expect CODE PATTERN -- command...: counts a pass or a failure in $passes / $fails.
source "$(dirname "$0")/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
for tool in python3 oiiotool; do
  command -v "$tool" >/dev/null || { echo "PENUMBRA_SKIP: $tool is not installed"; exit 0; }
done

python3 - "$work/slide.gltf" <<'PY'
import base64, json, struct, sys
pos = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
blob = b"".join(struct.pack("<3f", *p) for p in pos) + struct.pack("<6H", 0, 1, 2, 0, 2, 3)
blob += b"\0" * (-len(blob) % 4)
t_off = len(blob)
blob += struct.pack("<2f", 0.0, 2.0) + struct.pack("<6f", 0, 0, 0, 3, 0, 0)
gltf = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5]}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "animations": [{"samplers": [{"input": 2, "output": 3, "interpolation": "LINEAR"}],
                    "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}],
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 48, "byteLength": 12},
                    {"buffer": 0, "byteOffset": t_off, "byteLength": 8},
                    {"buffer": 0, "byteOffset": t_off + 8, "byteLength": 24}],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
        {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0.0], "max": [2.0]},
        {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}],
}
json.dump(gltf, open(sys.argv[1], "w"))
PY

# The mean of channel $2 of $1 over the 4 x 4 pixels at $3,$4 (oiiotool's statistics).
mean() {
  oiiotool "$1" --ch "$2" --cut "4x4+$3+$4" --printstats 2>/dev/null | sed -n 's/.*Avg: *\([0-9.e+-]*\).*/\1/p' | head -1
}
# near A B: |A - B| < 0.01
near() { python3 -c "import sys; sys.exit(0 if abs(float('$1') - float('$2')) < 0.01 else 1)"; }

# At time 1 the quad spans x in [0.5, 2.5]: pixels 34..37, 14..17 lie on it; 2..5, 2..5 do not.
# One frame moves it 1.5 / fps units, H / (2 * 5 * tan(0.4)) pixels per unit at depth 5.
step() { python3 -c "import math; print(1.5 / $1 * 32 / (10 * math.tan(0.4)))"; }
for integrator in whitted path raster; do
  exr="$work/$integrator.exr"
  expect 0 "" -- "$bin" render "$work/slide.gltf" -o "$exr" --width 48 --height 32 --spp 1 --accel bvh \
    --integrator "$integrator" --frame 24 --aov vector
  header=$(oiiotool --info -v "$exr" 2>/dev/null)
  for c in X Y Z W; do
    grep -q "vector\.$c" <<<"$header" || fail "$integrator: no channel vector.$c"
  done
  want=$(python3 -c "print(-$(step 24))")
  for c in X Z; do
    got=$(mean "$exr" "vector.$c" 34 14)
    near "$got" "$want" && passes=$((passes + 1)) || fail "$integrator: vector.$c on the quad is $got, want $want"
  done
  for c in Y W; do
    got=$(mean "$exr" "vector.$c" 34 14)
    near "$got" 0 && passes=$((passes + 1)) || fail "$integrator: vector.$c on the quad is $got, want 0"
  done
  got=$(mean "$exr" vector.X 2 2)
  near "$got" 0 && passes=$((passes + 1)) || fail "$integrator: vector.X off the quad is $got, want 0"
done

# --fps 12 --frame 12 is the same time with frames twice as far apart.
expect 0 "" -- "$bin" render "$work/slide.gltf" -o "$work/fps12.exr" --width 48 --height 32 --spp 1 --accel bvh \
  --frame 12 --fps 12 --aov vector
want=$(python3 -c "print(-$(step 12))")
got=$(mean "$work/fps12.exr" vector.X 34 14)
near "$got" "$want" && passes=$((passes + 1)) || fail "--fps 12: vector.X is $got, want $want"

# With motion blur the layer is the same: the centre ray meets the scene at the frame's time.
expect 0 "" -- "$bin" render "$work/slide.gltf" -o "$work/blur.exr" --width 48 --height 32 --spp 2 --accel bvh \
  --frame 24 --aov vector --motion-blur
want=$(python3 -c "print(-$(step 24))")
got=$(mean "$work/blur.exr" vector.X 34 14)
near "$got" "$want" && passes=$((passes + 1)) || fail "--motion-blur: vector.X is $got, want $want"

# The velocity layer beside it: the quad's camera-space velocity, 1.5 units per second along +x.
expect 0 "" -- "$bin" render "$work/slide.gltf" -o "$work/velocity.exr" --width 48 --height 32 --spp 1 \
  --accel bvh --frame 24 --aov vector,velocity
header=$(oiiotool --info -v "$work/velocity.exr" 2>/dev/null)
for c in X Y Z; do
  grep -q "velocity\.$c" <<<"$header" || fail "no channel velocity.$c"
done
for pair in X:1.5 Y:0 Z:0; do
  c=${pair%%:*}; want=${pair#*:}
  got=$(mean "$work/velocity.exr" "velocity.$c" 34 14)
  near "$got" "$want" && passes=$((passes + 1)) || fail "velocity.$c on the quad is $got, want $want"
done
got=$(mean "$work/velocity.exr" velocity.X 2 2)
near "$got" 0 && passes=$((passes + 1)) || fail "velocity.X off the quad is $got, want 0"

# The static pose: a warning, and zeros.
expect 0 "vector layer.*static pose" -- "$bin" render "$work/slide.gltf" -o "$work/static.exr" --width 48 \
  --height 32 --spp 1 --aov vector
got=$(mean "$work/static.exr" vector.X 22 14)
near "$got" 0 && passes=$((passes + 1)) || fail "static pose: vector.X is $got, want 0"

# A turntable's frames show one pose from an orbit turned 2 pi / N a frame: its vectors are
# the reprojection of the still quad (static pose, at the origin) through the orbit one frame
# before and after (azimuth -/+ 10 degrees at distance 5, --fov 45), computed here.
expect 0 "" -- "$bin" render "$work/slide.gltf" -o "$work/turn.exr" --width 48 --height 32 --spp 1 \
  --accel bvh --turntable 36 --orbit 0,0,5 --fov 45 --frame 0 --aov vector
turn_want() {  # channel X|Y|Z|W, block corner x y: the mean over the 4 x 4 pixels
  python3 - "$@" <<'PY'
import math, sys
ch, bx, by = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
W, H = 48, 32
ty = math.tan(math.radians(22.5)); tx = ty * W / H
def raster(p, az):
    eye = (5 * math.sin(az), 0, 5 * math.cos(az))
    u, w = (math.cos(az), 0, -math.sin(az)), (math.sin(az), 0, math.cos(az))
    d = [p[i] - eye[i] for i in range(3)]
    xc = sum(d[i] * u[i] for i in range(3)); depth = -sum(d[i] * w[i] for i in range(3))
    return ((xc / (depth * tx) + 1) * W / 2, (1 - d[1] / (depth * ty)) * H / 2)
total = 0
for y in range(by, by + 4):
    for x in range(bx, bx + 4):
        sx, sy = (x + 0.5) / W * 2 - 1, 1 - (y + 0.5) / H * 2
        p = (5 * tx * sx, 5 * ty * sy, 0)
        nx, ny = raster(p, 0)
        (px, py), (qx, qy) = raster(p, -math.radians(10)), raster(p, math.radians(10))
        total += {"X": px - nx, "Y": ny - py, "Z": nx - qx, "W": qy - ny}[ch]
print(total / 16)
PY
}
for block in "28 10" "18 19"; do
  for c in X Y Z W; do
    want=$(turn_want "$c" $block)
    got=$(mean "$work/turn.exr" "vector.$c" ${block% *} ${block#* })
    near "$got" "$want" && passes=$((passes + 1)) || fail "--turntable: vector.$c at $block is $got, want $want"
  done
done

expect 0 "vector" -- "$bin" render --help
expect 0 "velocity" -- "$bin" render --help

echo "$passes passed, $fails failed"
[ "$fails" -eq 0 ]
