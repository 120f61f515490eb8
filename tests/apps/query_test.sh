#!/usr/bin/env bash
# `penumbra query` end to end on the shipped default scene:
# - every acceleration structure gives the same JSON answers as brute force on the default and
#   CSG scenes (nearest with k, within, overlap by box, ray), apart from the "accel" field;
#   Embree's ray hit within float rounding (its ray test rounds differently);
# - the surface point a ray hits is at distance 0 from the scene (nearest), on the same node;
# - within's answers are within the radius and nearest first, and equal overlap --sphere's;
#   the k nearest are ordered and the first of them is nearest's k = 1 answer;
# - a points file gives one result per point, the same as --at for each;
# - pick reports the id AOV's node and material and the Z AOV's depth at pixels one surface
#   covers, for the scene's camera, --look-at, --ortho and --orbit;
# - info --volumes: closed forms of the shipped shapes, an implicit torus within its bound, a
#   scaled mesh box exact, open meshes and flat shapes not closed;
# - point sets: one cloud as .npy, .ply and text, the k nearest points in every structure equal
#   NumPy's brute force; a glTF POINTS primitive is queried where its node places it, and
#   hidden behind a triangle it leaves the image as it was, in every structure;
# - bad input exits 2 naming the option, the file and the line: NaN, k = 0 or absurd, a
#   malformed or empty points file, both or neither of --at and --points, an inverted box,
#   a zero direction, a scene without geometry, a pixel outside the image or not whole, a
#   --max-memory too small for --k.
# Usage: query_test.sh PENUMBRA_BINARY SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
source "$(dirname "$0")/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
py=/usr/bin/python3
scene="$src/scenes/default.gltf"

# 1. Every structure answers the same.
# (The library's tests compare every structure with an oracle at many points; this checks that
# the command passes --accel through and prints the same document.)
queries=("nearest --points $work/probe.txt --k 5" "within --at 0,1,0 --radius 1.5" "overlap --box -1,0,-1,1,1,1"
         "ray --from 0,1,6 --dir 0,0,-1")
printf '0.3 1.1 -0.4\n4 5 6\n0 1 0\n' >"$work/probe.txt"
for s in default csg; do
  for q in "${queries[@]}"; do
    for accel in brute bvh kdtree grid octree bsp embree; do
      # shellcheck disable=SC2086
      "$bin" query $q "$src/scenes/$s.gltf" --accel "$accel" --json >"$work/$accel.json" 2>"$work/err" ||
        fail "$s: $q --accel $accel: exit $?"
      sed -i '/"accel":/d' "$work/$accel.json"
      [ "$accel" = brute ] && continue
      if [ "$accel" = embree ] && [ "${q%% *}" = ray ]; then
        # Embree's ray test rounds differently: the same hit within float rounding.
        $py - "$work/brute.json" "$work/embree.json" <<'P' && passes=$((passes + 1)) || fail "$s: $q: embree's hit differs"
import json, math, sys
def same(a, b):
    if isinstance(a, float) or isinstance(b, float):
        return math.isclose(a, b, rel_tol=1e-5, abs_tol=1e-6)
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return a == b
assert same(json.load(open(sys.argv[1])), json.load(open(sys.argv[2])))
P
        continue
      fi
      cmp -s "$work/brute.json" "$work/$accel.json" && passes=$((passes + 1)) ||
        fail "$s: $q: $accel answers differently from brute force: $(diff "$work/brute.json" "$work/$accel.json" | head -5)"
    done
  done
done

