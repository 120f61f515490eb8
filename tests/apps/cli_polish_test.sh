#!/usr/bin/env bash
# The command line's messages and machine-readable outputs, end to end: every error line starts
# "penumbra: error:" (CLI11's parse errors too) and exits 2 while --help and --version exit 0;
# unknown options and commands name the closest known one; scene files in other 3D formats are
# named (by extension and by content) by render, info, mesh and batch; `info --json` parses and
# agrees with the glTF file and the text output; `render --progress json` writes only JSON lines
# with monotone fractions per phase (also under batch); the loading and building lines.
# Usage: cli_polish_test.sh PENUMBRA SRC WORK
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
py=/usr/bin/python3
fails=0; passes=0

# expect CODE PATTERN -- command...: counts a pass or a failure in $passes / $fails.
source "$(dirname "$0")/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
ok() { passes=$((passes + 1)); }
# expect_err CODE LINE -- command...: exits with CODE and stderr is exactly LINE (one line).
expect_err() {
  local code="$1" want="$2"; shift 3
  "$@" >"$work/out" 2>"$work/err"; local rc=$?
  if [ "$rc" -ne "$code" ] || [ "$(cat "$work/err")" != "$want" ]; then
    echo "FAIL: [$*] exit $rc (want $code)"; echo "  want | $want"; sed 's/^/  got  | /' "$work/err" | head -5
    fails=$((fails + 1))
  else
    ok
  fi
}
# all_errors_prefixed: every line of $work/err starts with "penumbra: error: ".
all_errors_prefixed() {
  if [ -s "$work/err" ] && ! grep -qv '^penumbra: error: ' "$work/err"; then ok;
  else fail "$1: stderr lines without 'penumbra: error: '"; sed 's/^/  | /' "$work/err" | head -5; fi
}

src="$(cd "$src" && pwd)"
d="$src/scenes/default.gltf"

# --- 1. Errors start with "penumbra: error:"; --help and --version are unchanged. -----------
expect 0 "^penumbra [0-9]+\.[0-9]+" -- "$bin" --version
[ ! -s "$work/err" ] && ok || fail "--version wrote to stderr"
expect 0 "Usage: .*render \[OPTIONS\] scene" -- "$bin" render --help
[ ! -s "$work/err" ] && ok || fail "render --help wrote to stderr"
# Every structure the factory builds is named by the help of each command that takes --accel.
for cmd in render info; do
  "$bin" $cmd --help >"$work/help.txt" 2>&1
  for accel in embree bvh kdtree grid octree bsp brute; do
    grep -A3 -- "--accel " "$work/help.txt" | grep -q "$accel" && ok || fail "$cmd --help does not name $accel"
  done
done
expect 0 "Usage: .*info" -- "$bin" info --help
for args in "render" "render $d" "render $d -o $work/a.exr --spp 0" "render $d -o $work/a.exr --width abc" \
            "render $d -o $work/a.exr --frame 1 --time 2" "render $d -o $work/a.exr --crop 1 2" \
            "info" "merge" "batch" "mesh $d -o $work/m.glb" "submit slurm" "proxies $d" "collide"; do
  # shellcheck disable=SC2086
  "$bin" $args >"$work/out" 2>"$work/err"; rc=$?
  [ "$rc" -eq 2 ] && ok || fail "penumbra $args: exit $rc, want 2"
  all_errors_prefixed "penumbra $args"
done
expect_err 2 "penumbra: error: scene is required" -- "$bin" render
expect_err 2 "penumbra: error: --spp: Value 0 not in range 1 to 65536" -- "$bin" render "$d" -o "$work/a.exr" --spp 0
expect_err 2 "penumbra: error: a command is required: render, info, merge, deep, denoise, batch, submit, mesh, proxies, collide, query (penumbra --help describes them)" -- "$bin"
expect_err 2 "penumbra: error: a command is required for submit: slurm (penumbra submit --help describes them)" -- "$bin" submit
# Errors after parsing (bad input) and warnings carry the same prefixes.
expect_err 2 "penumbra: error: $work/missing.gltf: file not found" -- "$bin" info "$work/missing.gltf"
expect_err 2 "penumbra: error: --progress: sometimes not in {auto,text,json,none}" -- "$bin" render "$d" -o "$work/a.exr" --progress sometimes

