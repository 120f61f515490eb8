#!/usr/bin/env bash
# The camera flags end to end: a unit sphere at a known distance gives the analytic Z at the
# image centre and fills the analytic share of the frame for --fov and --focal-length/--sensor;
# --orbit 0,0 is the look-at from +Z; `info` prints the view and projection matrices (checked
# against hand-computed ones); turntable frame N is frame 0 and frame k is the orbit at
# 360 k / N; framed views touch the border within one pixel on the limiting axis (perspective,
# orthographic, Euler angles, the rasterizer); contact sheets; job files; and bad values exit 2
# naming the flag, writing nothing.
# Usage: camera_test.sh PENUMBRA SRC WORK_DIR
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
# check NAME PYTHON-EXPRESSION: passes when the expression is true.
check() {
  if python3 -c "import math, sys; sys.exit(0 if ($2) else 1)"; then ok; else fail "$1: $2"; fi
}
stat_avg() {  # FILE CHANNEL [CUT]: the channel's mean (over a cut region if given)
  oiiotool "$1" --ch "$2" ${3:+--cut "$3"} --printstats 2>/dev/null | sed -n 's/.*Avg: *\([0-9.e+-]*\).*/\1/p' | head -1
}
same_pixels() {
  oiiotool "$1" "$2" --fail 0 --diff >"$work/diff.txt" 2>&1 && ok || { fail "pixels of $1 and $2 differ"; sed 's/^/  | /' "$work/diff.txt" | head -4; }
}
shape_scene() {  # FILE SHAPE-JSON: one PENUMBRA_shapes node
  printf '{"asset":{"version":"2.0"},"extensionsUsed":["PENUMBRA_shapes"],"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"extensions":{"PENUMBRA_shapes":%s}%s}]}\n' "$2" "${3:-}" >"$1"
}
sphere="$work/sphere.gltf"
shape_scene "$sphere" '{"type":"sphere","radius":1}'

# The unit sphere seen from distance d: Z = d - 1 at the centre pixel (odd sizes put a pixel's
# centre on the axis); its silhouette is a disc of radius tan(asin(1/d)) = 1/sqrt(d^2 - 1) on
# the image plane at depth 1, whose share of the 2 tan_x x 2 tan_y frame is the mean alpha.
sphere_view() {  # NAME D W H TAN_Y FLAGS...
  local name="$1" d="$2" w="$3" h="$4" tan_y="$5"; shift 5
  expect 0 "$name.exr" -- "$bin" render "$sphere" --look-at "0,0,$d" 0,0,0 "$@" --width "$w" --height "$h" \
    --spp 16 --aov Z -o "$work/$name.exr" --no-png -q --float
  local z; z=$(stat_avg "$work/$name.exr" Z "1x1+$((w / 2))+$((h / 2))")
  check "$name: Z at the centre is $z" "abs(float('$z') - ($d - 1)) < ${ZTOL:-1e-4}"
  local fill; fill=$(stat_avg "$work/$name.exr" A)
  check "$name: the sphere fills $fill of the frame" \
    "abs(float('$fill') - math.pi / ($d**2 - 1) / (4 * ($tan_y)**2 * $w / $h)) < 0.004"
}
sphere_view fov40 4 255 255 "math.tan(math.radians(20))" --fov 40
sphere_view fov25 6 319 179 "math.tan(math.radians(12.5))" --fov 25
# 50 mm on a 36 mm sensor across the larger (horizontal) side: tan_x = 18 / 50.
sphere_view lens50 5 319 179 "18 / 50 * 179 / 319" --focal-length 50 --sensor 36
sphere_view lens50portrait 5 179 319 "18 / 50" --focal-length 50
# Orthographic: a disc of radius 1 in a frame 3 units high.
expect 0 "ortho.exr" -- "$bin" render "$sphere" --look-at 0,0,4 0,0,0 --ortho 3 --width 255 --height 255 --spp 16 \
  -o "$work/ortho.exr" --no-png -q --float
check "ortho fill" "abs(float('$(stat_avg "$work/ortho.exr" A)') - math.pi / 9) < 0.004"