# 2. Consistency between the queries, checked on the JSON.
"$bin" query ray "$scene" --from 0,1,6 --dir 0.1,-0.1,-1 --json >"$work/ray.json" || fail "ray"
hit=$($py -c 'import json,sys; m=json.load(open(sys.argv[1]))["results"][0]["matches"]; print(",".join(map(repr,m[0]["point"])) if m else "")' "$work/ray.json")
[ -n "$hit" ] || fail "the ray from the camera's side hits nothing"
"$bin" query nearest "$scene" --at "$hit" --k 1 --json >"$work/hit.json" || fail "nearest at the hit"
$py - "$work/ray.json" "$work/hit.json" <<'P' && passes=$((passes + 1)) || fail "the ray's hit point is not on the nearest surface"
import json, sys
ray = json.load(open(sys.argv[1]))["results"][0]["matches"][0]
near = json.load(open(sys.argv[2]))["results"][0]["matches"][0]
assert near["distance"] < 1e-4, near
assert near["node"] == ray["node"], (near, ray)
P
"$bin" query within "$scene" --at 0,1,0 --radius 1.5 --json >"$work/within.json" || fail "within"
"$bin" query overlap "$scene" --sphere 0,1,0,1.5 --json >"$work/ball.json" || fail "overlap --sphere"
"$bin" query nearest "$scene" --at 0,1,0 --k 4000 --json >"$work/k.json" || fail "nearest k"
"$bin" query nearest "$scene" --at 0,1,0 --json >"$work/k1.json" || fail "nearest k=1"
$py - "$work/within.json" "$work/ball.json" "$work/k.json" "$work/k1.json" <<'P' && passes=$((passes + 1)) || fail "within / overlap / nearest disagree"
import json, sys
w, b, k, k1 = (json.load(open(f))["results"][0]["matches"] for f in sys.argv[1:5])
d = [m["distance"] for m in w]
assert w and all(x <= 1.5 for x in d) and d == sorted(d), d[:5]
assert w == b
dk = [m["distance"] for m in k]
assert dk == sorted(dk) and k[0] == k1[0]
# Every primitive within 1.5 is among the k nearest, in the same order.
assert k[:len(w)] == w
P

# 3. A points file: one result per point, as --at gives.
printf '# x y z\n0.3 1.1 -0.4\n\n4,5,6\n-1\t0.5\t2\n' >"$work/points.txt"
"$bin" query nearest "$scene" --points "$work/points.txt" --k 2 --json >"$work/pts.json" || fail "--points"
i=0
for p in 0.3,1.1,-0.4 4,5,6 -1,0.5,2; do
  "$bin" query nearest "$scene" --at "$p" --k 2 --json >"$work/one.json"
  $py - "$work/pts.json" "$work/one.json" "$i" <<'P' && passes=$((passes + 1)) || fail "points file entry $i differs from --at $p"
import json, sys
a = json.load(open(sys.argv[1]))["results"][int(sys.argv[3])]
b = json.load(open(sys.argv[2]))["results"][0]
assert a == b, (a, b)
P
  i=$((i + 1))
done
expect 0 'nearest at \(0.3, 1.1, -0.4\): 1' -- "$bin" query nearest "$scene" --at 0.3,1.1,-0.4
expect 0 '1\. distance [0-9.e-]+, node [0-9]+ ' -- "$bin" query nearest "$scene" --at 0.3,1.1,-0.4

# 4. pick: the id AOV's node and material at pixels one surface covers, for the scene's camera,
# --look-at, an orthographic lens and --orbit; depth is the Z AOV's there.
if command -v oiiotool >/dev/null; then
  views=("" "--look-at 3,2.5,5 0,0.8,0" "--ortho 4" "--orbit 30,20")
  for view in "${views[@]}"; do
    # shellcheck disable=SC2086
    "$bin" render "$scene" -o "$work/ids.exr" --width 64 --height 36 --spp 4 --aov id,Z --no-png -q $view ||
      fail "render for pick ($view)"
    oiiotool --info -v "$work/ids.exr" >"$work/ids_info.txt" && oiiotool --dumpdata "$work/ids.exr" >"$work/ids_dump.txt" ||
      fail "oiiotool --dumpdata"
    # {"x,y": [object id, material id, Z]} from the dump, by the channel list's order.
    $py - "$work/ids_info.txt" "$work/ids_dump.txt" "$work/ids.json" <<'P' || fail "reading the id AOV"