# --- 2. Unknown options and commands: the closest known name, if close enough. -------------
expect_err 2 "penumbra: error: unknown option --sp (did you mean --spp?)" -- "$bin" render "$d" -o "$work/a.exr" --sp 4
expect_err 2 "penumbra: error: unknown option --sp (did you mean --spp?)" -- "$bin" render "$d" -o "$work/a.exr" --sp=4
expect_err 2 "penumbra: error: unknown option -spp (did you mean --spp?)" -- "$bin" render "$d" -o "$work/a.exr" -spp 4
expect_err 2 "penumbra: error: unknown option --intgrator (did you mean --integrator?)" -- "$bin" render "$d" -o "$work/a.exr" --intgrator path
expect_err 2 "penumbra: error: unknown option --tiel (did you mean --tile?)" -- "$bin" render "$d" -o "$work/a.exr" --tiel 0/2
expect_err 2 "penumbra: error: unknown option --no-such-flag (penumbra render --help lists the options)" -- "$bin" render "$d" -o "$work/a.exr" --no-such-flag
expect_err 2 "penumbra: error: unknown option --jsn (did you mean --json?)" -- "$bin" info "$d" --jsn
expect_err 2 "penumbra: error: unknown option --unti (did you mean --unit?)" -- "$bin" batch "$work/job.json" --unti 3
expect_err 2 "penumbra: error: unknown option --forc (did you mean --force?)" -- "$bin" merge "$work/a.exr" -o "$work/b.exr" --forc
# Options of another subcommand are not suggested: --json is info's, not render's.
expect_err 2 "penumbra: error: unknown option --jsn (penumbra render --help lists the options)" -- "$bin" render "$d" -o "$work/a.exr" --jsn
# Two unknown options: one line each.
"$bin" render "$d" -o "$work/a.exr" --sp 4 --widht 10 >"$work/out" 2>"$work/err"
printf 'penumbra: error: unknown option --sp (did you mean --spp?)\npenumbra: error: unknown option --widht (did you mean --width?)\n' >"$work/want"
cmp -s "$work/err" "$work/want" && ok || { fail "two unknown options:"; sed 's/^/  | /' "$work/err"; }
expect_err 2 "penumbra: error: unexpected argument extra.gltf (penumbra render --help lists what it takes)" -- "$bin" render "$d" extra.gltf -o "$work/a.exr"
expect_err 2 "penumbra: error: unknown command rendr (did you mean render?)" -- "$bin" rendr "$d"
expect_err 2 "penumbra: error: unknown command ifno (did you mean info?)" -- "$bin" ifno "$d"
expect_err 2 "penumbra: error: unknown command slrm for submit (did you mean slurm?)" -- "$bin" submit slrm job.json
expect_err 2 "penumbra: error: unknown command paint (penumbra --help lists the commands)" -- "$bin" paint "$d"
[ ! -e "$work/a.exr" ] && ok || fail "a refused command line wrote $work/a.exr"

# --- 3. Other 3D formats are named, by extension and by content. ---------------------------
hint="; Penumbra reads glTF 2.0 (.gltf, .glb) — convert it, e.g. with Blender's glTF exporter (File > Import, then File > Export > glTF 2.0)"
printf '# cube\nmtllib cube.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$work/cube.obj"
cp "$work/cube.obj" "$work/cube-obj.gltf"
cp "$work/cube.obj" "$work/cube-obj.glb"
printf 'ply\nformat ascii 1.0\nelement vertex 0\nend_header\n' >"$work/cloud.ply"
cp "$work/cloud.ply" "$work/cloud-ply.gltf"
printf 'solid part\nendsolid part\n' >"$work/part-stl.glb"
printf '#usda 1.0\n' >"$work/stage-usda.gltf"
cp "$d" "$work/really-gltf.fbx"  # by extension, whatever the bytes
for f in cube.obj:"a Wavefront OBJ file" cube-obj.gltf:"a Wavefront OBJ file" cube-obj.glb:"a Wavefront OBJ file" \
         cloud.ply:"a PLY (Stanford polygon) file" cloud-ply.gltf:"a PLY (Stanford polygon) file" \
         part-stl.glb:"an STL file" stage-usda.gltf:"a USD file" really-gltf.fbx:"an FBX file"; do
  file="${f%%:*}"; kind="${f#*:}"
  want="penumbra: error: $work/$file: this is $kind$hint"
  expect_err 2 "$want" -- "$bin" info "$work/$file"
  expect_err 2 "$want" -- "$bin" render "$work/$file" -o "$work/x.exr" -q
