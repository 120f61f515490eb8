#!/usr/bin/env bash
# End-to-end test of `penumbra mesh`: a scene with implicit shapes (PENUMBRA_shapes) meshed to
# .glb and .gltf, read back by `penumbra info` (and Blender when installed); a displaced sphere
# meshed to its relief; an unknown node, a node without an implicit shape, bad resolutions and
# outputs, an empty --node, a resolution over the memory budget and a million instanced placements
# over it exit 2 before writing anything.
# Usage: mesh_cli_test.sh PENUMBRA SRC WORK
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0

# expect CODE PATTERN -- command...: counts a pass or a failure in $passes / $fails.
source "$(dirname "$0")/expect.sh"
absent() {  # absent FILE...: a refused run wrote nothing
  for f in "$@"; do [ ! -e "$f" ] || { echo "FAIL: a refused run wrote $f"; fails=$((fails + 1)); }; done
}

# A ball of radius 0.5 at (2, 0, 0) (unit sphere scaled by 0.5), the classic CSG part at the
# origin, an analytic sphere and an empty node.
scene="$work/shapes.gltf"
cat >"$scene" <<'JSON'
{
  "asset": {"version": "2.0"},
  "extensionsUsed": ["PENUMBRA_shapes"],
  "materials": [{"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]}},
                {"name": "grey"}],
  "scenes": [{"nodes": [0, 1, 2, 3]}],
  "scene": 0,
  "nodes": [
    {"name": "ball", "translation": [2, 0, 0], "scale": [0.5, 0.5, 0.5],
     "extensions": {"PENUMBRA_shapes": {"type": "implicit", "material": 0,
                                        "csg": {"type": "sphere", "radius": 1}}}},
    {"name": "part",
     "extensions": {"PENUMBRA_shapes": {"type": "implicit", "material": 1, "csg": {
       "type": "subtraction", "children": [
         {"type": "intersection", "children": [{"type": "sphere", "radius": 1.35},
                                               {"type": "box", "size": [2, 2, 2]}]},
         {"type": "union", "children": [
           {"type": "cylinder", "radius": 0.5, "height": 3},
           {"type": "cylinder", "radius": 0.5, "height": 3, "rotation": [0, 0, 0.7071068, 0.7071068]},
           {"type": "cylinder", "radius": 0.5, "height": 3, "rotation": [0.7071068, 0, 0, 0.7071068]}]}]}}}},
    {"name": "plain", "extensions": {"PENUMBRA_shapes": {"type": "sphere", "radius": 1}}},
    {"name": "empty"}
  ]
}
JSON

# Every implicit shape, as one .glb: two meshes; `info` reads it back.
expect 0 "all.glb" -- "$bin" mesh "$scene" --resolution 40 -o "$work/all.glb"
expect 0 "2 shapes meshed at resolution 40" -- "$bin" mesh "$scene" --resolution 40 -o "$work/all.glb"
expect 0 "1 analytic shapes skipped" -- "$bin" mesh "$scene" --resolution 40 -o "$work/all.glb"
expect 0 "meshes       2 \(2 primitives\)" -- "$bin" info "$work/all.glb"
expect 0 "materials    2" -- "$bin" info "$work/all.glb"
# One node by name as .gltf + .bin, by index as .glb; its bounds are the ball's within a cell.
expect 0 "ball.gltf" -- "$bin" mesh "$scene" --node ball --resolution 32 -o "$work/ball.gltf" -q
[ -s "$work/ball.bin" ] || { echo "FAIL: ball.bin missing"; fails=$((fails + 1)); }
expect 0 "meshes       1 \(1 primitives\)" -- "$bin" info "$work/ball.gltf"
# The ball's world box is (1.5, -0.5, -0.5) - (2.5, 0.5, 0.5); one cell is 0.5 * 2 / 32.
"$bin" info "$work/ball.gltf" >"$work/info" 2>&1
bounds=$(sed -n 's/^bounds *(\(.*\)) - (\(.*\))$/\1, \2/p' "$work/info" | tr -d ' ')
if python3 -c "
import sys
got = [float(x) for x in '$bounds'.split(',')]
want = [1.5, -0.5, -0.5, 2.5, 0.5, 0.5]
sys.exit(0 if len(got) == 6 and all(abs(g - w) <= 0.5 * 2 / 32 for g, w in zip(got, want)) else 1)
"; then passes=$((passes + 1)); else echo "FAIL: ball bounds '$bounds' not within a cell of the ball's"; fails=$((fails + 1)); fi
expect 0 "part.glb" -- "$bin" mesh "$scene" --node 1 --resolution 24 -o "$work/part.glb" -q
expect 0 "meshes       1 " -- "$bin" info "$work/part.glb"
# The shipped CSG scene: its three implicit shapes (the ground plane is analytic).
expect 0 "3 shapes meshed at resolution 32" -- "$bin" mesh "$src/scenes/csg.gltf" --resolution 32 -o "$work/csg.glb"
expect 0 "meshes       3 \(3 primitives\)" -- "$bin" info "$work/csg.glb"
# A unit sphere displaced by fBm (amplitude 0.2), meshed to .gltf + .bin: every vertex lies within
# the amplitude and a cell of the unit sphere, and their radii spread over much of that relief (a
# plain sphere's would agree within a cell).
rough="$work/rough.gltf"
cat >"$rough" <<'JSON'
{
  "asset": {"version": "2.0"},
  "extensionsUsed": ["PENUMBRA_shapes"],
  "scenes": [{"nodes": [0]}],
  "scene": 0,
  "nodes": [
    {"name": "rough", "extensions": {"PENUMBRA_shapes": {"type": "implicit", "csg": {
      "type": "displace", "amplitude": 0.2, "frequency": 2, "seed": 5, "noise": "fbm", "detail": 3,
      "children": [{"type": "sphere", "radius": 1}]}}}}
  ]
}
JSON
expect 0 "1 shapes meshed at resolution 48" -- "$bin" mesh "$rough" --resolution 48 -o "$work/rough-mesh.gltf"
if python3 -c "
import json, math, struct, sys
doc = json.load(open('$work/rough-mesh.gltf'))
acc = doc['accessors'][doc['meshes'][0]['primitives'][0]['attributes']['POSITION']]
view = doc['bufferViews'][acc['bufferView']]
data = open('$work/' + doc['buffers'][view['buffer']]['uri'], 'rb').read()
start = view.get('byteOffset', 0) + acc.get('byteOffset', 0)
radii = [math.sqrt(sum(c * c for c in struct.unpack_from('<3f', data, start + 12 * i))) for i in range(acc['count'])]
cell = 2.4 / 48
ok = all(abs(r - 1) <= 0.2 + cell for r in radii) and max(radii) - min(radii) > 0.1
print('vertex radii in [%.3f, %.3f]' % (min(radii), max(radii)))
sys.exit(0 if ok else 1)
"; then passes=$((passes + 1)); else echo "FAIL: the displaced sphere's vertex radii"; fails=$((fails + 1)); fi
[ -z "$(ls -A "$work" | grep '\.tmp-')" ] || { echo "FAIL: temporaries left behind"; fails=$((fails + 1)); }

# Refusals: exit 2, the reason named, nothing written.
expect 2 "--node 'nosuch': .* has no node of that name" -- "$bin" mesh "$scene" --node nosuch --resolution 8 -o "$work/x.glb"
expect 2 "--node 9: .* has 4 nodes" -- "$bin" mesh "$scene" --node 9 --resolution 8 -o "$work/x.glb"
expect 2 "node 'plain' places no implicit shape" -- "$bin" mesh "$scene" --node plain --resolution 8 -o "$work/x.glb"
expect 2 "node 'empty' places no implicit shape" -- "$bin" mesh "$scene" --node 3 --resolution 8 -o "$work/x.glb"
expect 2 "--resolution 0: outside \[1, 4096\]" -- "$bin" mesh "$scene" --resolution 0 -o "$work/x.glb"
expect 2 "--resolution 5000: outside" -- "$bin" mesh "$scene" --resolution 5000 -o "$work/x.glb"
expect 2 "resolution" -- "$bin" mesh "$scene" -o "$work/x.glb"
expect 2 "must be a .glb or .gltf" -- "$bin" mesh "$scene" --resolution 8 -o "$work/x.obj"
expect 2 "does not exist" -- "$bin" mesh "$scene" --resolution 8 -o "$work/nodir/x.glb"
expect 2 "would overwrite" -- "$bin" mesh "$scene" --resolution 8 -o "$scene"
expect 2 "ball: meshing at resolution 2000 needs [0-9]+ bytes, more than the [0-9]+ bytes left" -- "$bin" mesh "$scene" --node ball --resolution 2000 --max-memory 64M -o "$work/x.glb"
# One implicit sphere placed a million times (EXT_mesh_gpu_instancing): the meshes of all
# placements together are over the budget, refused before any is meshed.
python3 - "$work" <<'PY'
import array, json, sys
n = 1000000
t = array.array("f")
for i in range(n):
    t.extend((3.0 * (i % 100), 3.0 * (i // 100 % 100), 3.0 * (i // 10000)))
open(sys.argv[1] + "/swarm.bin", "wb").write(t.tobytes())
json.dump({"asset": {"version": "2.0"}, "extensionsUsed": ["PENUMBRA_shapes", "EXT_mesh_gpu_instancing"],
           "buffers": [{"uri": "swarm.bin", "byteLength": 12 * n}],
           "bufferViews": [{"buffer": 0, "byteLength": 12 * n}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3"}],
           "scenes": [{"nodes": [0]}], "scene": 0,
           "nodes": [{"name": "swarm", "extensions": {
               "PENUMBRA_shapes": {"type": "implicit", "csg": {"type": "sphere", "radius": 1}},
               "EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 0}}}}]},
          open(sys.argv[1] + "/swarm.gltf", "w"))
PY
expect 2 "swarm: meshing its 1000000 placements at resolution 64 needs [0-9]+ bytes .*more than the [0-9]+ bytes left" -- \
  "$bin" mesh "$work/swarm.gltf" --resolution 64 --max-memory 2G -o "$work/x.glb"
absent "$work/x.glb"
expect 2 "--node: the value is empty" -- "$bin" mesh "$scene" --node '' --resolution 8 -o "$work/x.glb"
expect 2 "spheres.gltf: the scene places no implicit shape" -- "$bin" mesh "$src/scenes/spheres.gltf" --resolution 8 -o "$work/x.glb"
expect 2 "default.gltf: the scene places no implicit shape" -- "$bin" mesh "$src/scenes/default.gltf" --resolution 8 -o "$work/x.glb"
expect 2 "missing.gltf" -- "$bin" mesh "$work/missing.gltf" --resolution 8 -o "$work/x.glb"
absent "$work/x.glb" "$work/x.obj"
cmp -s "$scene" "$work/out" && { echo "FAIL: the scene was overwritten"; fails=$((fails + 1)); }
grep -q PENUMBRA_shapes "$scene" || { echo "FAIL: the scene was overwritten"; fails=$((fails + 1)); }

# Blender's importer reads the .glb (when Blender is installed). Smooth shading is asked for:
# the importer's default guess of flat faces from the normals uses numpy's removed np.bool in
# Debian 12's Blender 3.4 with numpy 1.24.
if command -v blender >/dev/null; then
  expect 0 "vertices [1-9][0-9]* in 2 meshes" -- blender -b --factory-startup --python-exit-code 1 --python-expr "
import bpy
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=r'$work/all.glb', import_shading='SMOOTH')
meshes = [o for o in bpy.context.scene.objects if o.type == 'MESH']
print('vertices', sum(len(o.data.vertices) for o in meshes), 'in', len(meshes), 'meshes')
"
else
  echo "PENUMBRA_SKIP: Blender import skipped (blender not installed)"
fi

echo "mesh cli: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