import json, re, sys
names = [c.split(" (")[0] for c in re.search(r"channel list: (.*)", open(sys.argv[1]).read())[1].split(", ")]
at = [names.index(n) for n in ("object_id.X", "material_id.X", "Z")]
ids = {}
for line in open(sys.argv[2]):
    m = re.match(r"\s*Pixel \((\d+), (\d+)\):\s*(.*)", line)
    if m:
        v = [float(x) for x in m[3].split()]
        ids[f"{m[1]},{m[2]}"] = [v[i] for i in at]
json.dump(ids, open(sys.argv[3], "w"))
P
    pixels=$($py - "$work/ids.json" <<'P'
import json, sys
ids = {tuple(map(int, k.split(","))): tuple(v[:2]) for k, v in json.load(open(sys.argv[1])).items()}
uniform = [(x, y) for (x, y), v in sorted(ids.items())
           if all(ids.get((x + dx, y + dy)) == v for dx in (-1, 0, 1) for dy in (-1, 0, 1))]
# Four, spread over the image (the library's test compares every such pixel).
step = max(1, len(uniform) // 4)
print(" ".join(f"{x},{y}" for x, y in uniform[::step][:4]))
P
)
    [ -n "$pixels" ] || fail "no pixel one surface covers ($view)"
    for px in $pixels; do
      # shellcheck disable=SC2086
      "$bin" query pick "$scene" --pixel "$px" --width 64 --height 36 --accel bvh --json $view >"$work/pick.json" ||
        fail "pick $px ($view): exit $?"
      $py - "$work/ids.json" "$work/pick.json" "$px" <<'P' && passes=$((passes + 1)) || fail "pick $px ($view) differs from the id AOV"
import json, math, sys
x, y = map(int, sys.argv[3].split(","))
obj, mat, z = json.load(open(sys.argv[1]))[f"{x},{y}"]
doc = json.load(open(sys.argv[2]))
assert doc["query"] == "pick" and doc["pixel"] == [x, y] and (doc["width"], doc["height"]) == (64, 36), doc
matches = doc["results"][0]["matches"]
if obj == 0:
    assert matches == [], matches
else:
    (m,) = matches
    assert m["node"] + 1 == obj and m["material"] + 1 == mat, (m, obj, mat)
    # The Z AOV is the nearest of the pixel's samples; the centre's depth is close to it.
    assert math.isclose(m["depth"], z, rel_tol=0.1, abs_tol=0.05), (m["depth"], z)
P
    done
  done
else
  echo "SKIP: pick against the id AOV (oiiotool not found)"
fi
expect 0 'pick: 1' -- "$bin" query pick "$scene" --pixel 480,300
expect 0 '"camera": 0' -- "$bin" query pick "$scene" --pixel 10,10 --json

# 5. info --volumes: the shipped shapes' closed forms within 0.1%, the torus' within the bound
# reported, a mesh box scaled by its node exact, flat shapes and an open mesh not closed.
"$bin" info "$src/scenes/spheres.gltf" --volumes --json >"$work/vol.json" 2>/dev/null || fail "info --volumes spheres"
$py - "$src/scenes/spheres.gltf" "$work/vol.json" <<'P' && passes=$((passes + 1)) || fail "spheres.gltf volumes differ from the closed forms"
import json, math, sys
nodes = json.load(open(sys.argv[1]))["nodes"]
checked = 0
for v in json.load(open(sys.argv[2]))["volumes"]:
    shape = nodes[v["node"]]["extensions"]["PENUMBRA_shapes"]
    kind, r = shape["type"], shape.get("radius", 0.5)
    if kind == "plane":
        assert not v["closed"] and v["volume"] is None, v
        continue
    exact = {"sphere": 4 / 3 * math.pi * r ** 3,
             "capsule": math.pi * r * r * shape.get("height", 1) + 4 / 3 * math.pi * r ** 3,
             "box": math.prod(shape.get("size", [1, 1, 1]))}[kind]
    assert v["closed"] and v["error"] == 0 and math.isclose(v["volume"], exact, rel_tol=1e-3), (v, exact)
    checked += 1
assert checked >= 8, checked
P
"$bin" info "$src/scenes/csg.gltf" --volumes --json >"$work/csg.json" 2>/dev/null || fail "info --volumes csg"
$py - "$work/csg.json" <<'P' && passes=$((passes + 1)) || fail "csg.gltf: the torus' volume is not within its bound"
import json, math, sys
v = {x["node_name"]: x for x in json.load(open(sys.argv[1]))["volumes"]}
t = v["torus"]
exact = 2 * math.pi ** 2 * 0.8 * 0.28 ** 2
assert t["closed"] and abs(t["volume"] - exact) <= t["error"] <= 0.05 * exact, (t, exact)
assert v["csg part"]["closed"] and 0 < v["csg part"]["volume"] < 8, v["csg part"]
assert not v["ground"]["closed"]
P
$py - "$work" <<'P' || fail "writing the box scene"
import base64, json, struct, sys
c = [(0, 0, 0), (2, 0, 0), (2, 3, 0), (0, 3, 0), (0, 0, 4), (2, 0, 4), (2, 3, 4), (0, 3, 4)]
faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
pos, idx = [], []
for f in faces:
    b = len(pos)
    pos += [c[k] for k in f]
    idx += [b, b + 1, b + 2, b, b + 2, b + 3]
def scene(indices, name):
    blob = b"".join(struct.pack("<3f", *p) for p in pos) + struct.pack(f"<{len(indices)}I", *indices)
    g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
         "nodes": [{"mesh": 0, "scale": [1, 2, 1], "translation": [5, 0, 0], "name": "box"}],
         "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
         "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
                        "min": [0, 0, 0], "max": [2, 3, 4]},
                       {"bufferView": 1, "componentType": 5125, "count": len(indices), "type": "SCALAR"}],
         "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 12 * len(pos)},
                         {"buffer": 0, "byteOffset": 12 * len(pos), "byteLength": 4 * len(indices)}],
         "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]}
    json.dump(g, open(f"{sys.argv[1]}/{name}.gltf", "w"))