done
for ext in usd usdc usdz abc blend dae; do
  cp "$work/cube.obj" "$work/scene.$ext"
  expect 2 "penumbra: error: $work/scene.$ext: this is an? [A-Za-z]+ file; Penumbra reads glTF 2.0" -- "$bin" info "$work/scene.$ext"
done
expect_err 2 "penumbra: error: $work/cube.obj: this is a Wavefront OBJ file$hint" -- "$bin" mesh "$work/cube.obj" -o "$work/m.glb" --resolution 8 -q
printf 'hello\n' >"$work/text.gltf"
expect_err 2 "penumbra: error: $work/text.gltf: this is not a glTF file: it starts with neither a JSON object nor the GLB magic 'glTF'; Penumbra reads glTF 2.0 (.gltf, .glb)" -- "$bin" info "$work/text.gltf"
: >"$work/empty.gltf"
expect_err 2 "penumbra: error: $work/empty.gltf: this is an empty file; Penumbra reads glTF 2.0 (.gltf, .glb)" -- "$bin" info "$work/empty.gltf"
# A batch shot: the job file and the shot, then the scene and its format.
cat >"$work/obj-job.json" <<EOF
{"version": 1, "defaults": {"width": 16, "height": 9, "spp": 1},
 "shots": [{"name": "cube", "scene": "cube-obj.gltf", "output": "$work/cube.exr"}]}
EOF
expect_err 2 "penumbra: error: $work/obj-job.json: shots[0] (cube): $work/cube-obj.gltf: this is a Wavefront OBJ file$hint" -- "$bin" batch "$work/obj-job.json" -q
[ ! -e "$work/x.exr" ] && [ ! -e "$work/cube.exr" ] && ok || fail "a refused scene left an output"

# Warnings keep their own prefix; with JSON progress they are JSON objects too.
"$py" -c 'import json,sys; j=json.load(open(sys.argv[1])); j["extensionsUsed"].append("EXT_unknown_thing"); json.dump(j, open(sys.argv[2], "w"))' "$d" "$work/warn.gltf"
expect 0 "^penumbra: warning: $work/warn.gltf: extensionsUsed: extension EXT_unknown_thing is not supported and will be ignored$" -- "$bin" render "$work/warn.gltf" -o "$work/w.exr" --width 16 --spp 1
expect 0 '^\{"warning":"[^"]*warn.gltf: extensionsUsed: extension EXT_unknown_thing is not supported and will be ignored"\}$' -- "$bin" render "$work/warn.gltf" -o "$work/w.exr" --width 16 --spp 1 --progress json
expect 0 '^unsupported ignored False$' -- "$py" -c 'import json,sys; e=json.load(sys.stdin)["extensions"][1]; print(e["support"], e["note"], e["required"])' < <("$bin" info "$work/warn.gltf" --json 2>/dev/null)

# --- 4. info --json: one document, the same facts as the text and the file. -----------------
expect 0 "4646 triangles rendered" -- "$bin" info "$d"
cp "$work/out" "$work/info.txt"
for accel in embree bvh grid; do
  "$bin" info "$d" --json --accel "$accel" >"$work/info-$accel.json" 2>"$work/err"; rc=$?
  [ "$rc" -eq 0 ] && ok || fail "info --json --accel $accel: exit $rc"
done
"$bin" info "$d" --accel bvh >"$work/info-bvh.txt"
# shellcheck disable=SC2016
check_info='
import json, re, sys
info = json.load(open(sys.argv[1]))
gltf = json.load(open(sys.argv[2]))
text = open(sys.argv[3]).read()
bvh = json.load(open(sys.argv[4]))
bvh_text = open(sys.argv[5]).read()
problems = []
def check(what, got, want, tol=None):
    good = abs(got - want) <= tol * max(1.0, abs(want)) if tol is not None else got == want
    if not good: problems.append("%s: %r, want %r" % (what, got, want))