# --orbit 0,0,D is the look-at from +Z (the same image); azimuth 90 is the look-at from +X.
"$bin" render "$sphere" --orbit 0,0,4 --width 63 --height 47 --spp 2 -o "$work/orbit.exr" --no-png -q
"$bin" render "$sphere" --look-at 0,0,4 0,0,0 --width 63 --height 47 --spp 2 -o "$work/lookat.exr" --no-png -q
same_pixels "$work/orbit.exr" "$work/lookat.exr"

# `info` prints the view and projection matrices; the JSON carries them.
info_json() { "$bin" info "$@" --json >"$work/info.json" 2>"$work/err" || fail "info $*: $(cat "$work/err")"; }
info_json "$src/scenes/default.gltf" --look-at 4,0,3 0,0,0 --fov 90 --width 100 --height 50
check "look-at view matrix" "
(lambda v: all(abs(a - b) < 1e-6 for r, s in zip(v, [[0.6, 0, -0.8, 0], [0, 1, 0, 0], [0.8, 0, 0.6, -5], [0, 0, 0, 1]]) for a, b in zip(r, s)))(
  __import__('json').load(open('$work/info.json'))['view']['view_matrix'])"
check "projection matrix for --fov 90 at 2:1" "
(lambda p: abs(p[0][0] - 0.5) < 1e-6 and abs(p[1][1] - 1) < 1e-6 and p[3][2] == -1)(
  __import__('json').load(open('$work/info.json'))['view']['projection_matrix'])"
expect 0 "view matrix \(world to camera" -- "$bin" info "$src/scenes/default.gltf" --orbit 30,20
expect 0 "projection matrix" -- "$bin" info "$src/scenes/default.gltf" --turntable 12 --frame 5
# The framed --orbit 0,0 of the default scene equals the look-at from its eye to the bounds' centre.
info_json "$src/scenes/default.gltf" --orbit 0,0
python3 - "$work/info.json" >"$work/lookat_args" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
lo, hi, eye = d["bounds"]["min"], d["bounds"]["max"], d["view"]["eye"]
c = [(a + b) / 2 for a, b in zip(lo, hi)]
print(",".join(repr(x) for x in eye), ",".join(repr(x) for x in c))
PY
cp "$work/info.json" "$work/orbit.json"
read -r eye target <"$work/lookat_args"
info_json "$src/scenes/default.gltf" --look-at "$eye" "$target"
check "framed --orbit 0,0 == look-at from +Z" "
(lambda a, b: all(abs(x - y) < 1e-4 for x, y in zip(a['eye'], b['eye'])) and all(abs(x - y) < 1e-5 for r, s in zip(a['view_matrix'], b['view_matrix']) for x, y in zip(r, s)))(
  __import__('json').load(open('$work/orbit.json'))['view'], __import__('json').load(open('$work/info.json'))['view'])"

# Turntables: frame N is frame 0; frame k of N is the orbit at 360 k / N; the contact sheet.
expect 0 "contact sheet of 5 frames" -- "$bin" render "$src/scenes/default.gltf" --turntable 4 --frames 0-4 \
  --turntable-elevation 20 --width 64 --height 36 --spp 1 -o "$work/tt.####.exr" --contact-sheet "$work/sheet.png"
same_pixels "$work/tt.0000.exr" "$work/tt.0004.exr"
check "frames 0 and 1 differ" "'$(oiiotool "$work/tt.0000.exr" "$work/tt.0001.exr" --diff 2>&1 | grep -c FAILURE)' != '0'"
expect 0 "sheet.png *: *134 x *116" -- oiiotool --info "$work/sheet.png"  # 2 x 3 cells of 64 x 36, 2 px gaps
"$bin" render "$sphere" --turntable 8 --orbit 10,30,5 --frame 3 --width 47 --height 31 --spp 2 -o "$work/t3.exr" --no-png -q
"$bin" render "$src/scenes/default.gltf" --turntable 8 --orbit 10,30,5 --frame 2 --width 47 --height 31 --spp 2 -o "$work/d2.exr" --no-png -q
"$bin" render "$src/scenes/default.gltf" --orbit 100,30,5 --width 47 --height 31 --spp 2 -o "$work/o100.exr" --no-png -q
same_pixels "$work/d2.exr" "$work/o100.exr"
info_json "$src/scenes/default.gltf" --turntable 8 --orbit 10,30,5 --frame 3
cp "$work/info.json" "$work/t3.json"
info_json "$src/scenes/default.gltf" --orbit 145,30,5
check "turntable frame 3 of 8 == orbit at 10 + 135 degrees" "
(lambda a, b: all(abs(x - y) < 1e-5 for r, s in zip(a['view_matrix'], b['view_matrix']) for x, y in zip(r, s)))(
  __import__('json').load(open('$work/t3.json'))['view'], __import__('json').load(open('$work/info.json'))['view'])"