scene(idx, "box")
scene(idx[:-3], "open")
P
expect 0 'node 0 "box", mesh "[^"]*": 48$' -- "$bin" info "$work/box.gltf" --volumes
expect 0 'volumes      1 of 1 instances closed, 48 enclosed in all' -- "$bin" info "$work/box.gltf" --volumes
expect 0 'not closed \(3 open edges, 0 shared' -- "$bin" info "$work/open.gltf" --volumes

# 6. Point sets: the same cloud as .npy, .ply and text gives the same k nearest points in every
# structure, equal to NumPy's brute force; a glTF POINTS primitive is queried at its node's
# placement, and rendered behind the triangle that hides it the image equals that of the file
# without it.
$py - "$work" <<'P' || fail "writing the point files"
import base64, json, struct, sys
import numpy as np
w = sys.argv[1]
rng = np.random.default_rng(5)
pts = rng.uniform(-1, 1, size=(500, 3)).astype(np.float32)
np.save(f"{w}/cloud.npy", pts)
np.savetxt(f"{w}/cloud.txt", pts, fmt="%.9g")
with open(f"{w}/cloud.ply", "w") as f:
    f.write(f"ply\nformat ascii 1.0\nelement vertex {len(pts)}\nproperty float x\nproperty float y\nproperty float z\nend_header\n")
    for p in pts:
        f.write("%.9g %.9g %.9g\n" % tuple(p))
q = rng.uniform(-1.2, 1.2, size=(20, 3)).astype(np.float32)
np.savetxt(f"{w}/probes.txt", q, fmt="%.9g")
d = np.linalg.norm(pts[None, :, :].astype(np.float64) - q[:, None, :].astype(np.float64), axis=2)
json.dump({"ids": np.argsort(d, axis=1, kind="stable")[:, :3].tolist(), "d": np.sort(d, axis=1)[:, :3].tolist()},
          open(f"{w}/brute_points.json", "w"))
