#!/usr/bin/env bash
# `penumbra collide` end to end on a generated scene of unit cubes: A at the origin with a child
# half its size inside it, B overlapping A by 0.2 along x (and the child by 0.35), C far away, a
# thin wall, and a cube animated through the wall at constant speed:
# - the meshes' contacts are exactly (A, B) and (child, B); the parent-child pair is left out
#   (counted) unless --include-children; each contact point lies in both boxes; the depths
#   (closed meshes: the deepest surface point inside the other) are the x overlaps 0.2 and
#   0.35 within their stated sample spacing;
# - a skinned cube and a cube below its skin's joint, overlapping by 0.2: left out as joined
#   unless --include-children;
# - analytic shapes (a sphere and a box sharing 0.5 along x, a capsule apart) collide as their
#   tessellations, with the depth 0.5 within the sample spacing and the tessellation's error;
# - with --proxy obb (a cube's OBB is the cube) the penetration depths are 0.2 and 0.35;
# - over --frames 0-24 at 24 fps the moving cube meets the wall at exactly the frames where
#   their x extents overlap (10 to 14), with meshes and with proxies;
# - --volumes: A and B share 0.2 x 1 x 1, the child and B 0.35 x 0.5 x 0.5: exactly on boxes,
#   within the stated bound on the meshes;
# - with --continuous over frames 0 and 24 (both miss the wall), on meshes (exactly) and on
#   proxies, the mover's first contact with
#   the wall is at the analytic time: its face reaches x = -0.05 at t = 2.45 / 6 s (boxes); the
#   bounding spheres (radii sqrt(3) / 2 and sqrt(2.0025)) meet earlier; the still nodes are not
#   advanced; the text report names it;
# - bad input exits 2 naming the option: an unknown proxy kind, a bad k, a bad range or fps,
#   --continuous on one frame; --volumes on an open mesh names the file, the node
#   and an open edge.
# Usage: collide_test.sh PENUMBRA_BINARY WORK_DIR
set -u
bin="$1"; work="$2"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
source "$(dirname "$0")/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
py=/usr/bin/python3

