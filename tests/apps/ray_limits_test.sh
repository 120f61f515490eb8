#!/usr/bin/env bash
# Rays at the limits of single precision: placements scaled so small that no single-precision
# kernel can invert them (shape nodes, implicit shapes, EXT_mesh_gpu_instancing copies of a
# mesh) are skipped with a warning naming the node, by every structure and both tracing
# integrators, where Embree used to abort the process; an instance whose object-space rays
# would leave Embree's range is still traced (its image equals the BVH's); and cameras whose
# rays would leave that range (orthographic extents, a file camera's ymag) exit 2 naming the
# camera, writing nothing.
# Usage: ray_limits_test.sh PENUMBRA SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
source "$src/tests/apps/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
ok() { passes=$((passes + 1)); }
for tool in oiiotool python3; do
  command -v "$tool" >/dev/null || { echo "PENUMBRA_SKIP: $tool is not installed"; exit 0; }
done

# Scenes: a unit sphere at the origin beside a node scaled by SCALE on every axis, as a shape
# node, an implicit shape, and a triangle mesh copied by EXT_mesh_gpu_instancing.
python3 - "$work" <<'EOF'
import base64, json, struct, sys
work = sys.argv[1]
def save(name, doc):
    json.dump(doc, open(f"{work}/{name}.gltf", "w"))