# --turntable N alone renders frames 0..N-1 and needs '#'; elevation 90 looks straight down.
expect 0 "t.0002.exr" -- "$bin" render "$sphere" --turntable 3 --turntable-elevation 90 --width 32 --height 32 --spp 1 \
  -o "$work/t.####.exr" --no-png
[ -e "$work/t.0003.exr" ] && fail "--turntable 3 rendered frame 3" || ok
check "elevation 90: the sphere fills the frame's centre" "float('$(stat_avg "$work/t.0001.exr" A 1x1+16+16)') == 1"
expect 2 "--turntable 3 renders 3 frames: -o needs a run of '#'" -- "$bin" render "$sphere" --turntable 3 -o "$work/t.exr"
# The turntable's frames keep the scene at --time (which --frames excludes otherwise).
expect 0 "tt_time.0001.exr" -- "$bin" render "$sphere" --turntable 2 --time 0.5 --width 16 --height 16 --spp 1 \
  -o "$work/tt_time.####.exr" --no-png
expect 2 "--time excludes --frame and --frames" -- "$bin" render "$sphere" --frames 1-2 --time 0.5 -o "$work/x.####.exr"

# Tight framing: the silhouette of a box touches the border within one pixel on the limiting
# axis, and nothing is cut on the other (alpha read back as an 8-bit PGM).
shape_scene "$work/box.gltf" '{"type":"box","size":[3,1,2]}' ',"translation":[1,0.5,-2]'
extent() {  # NAME: prints "left right top bottom" gaps in pixels between the alpha and the border
  oiiotool "$work/$1.exr" --ch A -d uint8 -o "$work/$1.pgm" || { fail "$1: no PGM"; return; }
  python3 - "$work/$1.pgm" <<'PY'
import sys
data = open(sys.argv[1], "rb").read()
parts = data.split(maxsplit=4)
w, h = int(parts[1]), int(parts[2])
px = data[len(data) - w * h:]
cols = [x for x in range(w) if any(px[y * w + x] for y in range(h))]
rows = [y for y in range(h) if any(px[y * w + x] for x in range(w))]
print(cols[0], w - 1 - cols[-1], rows[0], h - 1 - rows[-1])
PY
}
tight() {  # NAME FLAGS...: renders the box framed and checks the gaps
  local name="$1"; shift
  "$bin" render "$work/box.gltf" "$@" --spp 4 -o "$work/$name.exr" --no-png -q || { fail "$name: render failed"; return; }
  local gaps; gaps=$(extent "$name")
  check "$name: gaps (left right top bottom) $gaps" "
(lambda l, r, t, b: min(l, r, t, b) <= 1 and max(l, r, t, b) > 1)(*map(int, '$gaps'.split()))"
}
tight orbit_wide --orbit 30,25 --width 200 --height 100
tight orbit_tall --orbit -60,40 --width 90 --height 200
tight euler --euler 20,-35,10 --width 160 --height 120
tight ortho --orbit 45,30 --ortho fit --width 180 --height 120
tight raster --orbit 30,25 --width 200 --height 100 --integrator raster
tight default_view --width 160 --height 90
tight tt_limiting --turntable 2 --frame 0 --turntable-elevation 10 --width 120 --height 120
# The rasterizer sees the same frame as the ray tracer.
check "raster and whitted cover the same share" \
  "abs(float('$(stat_avg "$work/raster.exr" A)') - float('$(stat_avg "$work/orbit_wide.exr" A)')) < 0.01"