scene="$work/cubes.gltf"
"$py" - "$scene" <<'PY'
import base64, json, struct, sys
v = [(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
f = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
idx = [i for q in f for i in (q[0], q[1], q[2], q[0], q[2], q[3])]
times, moves = [0.0, 1.0], [(-3, 0, 5), (3, 0, 5)]
blob = (b"".join(struct.pack("<3f", *p) for p in v) + struct.pack(f"<{len(idx)}I", *idx) +
        struct.pack("<2f", *times) + b"".join(struct.pack("<3f", *p) for p in moves))
views = [{"buffer": 0, "byteOffset": 0, "byteLength": 96}, {"buffer": 0, "byteOffset": 96, "byteLength": 144},
         {"buffer": 0, "byteOffset": 240, "byteLength": 8}, {"buffer": 0, "byteOffset": 248, "byteLength": 24}]
accessors = [{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [-0.5] * 3, "max": [0.5] * 3},
             {"bufferView": 1, "componentType": 5125, "count": 36, "type": "SCALAR"},
             {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
             {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}]
doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 2, 3, 4, 5]}],
       "nodes": [{"name": "A", "mesh": 0, "children": [1]},
                 {"name": "A child", "mesh": 0, "translation": [0.4, 0, 0], "scale": [0.5, 0.5, 0.5]},
                 {"name": "B", "mesh": 0, "translation": [0.8, 0, 0]},
                 {"name": "C", "mesh": 0, "translation": [10, 0, 0]},
                 {"name": "wall", "mesh": 0, "translation": [0, 0, 5], "scale": [0.1, 2, 2]},
                 {"name": "mover", "mesh": 0, "translation": [-3, 0, 5]}],
       "meshes": [{"name": "cube", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
       "animations": [{"samplers": [{"input": 2, "output": 3, "interpolation": "LINEAR"}],
                       "channels": [{"sampler": 0, "target": {"node": 5, "path": "translation"}}]}],
       "accessors": accessors, "bufferViews": views,
       "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]}
json.dump(doc, open(sys.argv[1], "w"))
PY

# check_json WHAT PYTHON-CHECK ARGS...: runs collide --json with ARGS and the check on its document `d`.
check_json() {
  local what="$1" check="$2"; shift 2
  if ! "$bin" collide "$scene" --json "$@" >"$work/c.json" 2>"$work/err"; then
    fail "$what: collide $* exited $?"; sed 's/^/  | /' "$work/err" | head -3; return
  fi
  if "$py" - "$work/c.json" "$check" <<'PY'; then passes=$((passes + 1)); else fail "$what"; fi
import json, sys
d = json.load(open(sys.argv[1]))
def pairs(frame): return [(c["a"], c["b"]) for c in frame["contacts"]]
def inside(p, centre, half): return all(abs(p[k] - centre[k]) <= half[k] + 1e-6 for k in range(3))
ok = eval(sys.argv[2])
if not ok: print("  document:", json.dumps(d)[:600], file=sys.stderr)
sys.exit(0 if ok else 1)
PY
}

# 1. The meshes at the static pose.
check_json "mesh contacts" 'pairs(d["frames"][0]) == [(0, 2), (1, 2)] and d["frames"][0]["family_pairs"] == 1'
check_json "mesh contacts with children" 'pairs(d["frames"][0]) == [(0, 1), (0, 2), (1, 2)] and d["frames"][0]["family_pairs"] == 0' --include-children
check_json "contact points in both boxes" 'all(inside(c["point"], [0, 0, 0], [0.5] * 3) and inside(c["point"], [0.8, 0, 0], [0.5] * 3) for c in d["frames"][0]["contacts"] if c["b"] == 2) and all(c["triangle_pairs"] > 0 for c in d["frames"][0]["contacts"])'
# Closed cubes: the deepest surface point inside the other is as deep as the x overlap.
check_json "mesh depths" 'all(want - c["depth_error"] <= c["depth"] <= want + 1e-6 and c["depth_error"] <= 0.03 for c, want in zip(d["frames"][0]["contacts"], (0.2, 0.35)))'
check_json "broad phase counts" 'd["frames"][0]["nodes"] == 6 and d["frames"][0]["broad_pairs"] == 3 and d["frames"][0]["narrow_tests"] == 2 and d["frames"][0]["frame"] is None'
# A skinned cube and a cube below its joint's child, overlapping it: a skin joins them.
skinned="$work/skinned.gltf"
"$py" - "$skinned" <<'PY'
import base64, json, struct, sys
v = [(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
f = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
idx = [i for q in f for i in (q[0], q[1], q[2], q[0], q[2], q[3])]
blob = (b"".join(struct.pack("<3f", *p) for p in v) + struct.pack(f"<{len(idx)}I", *idx) +
        bytes(32) + b"".join(struct.pack("<4f", 1, 0, 0, 0) for _ in v))
views = [{"buffer": 0, "byteOffset": 0, "byteLength": 96}, {"buffer": 0, "byteOffset": 96, "byteLength": 144},
         {"buffer": 0, "byteOffset": 240, "byteLength": 32}, {"buffer": 0, "byteOffset": 272, "byteLength": 128}]
accessors = [{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [-0.5] * 3, "max": [0.5] * 3},
             {"bufferView": 1, "componentType": 5125, "count": 36, "type": "SCALAR"},
             {"bufferView": 2, "componentType": 5121, "count": 8, "type": "VEC4"},
             {"bufferView": 3, "componentType": 5126, "count": 8, "type": "VEC4"}]
doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
       "nodes": [{"name": "body", "mesh": 1, "skin": 0},
                 {"name": "bone", "children": [2]},
                 {"name": "sword", "mesh": 0, "translation": [0.8, 0, 0]}],
       "skins": [{"joints": [1]}],
       "meshes": [{"name": "cube", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]},
                  {"name": "skinned cube", "primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 2, "WEIGHTS_0": 3}, "indices": 1}]}],
       "accessors": accessors, "bufferViews": views,
       "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]}
json.dump(doc, open(sys.argv[1], "w"))
PY
expect 0 "2 nodes, broad phase 1 pairs \(1 joined by the hierarchy or a skin, left out\), narrow phase 0 tests, 0 contacts" -- "$bin" collide "$skinned"
expect 0 "'body' \(0\) and 'sword' \(2\) at .*, depth 0.2" -- "$bin" collide "$skinned" --include-children

# Analytic shapes (PENUMBRA_shapes) collide as their tessellations: a unit sphere and a 2 x 2 x 2
# box at x = 1.5 share 0.5 along x; a capsule far away touches neither.
shapes="$work/shapes.gltf"
"$py" - "$shapes" <<'PY'
import json, sys
shape = lambda name, s, t: {"name": name, "translation": t, "extensions": {"PENUMBRA_shapes": s}}
doc = {"asset": {"version": "2.0"}, "extensionsUsed": ["PENUMBRA_shapes"], "scene": 0, "scenes": [{"nodes": [0, 1, 2]}],
       "nodes": [shape("ball", {"type": "sphere", "radius": 1}, [0, 0, 0]),
                 shape("crate", {"type": "box", "size": [2, 2, 2]}, [1.5, 0, 0]),
                 shape("pill", {"type": "capsule", "radius": 0.3, "height": 1.2}, [20, 0, 0])]}
json.dump(doc, open(sys.argv[1], "w"))
PY
scene_saved="$scene"; scene="$shapes"
check_json "analytic shapes" 'pairs(d["frames"][0]) == [(0, 1)] and d["frames"][0]["nodes"] == 3 and 0.5 - d["frames"][0]["contacts"][0]["depth_error"] - 0.01 <= d["frames"][0]["contacts"][0]["depth"] <= 0.51'
check_json "analytic shapes (boxes)" 'pairs(d["frames"][0]) == [(0, 1)] and abs(d["frames"][0]["contacts"][0]["depth"] - 0.5) < 0.01' --proxy aabb
scene="$scene_saved"

# 2. Oriented boxes of cubes are the cubes: exact penetration depths.
check_json "OBB depths" '[(c["a"], c["b"], round(c["depth"], 6)) for c in d["frames"][0]["contacts"]] == [(0, 2, 0.2), (1, 2, 0.35)] and all(abs(abs(c["direction"][0]) - 1) < 1e-9 for c in d["frames"][0]["contacts"])' --proxy obb
check_json "sphere proxies" 'pairs(d["frames"][0]) == [(0, 2), (1, 2)]' --proxy sphere
# Shared volumes.
check_json "volumes (obb)" '[(c["a"], c["b"], round(c["volume"], 6), c["volume_exact"]) for c in d["frames"][0]["contacts"]] == [(0, 2, 0.2, True), (1, 2, 0.0875, True)] and d["volumes"]' --proxy obb --volumes
check_json "volumes (meshes)" '[(c["a"], c["b"]) for c in d["frames"][0]["contacts"]] == [(0, 2), (1, 2)] and all(abs(c["volume"] - v) <= c["volume_error"] and c["volume_error"] < 0.1 * v and not c["volume_exact"] for c, v in zip(d["frames"][0]["contacts"], (0.2, 0.0875)))' --volumes
expect 0 "'A' \\(0\\) and 'B' \\(2\\) at .*, depth 0.2, volume 0.2 \\(exact\\)" -- "$bin" collide "$scene" --proxy aabb --volumes

# 3. The moving cube meets the wall at frames 10 to 14 of 0-24.
for proxy in mesh obb hull; do
  check_json "frames ($proxy)" '[f["frame"] for f in d["frames"] if (4, 5) in pairs(f)] == list(range(10, 15)) and len(d["frames"]) == 25 and all(pairs(f)[:2] == [(0, 2), (1, 2)] for f in d["frames"])' --frames 0-24 --proxy "$proxy"
done
expect 0 "frame 12 \(time 0.5 s\): 6 nodes, broad phase 4 pairs \(1 joined by the hierarchy or a skin, left out\), narrow phase 3 tests, 3 contacts" -- "$bin" collide "$scene" --frames 12
expect 0 "'A' \(0\) and 'B' \(2\) at .*, depth 0.2" -- "$bin" collide "$scene" --proxy aabb

# 4. Continuous detection between two frames that both miss the wall.
swept='d["frames"][0]["continuous"]'
check_json "continuous (obb)" "pairs($swept) == [(4, 5)] and abs($swept[\"contacts\"][0][\"time\"] - 2.45 / 6) < 1e-4 and pairs(d[\"frames\"][0]) == pairs(d[\"frames\"][1]) == [(0, 2), (1, 2)] and $swept[\"moving_nodes\"] == 1 and $swept[\"narrow_tests\"] == 1 and $swept[\"to_frame\"] == 24 and d[\"frames\"][1][\"continuous\"] is None and $swept[\"undecided\"] == []" --frames 0-24:24 --proxy obb --continuous
check_json "continuous (sphere)" "pairs($swept) == [(4, 5)] and abs($swept[\"contacts\"][0][\"time\"] - (3 - 3 ** 0.5 / 2 - 2.0025 ** 0.5) / 6) < 1e-4 and abs($swept[\"contacts\"][0][\"normal\"][0] + 1) < 1e-6" --frames 0-24:24 --proxy sphere --continuous
check_json "continuous over every frame" "[f[\"frame\"] for f in d[\"frames\"] if f[\"continuous\"] and pairs(f[\"continuous\"]) == [(4, 5)]] == list(range(9, 15))" --frames 0-24 --proxy hull --continuous
expect 0 "swept to frame 24: 6 nodes \\(1 moving, 0 not rigid, left out\\), broad phase 1 pairs" -- "$bin" collide "$scene" --frames 0-24:24 --proxy aabb --continuous
expect 0 "'wall' \\(4\\) and 'mover' \\(5\\) first touch at time 0.40833" -- "$bin" collide "$scene" --frames 0-24:24 --proxy aabb --continuous
# On the meshes: the exact time (the vertices move on straight lines, as the mover does).
check_json "continuous (meshes)" "pairs($swept) == [(4, 5)] and abs($swept[\"contacts\"][0][\"time\"] - 2.45 / 6) < 1e-9 and $swept[\"triangle_pairs\"] > 0 and abs($swept[\"contacts\"][0][\"point\"][0] + 0.05) < 1e-6" --frames 0-24:24 --continuous
expect 0 "swept to frame 24: 6 nodes \\(1 moving, 0 changing their triangles, left out\\), broad phase 1 pairs .* swept over [0-9]+ triangle pairs, 1 first contact" -- "$bin" collide "$scene" --frames 0-24:24 --continuous

# 5. Refusals.
expect 2 "--proxy cube: not mesh or a proxy kind \(mesh, sphere" -- "$bin" collide "$scene" --proxy cube
expect 2 "--kdop 7: k must be 6, 14, 18 or 26" -- "$bin" collide "$scene" --proxy kdop --kdop 7
expect 2 "--frames" -- "$bin" collide "$scene" --frames 5-2
expect 2 "--fps must be a finite number > 0" -- "$bin" collide "$scene" --frames 0-2 --fps 0
expect 2 "--continuous needs --frames with two frames or more" -- "$bin" collide "$scene" --proxy obb --frames 3 --continuous
# The same cubes with B's top two triangles left out: open.
"$py" - "$scene" "$work/open.gltf" <<'PY'
import base64, json, struct, sys
doc = json.load(open(sys.argv[1]))
blob = base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1])
idx = list(struct.unpack("<36I", blob[96:240]))
blob += struct.pack("<30I", *idx[6:])
doc["bufferViews"].append({"buffer": 0, "byteOffset": len(blob) - 120, "byteLength": 120})
doc["accessors"].append({"bufferView": len(doc["bufferViews"]) - 1, "componentType": 5125, "count": 30, "type": "SCALAR"})
doc["meshes"].append({"name": "open cube", "primitives": [{"attributes": {"POSITION": 0}, "indices": len(doc["accessors"]) - 1}]})
doc["nodes"][2]["mesh"] = len(doc["meshes"]) - 1
doc["buffers"][0] = {"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}
json.dump(doc, open(sys.argv[2], "w"))
PY
expect 2 "penumbra: error: $work/open.gltf: .*node 2: .*not closed: edge" -- "$bin" collide "$work/open.gltf" --volumes
expect 0 "'A' \\(0\\) and 'B' \\(2\\)" -- "$bin" collide "$work/open.gltf"

echo "collide: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