def base(nodes, used):
    return {"asset": {"version": "2.0"}, "extensionsUsed": used, "scene": 0,
            "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes}
sphere = {"name": "unit", "extensions": {"PENUMBRA_shapes": {"type": "sphere", "radius": 1.0}}}
for scale in ["1e-13", "1e-16", "1e-30"]:
    s = float(scale)
    tiny = {"name": "tiny", "scale": [s, s, s], "translation": [2.5, 0, 0]}
    save(f"shape_{scale}", base([sphere, dict(tiny, extensions={"PENUMBRA_shapes": {"type": "box", "size": [1, 1, 1]}})],
                                ["PENUMBRA_shapes"]))
    save(f"implicit_{scale}", base([sphere, dict(tiny, extensions={"PENUMBRA_shapes": {
        "type": "implicit", "csg": {"type": "sphere", "radius": 1.0}}})], ["PENUMBRA_shapes"]))
    # One triangle, copied twice by EXT_mesh_gpu_instancing with the tiny scale.
    pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    trans = struct.pack("<6f", 2.5, 0, 0, 2.5, 0.5, 0)
    scl = struct.pack("<6f", s, s, s, s, s, s)
    data = pos + trans + scl
    doc = base([sphere, {"name": "copies", "mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {
        "attributes": {"TRANSLATION": 1, "SCALE": 2}}}}], ["PENUMBRA_shapes", "EXT_mesh_gpu_instancing"])
    doc["buffers"] = [{"byteLength": len(data),
                       "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}]
    doc["bufferViews"] = [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                          {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                          {"buffer": 0, "byteOffset": 60, "byteLength": 24}]
    doc["accessors"] = [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                         "min": [0, 0, 0], "max": [1, 1, 0]},
                        {"bufferView": 1, "componentType": 5126, "count": 2, "type": "VEC3"},
                        {"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC3"}]
    doc["meshes"] = [{"primitives": [{"attributes": {"POSITION": 0}}]}]
    save(f"copies_{scale}", doc)
# A sphere of radius 1e10 scaled by 1e-10 (radius 1 in the world), seen from 1e12 away: its
# object-space ray origins (1e22) are beyond what Embree accepts.
save("far", base([{"name": "scaled", "scale": [1e-10] * 3,
                   "extensions": {"PENUMBRA_shapes": {"type": "sphere", "radius": 1e10}}}], ["PENUMBRA_shapes"]))
# File cameras: an orthographic one of ymag 1e19, and a sane one.
for name, ymag in [("ortho_huge", 1e19), ("ortho_ok", 2.0)]:
    doc = base([sphere, {"name": "cam", "camera": 0, "translation": [0, 0, 5]}], ["PENUMBRA_shapes"])
    doc["cameras"] = [{"type": "orthographic", "orthographic": {"xmag": ymag, "ymag": ymag, "znear": 0.01, "zfar": 100}}]
    save(name, doc)
EOF

# Tiny placements: every structure renders the unit sphere at every scale and warns about the
# node instead of aborting, the two tracing integrators taking turns over the structures (each
# integrator meets each kind and scale).
for kind in shape implicit copies; do
  for scale in 1e-13 1e-16 1e-30; do
    scene="$work/${kind}_$scale.gltf"
    turn=0
    for accel in embree bvh kdtree grid octree bsp brute; do
      integrator=whitted
      [ $((turn % 2)) -eq 1 ] && integrator=path
      turn=$((turn + 1))
      expect 0 "warning: .*${kind}_$scale.gltf: nodes\[1\].*(singular|skipped)" -- \
        "$bin" render "$scene" -o "$work/t.exr" --no-png --width 24 --height 16 --spp 2 --accel "$accel" \
        --integrator "$integrator"
    done
    expect 0 "" -- "$bin" render "$scene" -o "$work/raster.exr" --no-png --width 24 --height 16 --integrator raster -q
  done
done

# Far camera, tiny placement: Embree traces it (its rays restarted at the scene's bounds: they
# would otherwise leave its range and abort) and covers the analytic share of the image. The
# other structures render it too (their single-precision object-space sphere test at 1e22 is
# not exact, so only Embree's coverage is compared).
fov=$(python3 -c "import math; print(math.degrees(2 * math.atan(2.0 / 1e12)))")
for accel in embree bvh kdtree; do
  expect 0 "" -- "$bin" render "$work/far.gltf" -o "$work/far_$accel.exr" --no-png --width 32 --height 32 \
    --spp 4 --accel "$accel" --look-at 0,0,1e12 0,0,0 --fov "$fov" -q
done
a_embree=$(oiiotool "$work/far_embree.exr" --ch A --printstats 2>/dev/null | sed -n 's/.*Avg: *\([0-9.e+-]*\).*/\1/p' | head -1)
# A disc of radius 1 in a frame 4 units wide: pi / 16 of the image is covered.
python3 -c "import math, sys; sys.exit(0 if abs(float('$a_embree') - math.pi / 16) < 0.02 else 1)" \
  && ok || fail "far camera: Embree's coverage $a_embree, want pi/16"

# Cameras whose rays leave single precision: exit 2 naming the camera, nothing written.
for args in "--ortho 1e19" "--ortho 1e29" "--orbit 30,10 --ortho 1e20" "--look-at 6e17,6e17,6e17 0,0,0 --ortho 1e18"; do
  for integrator in whitted path raster; do
    rm -f "$work/cam.exr" "$work/cam.png"
    # shellcheck disable=SC2086
    expect 2 "penumbra: error: .*shape_1e-13.gltf: the view: camera: .*(orthographic height|image plane reaches)" -- \
      "$bin" render "$work/shape_1e-13.gltf" -o "$work/cam.exr" --width 32 --height 24 --integrator "$integrator" $args
    [ -e "$work/cam.exr" ] || [ -e "$work/cam.png" ] && fail "a refused camera ($args) left an image"
  done
done
expect 2 "penumbra: error: .*ortho_huge.gltf: cameras\[0\]: camera: .*(orthographic|image plane)" -- \
  "$bin" render "$work/ortho_huge.gltf" -o "$work/cam.exr" --width 32 --height 24
expect 0 "" -- "$bin" render "$work/ortho_ok.gltf" -o "$work/cam.exr" --width 32 --height 24 -q
for accel in bvh kdtree brute; do
  expect 2 "cameras\[0\]: camera: " -- "$bin" render "$work/ortho_huge.gltf" -o "$work/cam.exr" --width 32 --accel "$accel"
done

# The Python module: the same refusal as an InputError, and the tiny placement renders.
py="${PENUMBRA_PYTHON:-python3}"
if "$py" -c "import numpy, penumbra" 2>/dev/null; then
  "$py" - "$work" <<'EOF' && ok || fail "Python: camera refusal or tiny placement"
import sys, penumbra
work = sys.argv[1]
try:
    penumbra.load(f"{work}/ortho_huge.gltf").render(width=16, height=16)
    sys.exit("the huge orthographic camera rendered")
except penumbra.InputError as e:
    assert "cameras[0]" in str(e) and "single-precision" in str(e), str(e)
for integrator in ["whitted", "path"]:
    img = penumbra.load(f"{work}/shape_1e-16.gltf").render(width=16, height=16, spp=2, integrator=integrator)
    assert img.beauty.shape[:2] == (16, 16)
EOF
else
  echo "note: the penumbra Python module is not importable here; its checks run in python.pytest"
fi

echo "$passes passed, $fails failed"
[ "$fails" -eq 0 ]
