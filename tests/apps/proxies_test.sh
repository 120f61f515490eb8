#!/usr/bin/env bash
# `penumbra proxies` end to end on a generated scene (a box "crate" rotated about Y, its child
# "post", a cylinder, and a flat "floor"):
# - closed forms through --json: the crate's OBB is the box (volume 1, ratio 1 to the mesh, Hausdorff
#   0) while its AABB is larger; the floor's minimal sphere has radius 5 sqrt(2); the crate's
#   sphere and capsule hold every world vertex of the crate; the hull's volume is Qhull's; the
#   subtree (--node crate) is fitted once and holds the post too;
# - every kind written with -o renders, and its image covers the scene's: per camera sample a
#   ray that hits a mesh hits its proxy, so the scene's alpha minus the proxies' is (near) 0;
#   --overlay keeps the meshes under translucent proxies;
# - bad input exits 2 naming the option or node: an unknown kind or node, a bad k, --overlay
#   without -o, a non-glTF output, a scene without meshes, a budget too small.
# Usage: proxies_test.sh PENUMBRA_BINARY WORK_DIR
set -u
bin="$1"; work="$2"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
source "$(dirname "$0")/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
py=/usr/bin/python3

scene="$work/props.gltf"
"$py" - "$scene" <<'PY'
import base64, json, math, struct, sys
pos, idx, meshes = [], [], []
def add_mesh(name, vertices, triangles):
    global pos, idx
    meshes.append((name, len(pos), len(vertices), len(idx), len(triangles) * 3))
    pos += vertices
    idx += [i for t in triangles for i in t]
def box(hx, hy, hz):
    v = [(sx * hx, sy * hy, sz * hz) for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)]
    f = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return v, [t for q in f for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))]
def cylinder(r, h, n):
    v = [(r * math.cos(2 * math.pi * i / n), y, -r * math.sin(2 * math.pi * i / n)) for y in (-h / 2, h / 2) for i in range(n)]
    t = []
    for i in range(n):
        a, b = i, (i + 1) % n
        t += [(a, b, b + n), (a, b + n, a + n)]
    for i in range(1, n - 1):
        t += [(0, i + 1, i), (n, n + i, n + i + 1)]
    return v, t
add_mesh("crate", *box(1, 0.5, 0.25))
add_mesh("post", *cylinder(0.1, 2, 24))
add_mesh("floor", [(-5, 0, -5), (5, 0, -5), (5, 0, 5), (-5, 0, 5)], [(0, 2, 1), (0, 3, 2)])
blob = b"".join(struct.pack("<3f", *p) for p in pos) + b"".join(struct.pack("<I", i) for i in idx)
views, accessors, gmeshes = [], [], []
for name, v0, nv, i0, ni in meshes:
    lo = [min(p[k] for p in pos[v0:v0 + nv]) for k in range(3)]
    hi = [max(p[k] for p in pos[v0:v0 + nv]) for k in range(3)]
    views.append({"buffer": 0, "byteOffset": 12 * v0, "byteLength": 12 * nv})
    accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": nv, "type": "VEC3", "min": lo, "max": hi})
    views.append({"buffer": 0, "byteOffset": 12 * len(pos) + 4 * i0, "byteLength": 4 * ni})
    accessors.append({"bufferView": len(views) - 1, "componentType": 5125, "count": ni, "type": "SCALAR"})
    gmeshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2}, "indices": len(accessors) - 1}]})
s, c = math.sin(math.radians(15)), math.cos(math.radians(15))
doc = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 2, 3]}],
    "nodes": [
        {"name": "crate", "mesh": 0, "translation": [0.5, 0.25, 0.3], "rotation": [0, s, 0, c], "children": [1]},
        {"name": "post", "mesh": 1, "translation": [0.6, 1.5, 0]},
        {"name": "floor", "mesh": 2},
        {"name": "cam", "camera": 0, "translation": [0, 3, 8], "rotation": [-0.1736482, 0, 0, 0.9848078]}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1}}],
    "meshes": gmeshes, "accessors": accessors, "bufferViews": views,
    "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]}
json.dump(doc, open(sys.argv[1], "w"))
PY