# Job files: camera flags are settings; a turntable needs the shot's frames.
cat >"$work/job.json" <<EOF
{"version": 1, "defaults": {"width": 40, "height": 30, "spp": 1},
 "shots": [{"name": "side", "scene": "sphere.gltf", "output": "$work/job_side.exr", "settings": {"look-at": ["0,0,4", "0,0,0"], "fov": 40}},
           {"name": "turn", "scene": "sphere.gltf", "output": "$work/job_turn.####.exr", "frames": "0-2", "settings": {"turntable": 3}}]}
EOF
expect 0 "" -- "$bin" batch "$work/job.json" -q
[ -e "$work/job_side.exr" ] && [ -e "$work/job_turn.0002.exr" ] && ok || fail "the job's frames are missing"
"$bin" render "$sphere" --look-at 0,0,4 0,0,0 --fov 40 --width 40 --height 30 --spp 1 -o "$work/cli_side.exr" --no-png -q
same_pixels "$work/job_side.exr" "$work/cli_side.exr"
sed 's/"frames": "0-2", //' "$work/job.json" >"$work/job_noframes.json"
expect 2 "turntable.*frames" -- "$bin" batch "$work/job_noframes.json" --list

# Depth of field: defocus spreads coverage but keeps its total (the sphere's mean alpha is the
# pinhole's; Z at the centre averages the lens' samples, within 0.01 of the front); autofocus on the centre puts the sphere's front (depth d - 1) in focus, so the centre
# pixel's Z and the sharp silhouette stay; the lens is in the identity, tiles of another f-number
# refuse to merge; the raster preview warns that it ignores the lens; job files take the settings.
ZTOL=0.01 sphere_view dof_far 4 255 255 "math.tan(math.radians(20))" --fov 40 --aperture-radius 0.3 --focus-distance 12
sphere_view dof_auto 4 255 255 "math.tan(math.radians(20))" --fov 40 --fstop 0.5
sphere_view dof_path 4 255 255 "math.tan(math.radians(20))" --fov 40 --integrator path --aperture-radius 0.2 \
  --focus-at 0,0 --aperture-blades 5 --aperture-rotation 10 --aperture-ratio 1.5
# Defocused, the silhouette's edge is soft: more partly covered pixels than through the pinhole.
partial() {  # FILE: pixels whose alpha is neither 0 nor 1
  oiiotool "$1" --ch A --rangecheck 0.02 0.98 2>/dev/null | sed -n 's/^ *\([0-9]*\) *within range.*/\1/p'
}
check "defocus softens the edge" "int('$(partial "$work/dof_far.exr")') > 4 * int('$(partial "$work/fov40.exr")')"
# In focus at the silhouette's depth (the tangent circle at d - 1/d), the edge stays sharp.
ZTOL=0.01 sphere_view dof_edge 4 255 255 "math.tan(math.radians(20))" --fov 40 --aperture-radius 0.1 --focus-distance 3.75
check "focus on the silhouette keeps the edge" \
  "int('$(partial "$work/dof_edge.exr")') < 1.3 * int('$(partial "$work/fov40.exr")')"
oiiotool --info -v "$work/dof_auto.exr" >"$work/dof_info.txt" 2>&1
grep -q 'fstop=0.5' "$work/dof_info.txt" && grep -q 'aperture [0-9.e-]* focus 3' "$work/dof_info.txt" && ok ||
  fail "the identity lacks the lens: $(grep -o 'camera.lens=[^;]*' "$work/dof_info.txt" | head -1)"
for t in 0 1; do
  "$bin" render "$sphere" --look-at 0,0,4 0,0,0 --width 40 --height 30 --spp 2 --aperture-radius 0.1 \
    --focus-distance "$((3 + t))" --tile "$t/2" -o "$work/dof_tile$t.exr" --no-png -q
done
expect 2 "rendered with other settings" -- "$bin" merge "$work/dof_tile0.exr" "$work/dof_tile1.exr" -o "$work/dof_merged.exr"
expect 0 "ignores depth of field" -- "$bin" render "$sphere" --integrator raster --fstop 2 --width 40 --height 30 \
  -o "$work/dof_raster.exr" --no-png