# A triangle and, at node translation (0, 0, -3), a POINTS primitive of three points.
tri = struct.pack("<9f", -1, -1, 0, 1, -1, 0, 0, 1, 0)
cloud = struct.pack("<9f", 0, 0, 0, 0.5, 0, 0, 0, 0.5, 0)
blob = tri + cloud
def gltf(with_points):
    prims = [{"attributes": {"POSITION": 0}}]
    nodes = [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 4]}]
    meshes = [{"primitives": prims}]
    if with_points:
        meshes.append({"primitives": [{"attributes": {"POSITION": 1}, "mode": 0}]})
        nodes.append({"mesh": 1, "translation": [0, 0, -3], "name": "cloud"})
    return {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
            "meshes": meshes, "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
                          {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [0.5, 0.5, 0]}],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 36}],
            "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]}
json.dump(gltf(True), open(f"{w}/points.gltf", "w"))
json.dump(gltf(False), open(f"{w}/nopoints.gltf", "w"))
P
for f in cloud.npy cloud.ply cloud.txt; do
  accels="brute bvh kdtree grid octree bsp embree"
  [ "$f" = cloud.npy ] || accels="brute embree"  # the readers agree; the structures, on one of them
  for accel in $accels; do
    "$bin" query nearest "$work/$f" --points "$work/probes.txt" --k 3 --json --accel "$accel" >"$work/pq.json" 2>"$work/err" ||
      fail "$f --accel $accel: exit $? $(head -2 "$work/err")"
    $py - "$work/pq.json" "$work/brute_points.json" <<'P' && passes=$((passes + 1)) || fail "$f --accel $accel: not the brute-force nearest points"
import json, math, sys
got = json.load(open(sys.argv[1]))["results"]
want = json.load(open(sys.argv[2]))
assert len(got) == 20
for r, ids, ds in zip(got, want["ids"], want["d"]):
    assert [m["point_index"] for m in r["matches"]] == ids, (r["matches"], ids)
    assert all(math.isclose(m["distance"], d, rel_tol=1e-5, abs_tol=1e-6) for m, d in zip(r["matches"], ds))
P
  done
done
expect 0 'point set 0 "cloud" point [0-9]+' -- "$bin" query nearest "$work/cloud.npy" --at 0,0,0
"$bin" query nearest "$work/points.gltf" --at 0.45,0.05,-2.9 --json >"$work/gp.json" 2>"$work/gp.err" || fail "query a glTF POINTS primitive"
$py - "$work/gp.json" <<'P' && passes=$((passes + 1)) || fail "the POINTS primitive is not found at its node's placement"
import json, math, sys
(m,) = json.load(open(sys.argv[1]))["results"][0]["matches"]
assert m["node_name"] == "cloud" and m["point_index"] == 1 and m["point"] == [0.5, 0.0, -3.0], m
assert math.isclose(m["distance"], math.sqrt(0.05 ** 2 * 2 + 0.1 ** 2), rel_tol=1e-5), m
P
expect 0 'points       3 ' -- "$bin" info "$work/points.gltf"
if command -v oiiotool >/dev/null; then
  for accel in embree bvh; do  # the points' spheres lie behind the triangle
    "$bin" render "$work/points.gltf" -o "$work/with.exr" --width 48 --spp 1 --accel "$accel" --no-png -q --aov id,Z &&
      "$bin" render "$work/nopoints.gltf" -o "$work/without.exr" --width 48 --spp 1 --accel "$accel" --no-png -q --aov id,Z ||
      fail "render the POINTS scene ($accel)"
    expect 0 "PASS" -- oiiotool "$work/with.exr" "$work/without.exr" --fail 0 --diff
  done
fi

