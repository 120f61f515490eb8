#!/usr/bin/env bash
# glTF points and lines and the wireframe overlay end to end through `penumbra`:
# - the corpus' MeshPrimitiveModes (POINTS, LINES, LINE_LOOP, LINE_STRIP beside triangles) renders
#   with Whitted, the path tracer and the raster preview in every structure, the point and line
#   pixels carrying their nodes' ids, the same ids in the raster preview and the ray tracer;
# - --wireframe writes the wireframe.A channel (OpenEXR's exrheader lists it), in a job file too,
#   and a render without it has none;
# - malformed points and lines and bad sizes exit 2 naming the element or flag, writing nothing.
# Usage: curves_test.sh PENUMBRA SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
corpus="${PENUMBRA_CORPUS:-$src/../shared/corpus}"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
. "$src/tests/apps/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
pass() { passes=$((passes + 1)); }
for tool in oiiotool exrheader python3; do
  command -v "$tool" >/dev/null || { echo "PENUMBRA_SKIP: $tool is not installed"; exit 0; }
done

# 1. MeshPrimitiveModes in every integrator and structure; ids of points and lines agree between
# the raster preview and the ray tracer on >= 99% of their pixels.
modes="$corpus/valid/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf"
if [ -f "$modes" ]; then
  for integrator in whitted path raster; do
    for accel in embree bvh kdtree grid octree bsp; do
      [ "$integrator" = whitted ] || [ "$accel" = embree ] || continue
      expect 0 "modes_${integrator}_$accel.exr" -- "$bin" render "$modes" -o "$work/modes_${integrator}_$accel.exr" \
        --integrator "$integrator" --accel "$accel" --width 160 --spp 1 --point-size 6px --line-width 2px --aov id --no-png
    done
  done
  # Object ids as text: oiiotool prints each pixel of the id channel.
  ids() {
    oiiotool "$1" --ch object_id.X -o "$work/ids.exr" && oiiotool --dumpdata "$work/ids.exr" | sed -n 's/.*Pixel.*: *\([0-9.]*\) *$/\1/p'
  }
  ids "$work/modes_whitted_embree.exr" >"$work/traced.txt"
  ids "$work/modes_raster_embree.exr" >"$work/raster.txt"
  "$bin" info "$modes" --json >"$work/info.json"
  python3 - "$work/traced.txt" "$work/raster.txt" <<'P' && pass || fail "raster and traced ids of points and lines differ on more than 1% of their pixels"
import sys
t = [float(x) for x in open(sys.argv[1])]
r = [float(x) for x in open(sys.argv[2])]
assert len(t) == len(r) > 1000, (len(t), len(r))
# MeshPrimitiveModes: nodes 0-3 hold POINTS, LINES, LINE_LOOP, LINE_STRIP (object ids 1-4).
curve = {1.0, 2.0, 3.0, 4.0}
pixels = [(a, b) for a, b in zip(t, r) if a in curve or b in curve]
agree = sum(a == b for a, b in pixels)
print(f"{len(pixels)} point and line pixels, {agree} agree")
assert len(pixels) > 100 and agree >= 0.99 * len(pixels)
P
  # Every structure sees the same ids as Embree with Whitted.
  for accel in bvh kdtree grid octree bsp; do
    oiiotool "$work/modes_whitted_$accel.exr" --ch object_id.X "$work/modes_whitted_embree.exr" --ch object_id.X \
      --fail 0 --diff >/dev/null 2>&1 && pass || fail "ids with --accel $accel differ from embree's"
  done
fi

# The shipped points and lines scene, path traced and previewed, in every structure the same ids.
for accel in embree bvh; do
  expect 0 "curves_$accel.exr" -- "$bin" render "$src/scenes/curves.gltf" -o "$work/curves_$accel.exr" --width 120 --spp 1 \
    --accel "$accel" --aov id --no-png
done
oiiotool "$work/curves_bvh.exr" --ch object_id.X "$work/curves_embree.exr" --ch object_id.X --fail 0 --diff >/dev/null 2>&1 &&
  pass || fail "curves.gltf: ids with --accel bvh differ from embree's"
expect 0 "curves_path.exr" -- "$bin" render "$src/scenes/curves.gltf" -o "$work/curves_path.exr" --width 120 --spp 4 \
  --integrator path --aov crypto_object --no-png
exrheader "$work/curves_path.exr" | grep -q 'point sphere' && pass || fail "the Cryptomatte manifest does not name the point set's node"

# 2. The wireframe layer: in the EXR with --wireframe only, in a job file too.
scene="$src/scenes/default.gltf"
expect 0 "wire.exr" -- "$bin" render "$scene" -o "$work/wire.exr" --width 96 --spp 1 --wireframe --wireframe-hidden dim --no-png
exrheader "$work/wire.exr" | grep -q "wireframe.A" && pass || fail "no wireframe.A channel"
oiiotool "$work/wire.exr" --ch wireframe.A --printstats 2>&1 | grep -qE "Stats Max: (0\.99|1\.0)" && pass ||
  fail "the wireframe layer never reaches full coverage"