cat >"$work/dof_job.json" <<EOF
{"version": 1, "defaults": {"width": 40, "height": 30, "spp": 4},
 "shots": [{"name": "dof", "scene": "sphere.gltf", "output": "$work/job_dof.exr",
            "settings": {"look-at": ["0,0,4", "0,0,0"], "aperture-radius": 0.2, "focus-distance": 2, "aperture-blades": 6}}]}
EOF
expect 0 "" -- "$bin" batch "$work/dof_job.json" -q
"$bin" render "$sphere" --look-at 0,0,4 0,0,0 --width 40 --height 30 --spp 4 --aperture-radius 0.2 --focus-distance 2 \
  --aperture-blades 6 -o "$work/cli_dof.exr" --no-png -q
same_pixels "$work/job_dof.exr" "$work/cli_dof.exr"
expect 2 "fstop needs a perspective camera" -- "$bin" render "$sphere" --ortho 3 --fstop 2 -o "$work/bad.exr"
expect 2 "focus_at: pixel 99,0 lies outside" -- "$bin" render "$sphere" --width 40 --aperture-radius 0.1 --focus-at 99,0 \
  -o "$work/bad.exr"
expect 2 "focus_distance needs depth of field" -- "$bin" render "$sphere" --focus-distance 3 -o "$work/bad.exr"
expect 2 "fstop and aperture_radius exclude" -- "$bin" render "$sphere" --fstop 2 --aperture-radius 1 -o "$work/bad.exr"
[ ! -e "$work/bad.exr" ] && ok || fail "a refused render wrote bad.exr"

# Motion blur: the shutter is in the identity (stripes of another shutter refuse to merge), job
# files take the settings, frame ranges blur each frame, the raster preview warns, and the
# shutter's settings need --motion-blur.
motion="$src/scenes/motion.gltf"
expect 0 "" -- "$bin" render "$motion" --time 1 --motion-blur --width 64 --height 36 --spp 4 -o "$work/mb.exr" --no-png -q
oiiotool --info -v "$work/mb.exr" >"$work/mb_info.txt" 2>&1
grep -q 'motion_blur=1' "$work/mb_info.txt" && grep -q 'scene.shutter=0.98958333333333337..1.0104166666666667' \
  "$work/mb_info.txt" && ok || fail "the identity lacks the shutter: $(grep -o 'scene.shutter=[^;]*' "$work/mb_info.txt")"
"$bin" render "$motion" --time 1 --width 64 --height 36 --spp 4 -o "$work/mb_still.exr" --no-png -q
oiiotool "$work/mb.exr" "$work/mb_still.exr" --fail 0 --diff >/dev/null 2>&1 && fail "motion blur changed nothing" || ok
for t in 0 1; do
  "$bin" render "$motion" --time 1 --motion-blur --shutter "0.$((5 + t))" --width 40 --height 30 --spp 2 \
    --tile "$t/2" -o "$work/mb_tile$t.exr" --no-png -q
done
expect 2 "rendered with other settings" -- "$bin" merge "$work/mb_tile0.exr" "$work/mb_tile1.exr" -o "$work/mb_merged.exr"
cat >"$work/mb_job.json" <<EOF
{"version": 1, "defaults": {"width": 40, "height": 30, "spp": 4},
 "shots": [{"name": "mb", "scene": "$motion", "output": "$work/job_mb.####.exr", "frames": "24",
            "settings": {"motion-blur": true, "shutter": 1, "motion-steps": 5}}]}
EOF
expect 0 "" -- "$bin" batch "$work/mb_job.json" -q --output-root "$work"
"$bin" render "$motion" --time 1 --motion-blur --shutter 1 --motion-steps 5 --width 40 --height 30 --spp 4 \
  -o "$work/cli_mb.exr" --no-png -q
same_pixels "$work/job_mb.0024.exr" "$work/cli_mb.exr"
expect 0 "" -- "$bin" render "$motion" --frames 23-24 --motion-blur --width 40 --height 30 --spp 2 \
  -o "$work/mb_frame.####.exr" --no-png -q