# 7. Bad input: exit 2, the option, file or line named.
expect 2 "error: --at: 'nan,0,0' is not 3 finite numbers" -- "$bin" query nearest "$scene" --at nan,0,0
expect 2 "error: --at: '1,2' is not 3 finite numbers" -- "$bin" query nearest "$scene" --at 1,2
expect 2 'error: .*--k' -- "$bin" query nearest "$scene" --at 0,0,0 --k 0
expect 2 'error: .*--k' -- "$bin" query nearest "$scene" --at 0,0,0 --k 100000000
printf '1 2 3\n1 2 x\n' >"$work/bad.txt"
expect 2 "error: $work/bad.txt: line 2: is not three finite numbers" -- "$bin" query nearest "$scene" --points "$work/bad.txt"
printf '1 2 3 4\n' >"$work/four.txt"
expect 2 "error: $work/four.txt: line 1: has more than three numbers" -- "$bin" query within "$scene" --points "$work/four.txt" --radius 1
printf '# nothing\n' >"$work/empty.txt"
expect 2 "error: $work/empty.txt: holds no point" -- "$bin" query nearest "$scene" --points "$work/empty.txt"
expect 2 "error: $work/missing.txt: cannot be read" -- "$bin" query nearest "$scene" --points "$work/missing.txt"
expect 2 'error: query: give one of --at X,Y,Z and --points FILE' -- "$bin" query nearest "$scene" --at 0,0,0 --points "$work/points.txt"
expect 2 'error: query: give one of --at X,Y,Z and --points FILE' -- "$bin" query within "$scene" --radius 1
expect 2 "error: --box: '1,1,1,0,0,0' has a minimum above its maximum" -- "$bin" query overlap "$scene" --box 1,1,1,0,0,0
expect 2 'error: query overlap: give one of --box and --sphere' -- "$bin" query overlap "$scene"
expect 2 'error: --dir: the direction must not be zero' -- "$bin" query ray "$scene" --from 0,0,0 --dir 0,0,0
expect 2 'error: .*--radius' -- "$bin" query within "$scene" --at 0,0,0 --radius -1
cat >"$work/empty.gltf" <<'G'
{"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0}
G
expect 2 "error: $work/empty.gltf: holds no geometry to query" -- "$bin" query nearest "$work/empty.gltf" --at 0,0,0
expect 2 'error: .*(subcommand|query)' -- "$bin" query
expect 2 'error: --pixel 64,0 is outside the 64x36 image' -- "$bin" query pick "$scene" --pixel 64,0 --width 64 --height 36
expect 2 "error: --pixel: '1.5,2' is not two whole numbers" -- "$bin" query pick "$scene" --pixel 1.5,2
expect 2 "error: --pixel: '1' is not 2 finite numbers" -- "$bin" query pick "$scene" --pixel 1
expect 2 'error: .*--pixel.*required' -- "$bin" query pick "$scene"
expect 2 'error: query pick: --frame picks a --turntable frame' -- "$bin" query pick "$scene" --pixel 1,1 --frame 3
expect 2 'error: --look-at: the eye and the target are the same point' -- "$bin" query pick "$scene" --pixel 1,1 --look-at 1,1,1 1,1,1
expect 2 'error: --max-memory: --k 65536 needs' -- "$bin" query nearest "$scene" --at 0,0,0 --k 65536 --max-memory 40M
printf 'not numpy' >"$work/bad.npy"
expect 2 "error: $work/bad.npy: header: is not a NumPy .npy file" -- "$bin" query nearest "$work/bad.npy" --at 0,0,0
$py -c 'import numpy as np, sys; np.save(sys.argv[1], np.zeros((4, 2))); np.save(sys.argv[2], np.array([[0, 0, np.nan]])); np.save(sys.argv[3], np.zeros((3, 3), dtype=np.int32))' \
  "$work/two.npy" "$work/nan.npy" "$work/int.npy"
expect 2 "error: $work/two.npy: header: shape \(4,2\) is not \(N, 3\)" -- "$bin" query nearest "$work/two.npy" --at 0,0,0
expect 2 "error: $work/nan.npy: row 0: is not three finite numbers" -- "$bin" query nearest "$work/nan.npy" --at 0,0,0
expect 2 "error: $work/int.npy: header: dtype '<i4' is not little-endian float32" -- "$bin" query nearest "$work/int.npy" --at 0,0,0
head -c 200 "$work/cloud.npy" >"$work/short.npy"
expect 2 "error: $work/short.npy: is truncated" -- "$bin" query nearest "$work/short.npy" --at 0,0,0
expect 2 "error: $work/two.npy: header: shape" -- "$bin" query nearest "$scene" --points "$work/two.npy"
expect 2 'error: query: --time, --variant and --scene apply to glTF scenes' -- "$bin" query nearest "$work/cloud.npy" --at 0,0,0 --time 1

echo "query: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