expect 0 "plain.exr" -- "$bin" render "$scene" -o "$work/plain.exr" --width 96 --spp 1 --no-png
exrheader "$work/plain.exr" | grep -q "wireframe.A" && fail "a render without --wireframe has a wireframe layer" || pass
cat >"$work/job.json" <<JSON
{"version": 1,
 "defaults": {"width": 64, "spp": 1},
 "shots": [
  {"name": "wired", "scene": "$scene", "output": "shots/wired.exr",
   "settings": {"wireframe": true, "wireframe-color": "1,0,0", "wireframe-width": 2}}]}
JSON
expect 0 "" -- "$bin" batch "$work/job.json" -q
exrheader "$work/shots/wired.exr" 2>/dev/null | grep -q "wireframe.A" && pass || fail "the job's shot has no wireframe layer"

# 3. Bad input: exit 2, the element or flag named, nothing written.
python3 - "$work" <<'P'
import base64, json, struct, sys
w = sys.argv[1]
def gltf(name, mode, positions, indices=None, ext=None, attributes=None):
    blob = struct.pack(f"<{len(positions)}f", *positions)
    acc = [{"bufferView": 0, "componentType": 5126, "count": len(positions) // 3, "type": "VEC3"}]
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": len(blob)}]
    prim = {"attributes": {"POSITION": 0}, "mode": mode}
    if indices is not None:
        ib = struct.pack(f"<{len(indices)}I", *indices)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(ib)})
        acc.append({"bufferView": 1, "componentType": 5125, "count": len(indices), "type": "SCALAR"})
        prim["indices"] = 1
        blob += ib
    if ext is not None:
        prim["extensions"] = {"PENUMBRA_points": ext}
    if attributes is not None:
        prim["attributes"] = attributes
    g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
         "meshes": [{"primitives": [prim]}], "accessors": acc, "bufferViews": views,
         "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]}
    json.dump(g, open(f"{w}/{name}.gltf", "w"))
tri = [0, 0, 0, 1, 0, 0, 0, 1, 0]
gltf("odd", 1, tri)
gltf("strip1", 3, tri[:3])
gltf("loop1", 2, tri, indices=[2])
gltf("nopos", 0, tri, attributes={})
gltf("zero", 1, tri[:6], ext={"width": 0})
gltf("nan", 0, tri, ext={"width": "wide"})
gltf("key", 0, tri, ext={"size": 1})
gltf("good", 3, tri, ext={"width": 0.1})
P
expect_refused odd "meshes\[0\]\.primitives\[0\]: LINES with an odd count"
expect_refused strip1 "meshes\[0\]\.primitives\[0\]: LINE_STRIP with one vertex"
expect_refused loop1 "meshes\[0\]\.primitives\[0\]: LINE_LOOP with one vertex"
expect_refused nopos "meshes\[0\]\.primitives\[0\]: POINTS without a POSITION"
expect_refused zero "meshes\[0\]\.primitives\[0\]\.extensions\.PENUMBRA_points\.width: not a finite positive number"
expect_refused nan "meshes\[0\]\.primitives\[0\]\.extensions\.PENUMBRA_points\.width: not a finite positive number"
expect_refused key "meshes\[0\]\.primitives\[0\]\.extensions\.PENUMBRA_points: unknown key 'size'"
expect 0 "lines        2 segments" -- "$bin" info "$work/good.gltf"
for bad in 0 -2px nanpx 2pix 1e40; do
  expect 2 "error: .*point_size" -- "$bin" render "$work/good.gltf" -o "$work/bad.exr" --point-size "$bad"
  expect 2 "error: .*line_width" -- "$bin" render "$work/good.gltf" -o "$work/bad.exr" --line-width "$bad"
done
expect 2 "error: .*wireframe_width needs wireframe" -- "$bin" render "$work/good.gltf" -o "$work/bad.exr" --wireframe-width 3
expect 2 "error: .*wireframe_color" -- "$bin" render "$work/good.gltf" -o "$work/bad.exr" --wireframe --wireframe-color 1,2
expect 2 "error: .*wireframe.hidden" -- "$bin" render "$work/good.gltf" -o "$work/bad.exr" --wireframe --wireframe-hidden maybe
expect 2 "error: .*wireframe_nodes: no node 'nosuch'" -- "$bin" render "$work/good.gltf" -o "$work/bad.exr" --wireframe --wireframe-nodes nosuch
expect 2 "error: .*wireframe with denoise" -- "$bin" render "$work/good.gltf" -o "$work/bad.exr" --integrator path --spp 4 --denoise --wireframe
[ -e "$work/bad.exr" ] && fail "a refused render left its output" || pass

echo "curves: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