[ -e "$work/mb_frame.0023.exr" ] && [ -e "$work/mb_frame.0024.exr" ] && ok || fail "the blurred frames are missing"
# Frame 24 of the range is the single frame 24 (the kept scene is posed and blurred anew).
"$bin" render "$motion" --frame 24 --motion-blur --width 40 --height 30 --spp 2 -o "$work/mb_single.exr" --no-png -q
same_pixels "$work/mb_frame.0024.exr" "$work/mb_single.exr"
expect 0 "ignores motion blur" -- "$bin" render "$motion" --integrator raster --motion-blur --width 40 --height 30 \
  -o "$work/mb_raster.exr" --no-png
# Deformation blur: the corpus' morph-target cube blurs (the file loaded at each step's time)
# with Embree and the own BVH, and differs from its still frame.
corpus="${PENUMBRA_CORPUS:-${PENUMBRA_CORPUS_DEFAULT:-$src/../shared/corpus}}"
morph="$corpus/extensions/AnimatedMorphCube/glTF-Quantized/AnimatedMorphCube.gltf"
if [ -f "$morph" ]; then
  for accel in embree bvh; do
    expect 0 "" -- "$bin" render "$morph" --time 1 --motion-blur --shutter 1 --accel "$accel" --width 48 \
      --height 48 --spp 8 -o "$work/morph_$accel.exr" --no-png -q
  done
  "$bin" render "$morph" --time 1 --width 48 --height 48 --spp 8 -o "$work/morph_still.exr" --no-png -q
  oiiotool "$work/morph_embree.exr" "$work/morph_still.exr" --fail 0 --diff >/dev/null 2>&1 &&
    fail "deformation blur changed nothing" || ok
else
  echo "PENUMBRA_SKIP: corpus not found (set PENUMBRA_CORPUS); deformation blur from the CLI skipped"
fi
expect 2 "shutter needs motion_blur" -- "$bin" render "$motion" --shutter 1 -o "$work/bad.exr"
expect 2 "motion-steps" -- "$bin" render "$motion" --motion-blur --motion-steps 1 -o "$work/bad.exr"
[ ! -e "$work/bad.exr" ] && ok || fail "a refused render wrote bad.exr"

# Bad values: exit 2 naming the flag, nothing written.
refused() {  # PATTERN FLAGS... (the output is $out, bad.exr unless set)
  local pattern="$1"; shift
  rm -f "$work"/bad*
  expect 2 "$pattern" -- "$bin" render "$sphere" -o "$work/${out:-bad.exr}" --width 16 --height 16 "$@"
  ls "$work"/bad* >/dev/null 2>&1 && fail "refused $* left $(ls "$work"/bad*)" || ok
}
refused "up vector is zero" --look-at 0,0,4 0,0,0 0,0,0
refused "eye and the target are the same point" --look-at 1,2,3 1,2,3
refused "up vector is parallel" --look-at 0,4,0 0,0,0 0,1,0
refused "--look-at: eye 'a,b,c'" --look-at a,b,c 0,0,0
refused "--look-at: At least 2" --look-at 0,0,4
refused "--fov: 0 degrees is outside \(0, 180\)" --fov 0
refused "--fov: 180 degrees" --fov 180
refused "--fov: -5 degrees" --fov=-5
refused "--fov: field of view 'nan'" --fov nan
refused "--fov and --focal-length" --fov 30 --focal-length 50
refused "--sensor needs --focal-length" --sensor 24
refused "--focal-length: must be > 0" --focal-length 0
refused "--ortho: the height must be > 0" --ortho=-1
refused "--ortho is an orthographic camera" --ortho 2 --fov 30
refused "--ortho fit frames the bounds" --look-at 0,0,4 0,0,0 --ortho fit
refused "--ortho fit frames the bounds" --orbit 0,0,3 --ortho fit
refused "--look-at: eye '1e39,0,0' is out of single-precision range" --look-at 1e39,0,0 0,0,0
refused "--ortho: height .1e39. is out of single-precision range" --ortho 1e39
refused "--orbit: value '1e39' is out of single-precision range" --orbit 1e39,0
refused "--orbit: azimuth 1.*e\+30 is outside \[-1e6, 1e6\] degrees" --orbit 1e30,0
refused "--euler: roll 10000000 is outside \[-1e6, 1e6\] degrees" --euler 0,0,1e7
refused "--position: position '0,0,1e39' is out of single-precision range" --euler 0,0,0 --position 0,0,1e39
refused "--focal-length: focal length '1e39' is out of single-precision range" --focal-length 1e39
refused "--sensor: sensor size '1e39' is out of single-precision range" --focal-length 50 --sensor 1e39
refused "--near: distance '1e39' is out of single-precision range" --near 1e39
refused "--far: distance '1e39' is out of single-precision range" --far 1e39
# A flag given an empty value is refused, not read as a flag left out.
for flag in --orbit --euler --position --turntable --turntable-elevation --fov --focal-length --sensor --ortho \
  --near --far; do
  refused "$flag: the value is empty" "$flag" ''
