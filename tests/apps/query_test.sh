#!/usr/bin/env bash
# `penumbra query` end to end on the shipped default scene:
# - every acceleration structure gives the same JSON answers as brute force on the default and
#   CSG scenes (nearest with k, within, overlap by box, ray), apart from the "accel" field;
#   Embree's ray hit within float rounding (its ray test rounds differently);
# - the surface point a ray hits is at distance 0 from the scene (nearest), on the same node;
# - within's answers are within the radius and nearest first, and equal overlap --sphere's;
#   the k nearest are ordered and the first of them is nearest's k = 1 answer;
# - a points file gives one result per point, the same as --at for each;
# - bad input exits 2 naming the option, the file and the line: NaN, k = 0 or absurd, a
#   malformed or empty points file, both or neither of --at and --points, an inverted box,
#   a zero direction, a scene without geometry.
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

# 4. Bad input: exit 2, the option, file or line named.
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

echo "query: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