for key in ["schema", "file", "asset", "scenes", "scene", "nodes", "meshes", "primitives", "stored", "instances",
            "shapes", "materials", "cameras", "cameras_defined", "lights", "lights_defined", "images", "textures",
            "animations", "extensions", "variants", "environment", "bounds", "accelerator", "warnings"]:
    if key not in info: problems.append("no key " + key)
check("schema", info["schema"], 1)
check("file", info["file"], sys.argv[2])
check("asset.version", info["asset"]["version"], gltf["asset"]["version"])
check("scenes", [s["name"] for s in info["scenes"]], [s["name"] for s in gltf["scenes"]])
check("scene", info["scene"], gltf.get("scene", 0))
check("nodes", info["nodes"], len(gltf["nodes"]))
check("mesh names", [m["name"] for m in info["meshes"]], [m["name"] for m in gltf["meshes"]])
check("mesh primitives", [m["primitives"] for m in info["meshes"]], [len(m["primitives"]) for m in gltf["meshes"]])
# Indexed triangle lists: a primitive has count / 3 triangles.
want_tris = [sum(gltf["accessors"][p["indices"]]["count"] // 3 for p in m["primitives"]) for m in gltf["meshes"]]
check("mesh triangles", [m["triangles"] for m in info["meshes"]], want_tris)
check("primitives", info["primitives"], sum(len(m["primitives"]) for m in gltf["meshes"]))
check("materials", [m["name"] for m in info["materials"]], [m["name"] for m in gltf["materials"]])
for m, g in zip(info["materials"], gltf["materials"]):
    pbr = g.get("pbrMetallicRoughness", {})
    for k in range(3): check(m["name"] + " base_color", m["base_color"][k], pbr.get("baseColorFactor", [1, 1, 1, 1])[k], 1e-6)
    check(m["name"] + " metallic", m["metallic"], pbr.get("metallicFactor", 1), 1e-6)
    check(m["name"] + " roughness", m["roughness"], pbr.get("roughnessFactor", 1), 1e-6)
check("cameras_defined", info["cameras_defined"], len(gltf["cameras"]))
cam, gcam = info["cameras"][0], gltf["cameras"][0]
check("camera name", cam["name"], gcam["name"])
check("camera type", cam["type"], gcam["type"])
for key, gkey in [("yfov", "yfov"), ("aspect", "aspectRatio"), ("znear", "znear"), ("zfar", "zfar")]:
    check("camera " + key, cam[key], gcam["perspective"][gkey], 1e-6)
glights = gltf["extensions"]["KHR_lights_punctual"]["lights"]
check("lights_defined", info["lights_defined"], len(glights))
check("lights", [(l["name"], l["type"], l["intensity"]) for l in info["lights"]],
      [(l["name"], l["type"], l["intensity"]) for l in glights])
check("extensions", [(e["name"], e["support"]) for e in info["extensions"]], [(e, "supported") for e in gltf["extensionsUsed"]])
check("variants", info["variants"], [])
check("environment", info["environment"], None)
# The text output: the same counts and figures.
def field(pattern, source=text):
    m = re.search(pattern, source, re.M)
    if not m: problems.append("text has no " + pattern); return None
    return m.groups()
g = field(r"^meshes +(\d+) \((\d+) primitives\); stored: (\d+) triangle meshes, (\d+) triangles")
if g: check("text meshes", [len(info["meshes"]), info["primitives"], info["stored"]["meshes"], info["stored"]["triangles"]], [int(x) for x in g])
g = field(r"^instances +(\d+) \((\d+) in world space, (\d+) placed by a transform\), (\d+) triangles rendered")
i = info["instances"]
if g: check("text instances", [i["count"], i["world_space"], i["placed"], i["triangles"]], [int(x) for x in g])
g = field(r"^bounds +\(([-\d.e+]+), ([-\d.e+]+), ([-\d.e+]+)\) - \(([-\d.e+]+), ([-\d.e+]+), ([-\d.e+]+)\)")
if g:
    for k, v in enumerate(info["bounds"]["min"] + info["bounds"]["max"]): check("text bounds %d" % k, v, float(g[k]), 1e-3)
g = field(r"^accelerator +(\S+)")
if g: check("text accelerator", info["accelerator"]["name"], g[0])
g = field(r"^  triangles +(\d+)")
if g: check("text accelerator triangles", info["accelerator"]["triangles"], int(g[0]))
check("embree nodes", info["accelerator"]["nodes"], None)
g = field(r"^  nodes +(\d+)", bvh_text)
if g: check("bvh nodes", bvh["accelerator"]["nodes"], int(g[0]))
g = field(r"^  leaves +(\d+)", bvh_text)
if g: check("bvh leaves", bvh["accelerator"]["leaves"], int(g[0]))
g = field(r"^  SAH cost +([\d.]+)", bvh_text)
if g: check("bvh SAH cost", bvh["accelerator"]["sah_cost"], float(g[0]), 0.01)
g = field(r"^warnings +(\d+)")
if g: check("text warnings", len(info["warnings"]), int(g[0]))
if problems: sys.exit("\n".join(problems))
print("info json ok")
'
expect 0 "^info json ok$" -- "$py" -c "$check_info" "$work/info-embree.json" "$d" "$work/info.txt" "$work/info-bvh.json" "$work/info-bvh.txt"
expect 0 "^grid None None$" -- "$py" -c 'import json,sys; a=json.load(open(sys.argv[1]))["accelerator"]; print(a["name"], a["leaves"], a["max_depth"])' "$work/info-grid.json"
# Shapes and procedural materials in the document.
expect 0 "^True True$" -- "$py" -c 'import json,sys; j=json.load(sys.stdin); print(len(j["shapes"]) > 0 and all(s["instances"] >= 1 for s in j["shapes"]), j["extensions"][1]["name"] == "PENUMBRA_shapes")' < <("$bin" info "$src/scenes/csg.gltf" --json)

# --- 5. --progress json: only JSON lines, each phase from 0 to 1, monotone. ----------------
# shellcheck disable=SC2016
check_progress='
import json, sys
want_frames = json.loads(sys.argv[2])
lines = open(sys.argv[1]).read().splitlines()
problems, last, phases, frames = [], {}, [], []
for n, line in enumerate(lines, 1):
    try:
        j = json.loads(line)
    except ValueError:
        problems.append("line %d is not JSON: %r" % (n, line)); continue
    if not isinstance(j, dict) or set(j) != {"phase", "fraction", "elapsed", "eta", "frame"}:
        problems.append("line %d keys: %r" % (n, line)); continue
    p, f = j["phase"], j["fraction"]
    if p not in ("load", "build", "render", "write"): problems.append("line %d phase %r" % (n, p))
    if not (0 <= f <= 1): problems.append("line %d fraction %r" % (n, f))
    if not (isinstance(j["elapsed"], (int, float)) and j["elapsed"] >= 0): problems.append("line %d elapsed" % n)
    if j["eta"] is not None and not j["eta"] >= 0: problems.append("line %d eta" % n)
    if (j["eta"] is None) != (f == 0): problems.append("line %d: eta null exactly at fraction 0" % n)
    key = (p, j["frame"])
    if key not in last:
        if f != 0: problems.append("line %d: %s starts at %r, not 0" % (n, p, f))
        phases.append(p)
        if j["frame"] not in frames: frames.append(j["frame"])
    elif f < last[key]: problems.append("line %d: %s went back from %r to %r" % (n, p, last[key], f))
    elif last[key] == 1: problems.append("line %d: %s continued after 1" % (n, p))
    last[key] = f
for key, f in last.items():
    if f != 1: problems.append("%s of frame %r ended at %r" % (key[0], key[1], f))
if "render" not in phases: problems.append("no render phase")
if frames != want_frames: problems.append("frames %r, want %r" % (frames, want_frames))
if problems: sys.exit("\n".join(problems))
print("progress ok: " + " ".join(dict.fromkeys(phases)))
'
expect 0 "" -- "$bin" render "$d" -o "$work/p.exr" --width 48 --spp 2 --progress json
[ "$(cat "$work/out")" = "$(printf '%s\n%s' "$work/p.exr" "$work/p.png")" ] && ok || fail "--progress json changed stdout: $(cat "$work/out")"
cp "$work/err" "$work/progress.txt"
expect 0 "^progress ok: load build render write$" -- "$py" -c "$check_progress" "$work/progress.txt" '[null]'
# The path tracer's passes, a frame number, a range of frames, under -q and under batch.
"$bin" render "$d" -o "$work/pp.exr" --width 48 --spp 16 --integrator path --frame 7 --progress json --no-png >/dev/null 2>"$work/progress.txt"
expect 0 "^progress ok: load build render write$" -- "$py" -c "$check_progress" "$work/progress.txt" '[7]'
"$bin" render "$d" -o "$work/f.#.exr" --width 32 --spp 1 --frames 1-3 --progress json -q --no-png >/dev/null 2>"$work/progress.txt"
expect 0 "^progress ok: load build render write$" -- "$py" -c "$check_progress" "$work/progress.txt" '[1, 2, 3]'
[ "$(grep -c '"phase":"render","fraction":0.0' "$work/progress.txt")" -eq 3 ] && ok || fail "--frames 1-3: not one render phase per frame"
cat >"$work/job.json" <<EOF
{"version": 1, "defaults": {"width": 16, "height": 9, "spp": 1},
 "shots": [{"name": "a", "scene": "$d", "output": "$work/ja.exr"},
           {"name": "b", "scene": "$d", "output": "$work/jb.#.exr", "frames": "4-5"}]}
EOF
"$bin" batch "$work/job.json" --progress json >/dev/null 2>"$work/progress.txt"; rc=$?
[ "$rc" -eq 0 ] && ok || fail "batch --progress json: exit $rc"
expect 0 "^progress ok: load build render write$" -- "$py" -c "$check_progress" "$work/progress.txt" '[null, 4, 5]'
# none and auto under -q print no progress; text prints the render lines.
expect_err 0 "" -- "$bin" render "$d" -o "$work/n.exr" --width 32 --spp 1 --progress none -q
expect_err 0 "" -- "$bin" render "$d" -o "$work/n.exr" --width 32 --spp 1 -q
expect 0 "^render 100\.0%  elapsed" -- "$bin" render "$d" -o "$work/n.exr" --width 32 --spp 1 --progress text -q

# --- 6. The loading and building lines (not under -q, nor with JSON progress). --------------
expect 0 "" -- "$bin" render "$d" -o "$work/l.exr" --width 32 --spp 1
head -2 "$work/err" >"$work/head"
printf 'penumbra: loading %s…\npenumbra: building embree (4.6k triangles)…\n' "$d" >"$work/want"
cmp -s "$work/head" "$work/want" && ok || { fail "the loading and building lines:"; sed 's/^/  | /' "$work/head"; }
grep -q "^penumbra render $d$" "$work/err" && ok || fail "no summary after the loading lines"
expect 0 "^penumbra: building bvh \(4.6k triangles\)…$" -- "$bin" render "$d" -o "$work/l.exr" --width 32 --spp 1 --accel bvh
expect 0 "^penumbra: building embree \(0 triangles, [0-9]+ shapes\)…$" -- "$bin" render "$src/scenes/csg.gltf" -o "$work/l.exr" --width 32 --spp 1
"$bin" render "$d" -o "$work/l.exr" --width 32 --spp 1 --progress none >/dev/null 2>"$work/err"
! grep -q "loading\|building" "$work/err" && grep -q "^penumbra render" "$work/err" && ok || fail "--progress none: $(head -2 "$work/err")"
# --frames loads the static scene once: one loading line for three frames.
"$bin" render "$d" -o "$work/g.#.exr" --width 16 --spp 1 --frames 1-3 --no-png >/dev/null 2>"$work/err"
[ "$(grep -c '^penumbra: loading' "$work/err")" -eq 1 ] && [ "$(grep -c '^penumbra: building' "$work/err")" -eq 1 ] && ok ||
  fail "--frames 1-3 of a static scene: $(grep -c '^penumbra: loading' "$work/err") loading lines"

echo "cli polish: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