done
refused "--look-at: the value is empty" --look-at '' 0,0,0
refused "field of view .* outside \(0, 180\) in single precision" --fov 179.99999999
refused "field of view .* outside \(0, 180\) in single precision" --focal-length 1e-30
refused "the camera lies .* scene units out, beyond 1e\+18" --orbit 0,0 --fov 1e-30
refused "the camera lies .* scene units out" --look-at 1e20,0,0 0,0,0
refused "--turntable: .*\[1, 36000\]" --turntable 0
refused "--turntable: '-3' is not an integer" --turntable=-3
refused "--turntable-elevation needs --turntable" --turntable-elevation 10
refused "--orbit: elevation" --orbit 0,91
refused "--orbit: expected AZ,EL" --orbit 10
refused "--orbit: the distance must be > 0" --orbit 0,0,0
refused "each place the camera" --orbit 0,0 --euler 0,0,0
refused "--position places the camera of --euler" --position 1,2,3
out=bad.##.exr refused "--turntable orbits the bounds" --turntable 4 --look-at 0,0,4 0,0,0
refused "--far must be beyond --near" --near 2 --far 1
refused "far clip distance 1e-05 is not beyond the near one" --orbit 0,0 --far 0.00001
refused "--contact-sheet tiles the frames" --contact-sheet "$work/s.png"
out=bad.##.exr refused "--contact-sheet tiles the frames' display images" --turntable 2 --no-png --contact-sheet "$work/s.png"
out=bad.##.exr refused "--contact-sheet is one image for every frame" --turntable 2 --contact-sheet "$work/s.##.png"
out=bad.##.exr refused "unsupported display image format" --turntable 2 --contact-sheet "$work/s.exr"
out=bad.##.exr refused "--contact-sheet tiles whole frames: not with --debug-pixel" --turntable 2 --contact-sheet "$work/s.png" --debug-pixel 1,1
# A sheet too large for its limits is refused before any frame renders when the size is given,
# else right after the first frame.
expect 2 "sheet of 100 frames exceeds 65536 pixels" -- "$bin" render "$sphere" --frames 0-99 --width 16384 --height 16384 \
  -o "$work/bad.###.exr" --contact-sheet "$work/s.png"
ls "$work"/bad* >/dev/null 2>&1 && fail "the refused sheet left $(ls "$work"/bad*)" || ok
rm -f "$work"/big*
# 60 frames of 64 x 36: the frame's buffers fit 250 KiB, the 398 x 382 RGB sheet does not.
expect 2 "sheet of 60 frames exceeds .* memory budget" -- "$bin" render "$sphere" --turntable 60 --width 64 \
  --max-memory 250K -o "$work/big.####.exr" --contact-sheet "$work/big.png" -q
[ -e "$work/big.0000.exr" ] && [ ! -e "$work/big.0001.exr" ] && [ ! -e "$work/big.png" ] && ok || fail "the oversized sheet was refused at the wrong time: $(ls "$work"/big* 2>&1)"
out=bad.##.exr refused "--contact-sheet.*the same file" --turntable 2 --png "$work/bad.##.png" --contact-sheet "$work/bad.01.png"
expect 2 "up vector is zero" -- "$bin" info "$sphere" --look-at 0,0,4 0,0,0 0,0,0
expect 2 "--orbit: value '1e39' is out of single-precision range" -- "$bin" info "$sphere" --orbit 1e39,0
expect 2 "--orbit: the value is empty" -- "$bin" info "$sphere" --orbit ''
expect 2 "--frame picks a --turntable frame" -- "$bin" info "$sphere" --frame 3

echo "camera: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