# 1. Closed forms and containment through --json.
check_json() {  # check_json KIND ARGS...: runs proxies --json and the Python check of that kind
  local kind="$1"; shift
  if ! "$bin" proxies "$scene" --kind "$kind" --json --samples 4000 "$@" >"$work/$kind.json" 2>"$work/err"; then
    fail "proxies --kind $kind $*: exit $?"; sed 's/^/  | /' "$work/err" | head -3; return
  fi
  if "$py" - "$work/$kind.json" "$kind" <<'PY'; then passes=$((passes + 1)); else fail "proxies --kind $kind: JSON check"; fi
import json, math, sys
doc = json.load(open(sys.argv[1])); kind = sys.argv[2]
by = {p["name"]: p for p in doc["proxies"]}
s, c = math.sin(math.radians(30)), math.cos(math.radians(30))  # the crate's turn about Y
def crate_world(x, y, z):
    return (c * x + s * z + 0.5, y + 0.25, -s * x + c * z + 0.3)
corners = [crate_world(sx, sy * 0.5, sz * 0.25) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
def dist(a, b): return math.dist(a, b)
def seg_dist(p, a, b):
    ab = [b[i] - a[i] for i in range(3)]; l2 = sum(x * x for x in ab)
    t = 0 if l2 == 0 else max(0, min(1, sum((p[i] - a[i]) * ab[i] for i in range(3)) / l2))
    return dist(p, [a[i] + t * ab[i] for i in range(3)])
ok = True
def check(cond, what):
    global ok
    if not cond: print("  check failed:", what, file=sys.stderr); ok = False
if kind in ("obb", "aabb"):
    crate = by["crate"]
    vol = 8 * math.prod(crate["box"]["half_extents"])
    if kind == "obb":
        check(abs(vol - 1) < 1e-5, f"crate OBB volume {vol} != 1")
        check(abs(crate["volume_ratio"] - 1) < 1e-5, "crate OBB ratio")
        check(crate["hausdorff"] < 1e-4, f"crate OBB Hausdorff {crate['hausdorff']}")
    else:
        check(vol > 1.3, f"crate AABB volume {vol} not above the box's")
    check(by["floor"]["mesh_volume"] is None and by["floor"]["volume_ratio"] is None, "floor is open")
    check(by["crate"]["mesh_volume"] is not None and abs(by["crate"]["mesh_volume"] - 1) < 1e-5, "crate volume 1")
if kind in ("sphere", "ritter"):
    r = by["floor"]["sphere"]["radius"]
    if kind == "sphere":
        check(abs(r - 5 * math.sqrt(2)) < 1e-5, f"floor sphere radius {r}")
        check(by["crate"]["sphere"]["radius"] <= by["crate"]["sphere"]["radius"] + 1e-12, "")
    for p in corners:
        check(dist(p, by["crate"]["sphere"]["center"]) <= by["crate"]["sphere"]["radius"] + 1e-5, f"corner {p} outside")
if kind == "capsule":
    cap = by["crate"]["capsule"]
    for p in corners:
        check(seg_dist(p, cap["a"], cap["b"]) <= cap["radius"] + 1e-5, f"corner {p} outside the capsule")
if kind in ("hull", "kdop", "composite"):
    for name, p in by.items():
        for part in p["parts"]:
            if kind == "hull":
                # Qhull measures its joggled hull: equal to rounding, or to 1e-5 for a flat part's thin slab.
                rel = 1e-5 if part["thickened"] else 1e-9
                check(abs(part["volume"] - part["qhull_volume"]) <= rel * part["volume"], f"{name}: hull volume != Qhull's")
            for q in (corners if name == "crate" else []):
                check(all(pl[0] * q[0] + pl[1] * q[1] + pl[2] * q[2] <= pl[3] + 1e-5 for pl in part["planes"]), f"{name}: corner outside")
    if kind == "hull":
        check(abs(by["crate"]["volume"] - 1) < 1e-5, "crate hull volume 1")
        check(by["floor"]["parts"][0]["thickened"], "flat floor thickened")
    if kind == "kdop":
        check(len(by["crate"]["parts"][0]["planes"]) == doc["k"], "k planes")
sys.exit(0 if ok else 1)
PY
}
for kind in sphere ritter aabb obb capsule hull kdop composite; do check_json "$kind"; done
check_json kdop --kdop 14
# The crate's subtree: one proxy holding the post's top (0.6 turned about Y, 1.5 + 1 up).
expect 0 '"name": "crate"' -- "$bin" proxies "$scene" --kind sphere --node crate --json --samples 0
n=$(grep -c '"node":' "$work/out"); [ "$n" = 1 ] && passes=$((passes + 1)) || fail "--node crate: $n proxies, want 1"
"$py" - "$work/out" <<'PY' && passes=$((passes + 1)) || fail "--node crate: the post's top is outside the sphere"
import json, math, sys
p = json.load(open(sys.argv[1]))["proxies"][0]["sphere"]
s, c = math.sin(math.radians(30)), math.cos(math.radians(30))
top = (c * 0.6 + 0.5, 0.25 + 1.5 + 1, -s * 0.6 + 0.3)
sys.exit(0 if math.dist(top, p["center"]) <= p["radius"] + 1e-5 else 1)
PY
expect 0 "node 0 'crate' .*obb centre" -- "$bin" proxies "$scene" --kind obb --samples 100

# 2. Every kind renders, and covers what the scene covers.
"$bin" render "$scene" -o "$work/scene.exr" --width 64 --height 48 --spp 2 --integrator whitted -q \
  || fail "render of the scene"
alpha_excess() {  # alpha_excess PROXY_EXR: the mean of max(0, scene alpha - proxy alpha)
  oiiotool "$work/scene.exr" --ch A "$1" --ch A --sub --clamp:min=0 --printstats 2>/dev/null |
    sed -n 's/.*Avg: *\([0-9.e+-]*\).*/\1/p' | head -1
}
for kind in sphere aabb obb capsule hull kdop composite; do
  expect 0 "$kind.glb" -- "$bin" proxies "$scene" --kind "$kind" --samples 0 -o "$work/$kind.glb"
  if "$bin" render "$work/$kind.glb" -o "$work/$kind.exr" --width 64 --height 48 --spp 2 --integrator whitted -q; then
    e=$(alpha_excess "$work/$kind.exr")
    if "$py" -c "import sys; sys.exit(0 if 0 <= float('$e') < 0.002 else 1)"; then passes=$((passes + 1))
    else fail "$kind proxies do not cover the scene: mean alpha excess $e"; fi
  else
    fail "render of the $kind proxies"
  fi
done
# The hull as .gltf + .bin over the scene: the meshes stay (info counts 3), the proxies are shapes.
expect 0 "overlay.gltf" -- "$bin" proxies "$scene" --kind hull --samples 0 --overlay -o "$work/overlay.gltf"
[ -s "$work/overlay.bin" ] && passes=$((passes + 1)) || fail "overlay.bin missing"
expect 0 "meshes +3" -- "$bin" info "$work/overlay.gltf"
expect 0 "shapes +3" -- "$bin" info "$work/overlay.gltf"

# 3. Refusals, each before anything is written.
expect 2 "--kind cube: not a proxy kind \(sphere, ritter" -- "$bin" proxies "$scene" --kind cube
expect 2 "--node 'nope': .* has no node of that name" -- "$bin" proxies "$scene" --kind obb --node nope
expect 2 "--node 9: .* has 4 nodes" -- "$bin" proxies "$scene" --kind obb --node 9
expect 2 "node 'cam' and the nodes below it place no mesh" -- "$bin" proxies "$scene" --kind obb --node cam
expect 2 "--kdop 10: k must be 6, 14, 18 or 26" -- "$bin" proxies "$scene" --kind kdop --kdop 10
expect 2 "--overlay: .*give -o" -- "$bin" proxies "$scene" --kind obb --overlay
expect 2 "must be a .glb or .gltf" -- "$bin" proxies "$scene" --kind obb -o "$work/x.png"
# 60,000 vertices in an external buffer: the scene loads in 12 MiB, fitting (256 bytes each) does not.
"$py" - "$work/big.gltf" <<'PY'
import json, math, struct, sys
n = 30000
pos = [(math.cos(2 * math.pi * i / n), y, math.sin(2 * math.pi * i / n)) for y in (0, 1) for i in range(n)]
idx = [k for i in range(n) for k in (i, n + (i + 1) % n, (i + 1) % n, i, n + i, n + (i + 1) % n)]
blob = b"".join(struct.pack("<3f", *p) for p in pos) + struct.pack(f"<{len(idx)}I", *idx)
open(sys.argv[1][:-5] + ".bin", "wb").write(blob)
json.dump({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 2 * n, "type": "VEC3",
                          "min": [-1, 0, -1], "max": [1, 1, 1]},
                         {"bufferView": 1, "componentType": 5125, "count": len(idx), "type": "SCALAR"}],
           "bufferViews": [{"buffer": 0, "byteLength": 24 * n}, {"buffer": 0, "byteOffset": 24 * n, "byteLength": 4 * len(idx)}],
           "buffers": [{"byteLength": len(blob), "uri": "big.bin"}]}, open(sys.argv[1], "w"))
PY
expect 2 "60.0k placed vertices with 20.0k samples needs .* over the budget \(--max-memory\)" -- "$bin" proxies "$work/big.gltf" --kind obb --max-memory 12M
expect 2 "with 10.00M samples needs .* over the budget" -- "$bin" proxies "$scene" --kind sphere --samples 10000000 --max-memory 100M
expect 2 "--samples: Value 10000001 not in range" -- "$bin" proxies "$scene" --kind sphere --samples 10000001
[ ! -e "$work/x.png" ] && passes=$((passes + 1)) || fail "a refused run wrote x.png"
printf '{"asset": {"version": "2.0"}, "nodes": [{"name": "lonely"}], "scenes": [{"nodes": [0]}]}' >"$work/empty.gltf"
expect 2 "no node places a mesh" -- "$bin" proxies "$work/empty.gltf" --kind sphere

echo "proxies: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
