#!/usr/bin/env bash
# Output safety and hostile paths through `penumbra`: what each kind of output target gets
# (regular file, symlink, device node, FIFO, /dev/stdout, directory), a full disk, colliding
# outputs, non-regular inputs, integer options that would wrap, signals in the last pass and
# the statistics' record of the files they describe. Every refusal asserts the exit code, the
# message, and that no pre-existing file changed. Usage: output_safety_test.sh PENUMBRA SRC WORK
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
scene="$src/scenes/default.gltf"
fails=0; passes=0
small=(--width 32 --spp 1 -q)
mounted=""
cleanup() { [ -n "$mounted" ] && umount "$mounted" 2>/dev/null; }
trap cleanup EXIT

fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
pass() { passes=$((passes + 1)); }
expect() {  # expect CODE PATTERN -- command...
  local code="$1" pattern="$2"; shift 3
  timeout 120 "$@" >"$work/out" 2>"$work/err"; local rc=$?
  if [ "$rc" -ne "$code" ] || ! grep -qE -- "$pattern" "$work/out" "$work/err"; then
    fail "[$*] exit $rc (want $code), pattern '$pattern'"; sed 's/^/  | /' "$work/err" | head -5
  else
    pass
  fi
}
sum() { sha256sum "$1" | cut -d' ' -f1; }
unchanged() {  # unchanged FILE HASH: the file still has these bytes
  if [ "$(sum "$1")" = "$2" ]; then pass; else fail "$1 changed"; fi
}
no_temporaries() {  # no_temporaries DIR
  if ls -A "$1" | grep -q '\.tmp-'; then fail "temporaries left in $1: $(ls -A "$1" | grep '\.tmp-')"; else pass; fi
}
json_ok() {  # json_ok FILE: a complete JSON document
  if python3 -c 'import json,sys; json.load(open(sys.argv[1]))' "$1" 2>/dev/null; then pass; else fail "$1 is not complete JSON"; fi
}

# A reference render: the pre-existing files every refusal below must leave alone.
"$bin" render "$scene" -o "$work/keep.exr" "${small[@]}" --stats-json "$work/keep.json" >/dev/null || fail "reference render"
exr_sum=$(sum "$work/keep.exr"); png_sum=$(sum "$work/keep.png"); json_sum=$(sum "$work/keep.json")

# --- Targets: devices and FIFOs are streamed to and stay what they are; symlinks keep pointing
# at their (replaced) target; directories are refused.
if [ "$(id -u)" -eq 0 ]; then
  mknod "$work/full" c 1 7 && mknod "$work/null" c 1 3
  expect 1 "full: write failed: No space left on device" -- "$bin" render "$scene" -o "$work/t1.exr" "${small[@]}" --stats-json "$work/full"
  [ -c "$work/full" ] && pass || fail "the device node $work/full was replaced"
  expect 0 "t2.exr" -- "$bin" render "$scene" -o "$work/t2.exr" "${small[@]}" --stats-json "$work/null"
  [ -c "$work/null" ] && pass || fail "the device node $work/null was replaced"
else
  echo "note: not root: device-node targets not exercised (mknod needs root)"
fi
mkfifo "$work/fifo"
(cat "$work/fifo" > "$work/fifo.out") &
reader=$!
expect 0 "t3.exr" -- "$bin" render "$scene" -o "$work/t3.exr" "${small[@]}" --stats-json "$work/fifo"
wait $reader
[ -p "$work/fifo" ] && pass || fail "the FIFO was replaced"
json_ok "$work/fifo.out"
# A reader that goes away mid-stream: the write fails with EPIPE (exit 1), no temporary stays.
mkfifo "$work/pipe-out.exr"
export TMPDIR="$work/tmp"; mkdir -p "$TMPDIR"
(head -c 100 "$work/pipe-out.exr" >/dev/null) &
expect 1 "pipe-out.exr: write failed: Broken pipe" -- "$bin" render "$scene" -o "$work/pipe-out.exr" --width 400 --spp 1 -q --no-png --float
wait
[ -z "$(ls -A "$TMPDIR")" ] && pass || fail "a broken stream left $(ls -A "$TMPDIR") in \$TMPDIR"
unset TMPDIR
# /dev/stdout: the JSON goes to stdout, and stdout then carries no paths.
timeout 60 "$bin" render "$scene" -o "$work/t4.exr" "${small[@]}" --stats-json /dev/stdout >"$work/stdout.json" 2>"$work/err" \
  && pass || fail "--stats-json /dev/stdout: exit $?"
json_ok "$work/stdout.json"
ln -s "$work/real.json" "$work/link.json"
expect 0 "t5.exr" -- "$bin" render "$scene" -o "$work/t5.exr" "${small[@]}" --stats-json "$work/link.json"
[ -L "$work/link.json" ] && pass || fail "the symlink was replaced by a file"
json_ok "$work/real.json"
mkdir "$work/dir.exr"
expect 2 "-o .*dir.exr: is a directory" -- "$bin" render "$scene" -o "$work/dir.exr" "${small[@]}"
expect 2 "--stats-json .*: is a directory" -- "$bin" render "$scene" -o "$work/t6.exr" "${small[@]}" --stats-json "$work"
[ ! -e "$work/t6.exr" ] && pass || fail "a refused run wrote its EXR"
no_temporaries "$work"

# --- Colliding outputs and outputs over inputs: refused before rendering, nothing changes.
expect 2 "-o .*keep.exr and --stats-json .*keep.exr are the same file" -- "$bin" render "$scene" -o "$work/keep.exr" "${small[@]}" --stats-json "$work/keep.exr"
ln "$work/keep.exr" "$work/hard.json"
expect 2 "are the same file" -- "$bin" render "$scene" -o "$work/keep.exr" "${small[@]}" --stats-json "$work/hard.json"
ln -s keep.exr "$work/alias.json"
expect 2 "are the same file" -- "$bin" render "$scene" -o "$work/keep.exr" "${small[@]}" --stats-json "$work/alias.json"
expect 2 "--png .*keep.png and --cost-png .*keep.png are the same file" -- "$bin" render "$scene" -o "$work/keep.exr" "${small[@]}" --aov cost --cost-png "$work/keep.png"
expect 2 "the resume state .*keep.exr.resume and --stats-json" -- "$bin" render "$scene" -o "$work/keep.exr" "${small[@]}" --integrator path --stats-json "$work/keep.exr.resume"
cp "$scene" "$work/scene.gltf"
scene_sum=$(sum "$work/scene.gltf")
expect 2 "--stats-json .*scene.gltf would overwrite the scene file" -- "$bin" render "$work/scene.gltf" -o "$work/t7.exr" "${small[@]}" --stats-json "$work/scene.gltf"
unchanged "$work/scene.gltf" "$scene_sum"
unchanged "$work/keep.exr" "$exr_sum"; unchanged "$work/keep.png" "$png_sum"; unchanged "$work/keep.json" "$json_sum"
mkfifo "$work/pipe.exr"
expect 2 "--checkpoint and --resume keep their state beside -o" -- "$bin" render "$scene" -o "$work/pipe.exr" "${small[@]}" --integrator path --checkpoint 1

# --- Non-regular inputs never block: FIFOs and devices are named and refused at once.
mkfifo "$work/in.fifo"
expect 2 "in.fifo: --env: is a FIFO, not a regular file" -- "$bin" render "$scene" -o "$work/t8.exr" "${small[@]}" --integrator path --env "$work/in.fifo"
expect 2 "/dev/zero: --env: is a character device, not a regular file" -- "$bin" render "$scene" -o "$work/t8.exr" "${small[@]}" --integrator path --env /dev/zero
expect 2 "in.fifo: --ocio-config: is a FIFO" -- "$bin" render "$scene" -o "$work/t8.exr" "${small[@]}" --ocio-config "$work/in.fifo"
expect 2 "in.fifo: \\\$OCIO: is a FIFO" -- env OCIO="$work/in.fifo" "$bin" render "$scene" -o "$work/t8.exr" "${small[@]}"
expect 2 "in.fifo: .*is a FIFO, not a regular file" -- "$bin" render "$work/in.fifo" -o "$work/t8.exr" "${small[@]}"
expect 2 "in.fifo: .*is a FIFO, not a regular file" -- "$bin" info "$work/in.fifo"
[ ! -e "$work/t8.exr" ] && pass || fail "a refused run wrote its EXR"

# --- Integer options are range-checked: nothing wraps.
expect 2 "--tile N: 4294967297 is outside|--tile: 4294967297 stripes exceed" -- "$bin" render "$scene" -o "$work/t9.exr" "${small[@]}" --tile 0/4294967297
expect 2 "--tile: expected i/N" -- "$bin" render "$scene" -o "$work/t9.exr" "${small[@]}" --tile -0/2
expect 2 "--seed: '-1' is not an integer" -- "$bin" render "$scene" -o "$work/t9.exr" "${small[@]}" --seed -1
expect 2 "--seed: '18446744073709551616' is not an integer" -- "$bin" render "$scene" -o "$work/t9.exr" "${small[@]}" --seed 18446744073709551616
expect 2 "--frame: 99999999999999999999 is outside" -- "$bin" render "$scene" -o "$work/t9.exr" "${small[@]}" --frame 99999999999999999999
expect 2 "--debug-pixel x: 4294967297 is outside" -- "$bin" render "$scene" -o "$work/t9.exr" "${small[@]}" --debug-pixel 4294967297,1
expect 2 "--crop: '0x10' is not an integer" -- "$bin" render "$scene" -o "$work/t9.exr" "${small[@]}" --crop 0x10 20 0 10
expect 2 "--spp: Value 4294967297 not in range" -- "$bin" render "$scene" -o "$work/t9.exr" "${small[@]}" --spp 4294967297
expect 2 "bvh.max_leaf_size: '4294967297' is not a valid" -- "$bin" render "$scene" -o "$work/t9.exr" "${small[@]}" --accel bvh --accel-param bvh.max_leaf_size=4294967297
expect 2 "--accel-param bvh.max_leaf_size=2: a parameter of 'bvh', but --accel is 'embree'" -- "$bin" render "$scene" -o "$work/t9.exr" "${small[@]}" --accel-param bvh.max_leaf_size=2
[ ! -e "$work/t9.exr" ] && pass || fail "a refused run wrote its EXR"

# --- One memory budget: the film and AOV buffers of either integrator are charged up front.
expect 2 "image 16384x16384 \(whitted\) needs [0-9.]+ GiB for the film and output buffers, over the 1.0 GiB budget" -- "$bin" render "$scene" -o "$work/big.exr" --width 16384 --height 16384 --max-memory 1G
expect 2 "image 4096x4096 \(whitted, with AOVs\) needs [0-9.]+ GiB for the film and output buffers, over the 512.0 MiB budget" -- "$bin" render "$scene" -o "$work/big.exr" --width 4096 --height 4096 --aov all --max-memory 512M
expect 0 "big.exr" -- "$bin" render "$scene" -o "$work/big.exr" --width 2048 --height 2048 --spp 1 -q --no-png --max-memory 512M
rm -f "$work/big.exr"

# Memory that runs out anyway (an address-space limit below the budget) ends in a clear message,
# exit 1 and no output. AddressSanitizer reserves terabytes of address space: not under it.
if [ "${PENUMBRA_SANITIZED:-0}" != 1 ]; then
  (ulimit -v 1500000; exec "$bin" render "$scene" -o "$work/oom.exr" --width 8000 --height 8000 --spp 1 --max-memory 16G -q) \
    >"$work/out" 2>"$work/err"; rc=$?
  if [ "$rc" -eq 1 ] && grep -q "out of memory while rendering; no file is left half-written" "$work/err" && [ ! -e "$work/oom.exr" ]; then pass
  else fail "out of memory: exit $rc"; sed 's/^/  | /' "$work/err" | tail -3; fi
fi

# --- A signal in the last pass still ends the run with 128 + signal (143), the image complete.
"$bin" render "$scene" -o "$work/last.exr" --integrator path --width 1280 --spp 1 --no-png >"$work/out" 2>"$work/err" &
pid=$!
for _ in $(seq 400); do grep -q "^render" "$work/err" 2>/dev/null && break; sleep 0.02; done
kill -TERM $pid 2>/dev/null
wait $pid; rc=$?
if grep -q "interrupted by signal 15 during the last pass: the image is complete" "$work/err"; then
  [ "$rc" -eq 143 ] && [ -e "$work/last.exr" ] && [ ! -e "$work/last.exr.resume" ] && pass \
    || fail "signal in the last pass: exit $rc (want 143), EXR and no resume state"
elif [ "$rc" -eq 0 ]; then
  echo "note: the one-pass render finished before the signal; last-pass signal not exercised"
else
  fail "signal in the last pass: exit $rc"; sed 's/^/  | /' "$work/err" | tail -3
fi

# --- The statistics record the SHA-256 of the images as this run wrote them, so a reader can
# tell whether the files at those paths are the ones they describe (concurrent runs on one path).
expect 0 "st.exr" -- "$bin" render "$scene" -o "$work/st.exr" "${small[@]}" --stats-json "$work/st.json"
rec_exr=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["outputs"]["exr"]["sha256"])' "$work/st.json")
rec_png=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["outputs"]["png"]["sha256"])' "$work/st.json")
[ "$rec_exr" = "$(sum "$work/st.exr")" ] && [ "$rec_png" = "$(sum "$work/st.png")" ] && pass || fail "recorded hashes differ from the files"
"$bin" render "$scene" -o "$work/st.exr" --width 40 --spp 1 -q >/dev/null  # another run replaces the EXR
[ "$rec_exr" != "$(sum "$work/st.exr")" ] && pass || fail "a different render has the same hash"

# --- Resume state is verified: a damaged state, a FIFO in its place, or a scene edited to the
# same size since the interrupt are refused (exit 2) and neither the state nor the image changes.
flip() {  # flip FILE OFFSET: invert one byte in place
  python3 -c 'import sys; p, o = sys.argv[1], int(sys.argv[2]); b = bytearray(open(p, "rb").read()); b[o] ^= 0xff; open(p, "wb").write(b)' "$1" "$2"
}
one_pass=(--integrator path --width 24 --spp 64 --no-png -q --checkpoint 1e-9 --time-limit 1e-9)
expect 0 "res.exr" -- "$bin" render "$work/scene.gltf" -o "$work/res.exr" "${one_pass[@]}"
[ -e "$work/res.exr.resume" ] && pass || fail "a time-limited checkpointed render left no resume state"
cp "$work/res.exr.resume" "$work/good.resume"
size=$(stat -c %s "$work/res.exr.resume")
for offset in 20 $((size / 2)) $((size - 3)); do  # header, payload, checksum
  cp "$work/good.resume" "$work/res.exr.resume"; flip "$work/res.exr.resume" "$offset"
  bad=$(sum "$work/res.exr.resume"); img=$(sum "$work/res.exr")
  expect 2 "res.exr.resume: (checksum mismatch|truncated or corrupt|not a Penumbra checkpoint)" -- "$bin" render "$work/scene.gltf" -o "$work/res.exr" --integrator path --width 24 --spp 64 --no-png -q --resume
  unchanged "$work/res.exr.resume" "$bad"; unchanged "$work/res.exr" "$img"
done
cp "$work/good.resume" "$work/res.exr.resume"
python3 - "$work/scene.gltf" <<'PY'
import sys
p = sys.argv[1]; t = open(p).read()
i = t.index('"baseColorFactor"'); j = t.index('0.', i)
open(p, 'w').write(t[:j] + ('1.' if t[j] == '0' else '0.') + t[j + 2:])  # same size, other colour
PY
expect 2 "res.exr.resume: was written for other settings.*" -- "$bin" render "$work/scene.gltf" -o "$work/res.exr" --integrator path --width 24 --spp 64 --no-png -q --resume
grep -q "scene.sha256: stored" "$work/err" && pass || fail "the refusal does not name scene.sha256"
cp "$scene" "$work/scene.gltf"
expect 0 "resuming" -- "$bin" render "$work/scene.gltf" -o "$work/res.exr" --integrator path --width 24 --spp 64 --no-png --resume
# The scene's identity covers its external buffers: a triangle whose .bin is edited in place.
python3 - "$work/tri" <<'PY'
import json, struct, sys
d = sys.argv[1]
import os; os.makedirs(d, exist_ok=True)
pos = struct.pack("<9f", -1, -1, 0, 1, -1, 0, 0, 1, 0)
open(d + "/tri.bin", "wb").write(pos)
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
     "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
     "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}],
     "bufferViews": [{"buffer": 0, "byteLength": 36}], "buffers": [{"byteLength": 36, "uri": "tri.bin"}]}
json.dump(g, open(d + "/tri.gltf", "w"))
PY
expect 0 "t.exr" -- "$bin" render "$work/tri/tri.gltf" -o "$work/tri/t.exr" "${one_pass[@]}"
flip "$work/tri/tri.bin" 2
expect 2 "t.exr.resume: was written for other settings" -- "$bin" render "$work/tri/tri.gltf" -o "$work/tri/t.exr" --integrator path --width 24 --spp 64 --no-png -q --resume
grep -q "scene.sha256: stored" "$work/err" && pass || fail "an edited buffer does not change scene.sha256"
expect 2 "--stats-json .*tri.bin would overwrite the scene's file" -- "$bin" render "$work/tri/tri.gltf" -o "$work/tri/u.exr" "${small[@]}" --stats-json "$work/tri/tri.bin"
rm -f "$work/res.exr.resume"; mkfifo "$work/res.exr.resume"
expect 2 "the resume state .*res.exr.resume is not a regular file; --checkpoint and --resume need one" -- "$bin" render "$work/scene.gltf" -o "$work/res.exr" --integrator path --width 24 --spp 64 --no-png -q --resume
rm -f "$work/res.exr.resume"

# --- merge refuses parts of different renders (unless --force) and non-regular parts.
tile=(--width 48 --spp 1 --no-png -q)
"$bin" render "$scene" -o "$work/m0.exr" "${tile[@]}" --tile 0/2 >/dev/null && "$bin" render "$scene" -o "$work/m1.exr" "${tile[@]}" --tile 1/2 >/dev/null \
  && pass || fail "tiles render"
python3 - "$work/scene.gltf" "$work/other.gltf" <<'PY'
import sys
t = open(sys.argv[1]).read(); i = t.index('"baseColorFactor"'); j = t.index('0.', i)
open(sys.argv[2], 'w').write(t[:j] + ('1.' if t[j] == '0' else '0.') + t[j + 2:])
PY
"$bin" render "$work/other.gltf" -o "$work/o1.exr" "${tile[@]}" --tile 1/2 >/dev/null || fail "other scene's tile"
expect 2 "o1.exr: is from another scene than .*m0.exr: penumbra:scene_sha256" -- "$bin" merge "$work/m0.exr" "$work/o1.exr" -o "$work/mixed.exr"
expect 0 "mixed.exr" -- "$bin" merge "$work/m0.exr" "$work/o1.exr" -o "$work/mixed.exr" --force
"$bin" render "$scene" -o "$work/s1.exr" --width 48 --spp 2 --no-png -q --tile 1/2 >/dev/null || fail "tile with other spp"
expect 2 "s1.exr: was rendered with other settings.*" -- "$bin" merge "$work/m0.exr" "$work/s1.exr" -o "$work/mixed2.exr"
grep -q "spp: " "$work/err" && pass || fail "the refusal does not name spp"
if command -v oiiotool >/dev/null; then  # crops cut by another tool that drops Penumbra's metadata
  "$bin" render "$scene" -o "$work/full.exr" "${tile[@]}" >/dev/null
  oiiotool "$work/full.exr" --eraseattrib "penumbra:.*" --crop 48x14+0+0 -o "$work/c0.exr" &&
    oiiotool "$work/full.exr" --eraseattrib "penumbra:.*" --crop 48x13+0+14 -o "$work/c1.exr"
  expect 2 "c0.exr: has no penumbra:scene_sha256 metadata.*--force" -- "$bin" merge "$work/c0.exr" "$work/c1.exr" -o "$work/cut.exr"
  expect 0 "cut.exr" -- "$bin" merge "$work/c0.exr" "$work/c1.exr" -o "$work/cut.exr" --force
  expect 0 "PASS" -- oiiotool "$work/full.exr" "$work/cut.exr" --fail 0 --diff
fi
"$bin" render "$scene" -o "$work/i0.exr" --width 48 --spp 64 --no-png -q --tile 0/2 --integrator path --time-limit 1e-9 >/dev/null \
  || fail "time-limited tile"
expect 2 "i0.exr: is incomplete" -- "$bin" merge "$work/i0.exr" "$work/m1.exr" -o "$work/inc.exr"
# --reproducible: no command line or timing in the header, so the merge of a frame's tiles is the
# whole-frame render's file byte for byte (path tracer: the merged samples, mean spp and passes).
for layout in single --multipart; do
  repro=(--width 48 --spp 3 --no-png -q --reproducible --integrator path --aov Z,samples)
  [ "$layout" = single ] || repro+=("$layout")
  "$bin" render "$scene" -o "$work/r.exr" "${repro[@]}" >/dev/null || fail "reproducible frame"
  for i in 0 1 2; do "$bin" render "$scene" -o "$work/r$i.exr" "${repro[@]}" --tile $i/3 >/dev/null || fail "tile $i"; done
  sleep 1  # a time stamp would now differ
  expect 0 "r-merged.exr" -- "$bin" merge "$work/r0.exr" "$work/r1.exr" "$work/r2.exr" -o "$work/r-merged.exr"
  cmp -s "$work/r.exr" "$work/r-merged.exr" && pass || fail "$layout: merged reproducible tiles differ from the whole frame"
done
if grep -aq "penumbra:command_line\|penumbra:render_seconds" "$work/r.exr"; then fail "--reproducible recorded the command line or time"; else pass; fi
grep -aq "penumbra:command_line" "$work/m0.exr" && pass || fail "a render without --reproducible records no command line"
expect 2 "/dev/zero: .*is a character device, not a regular file" -- "$bin" merge /dev/zero "$work/m1.exr" -o "$work/z.exr"
expect 2 "in.fifo: .*is a FIFO, not a regular file" -- "$bin" merge "$work/m0.exr" "$work/in.fifo" -o "$work/z.exr"
expect 2 "would overwrite part 1" -- "$bin" merge "$work/m0.exr" "$work/m1.exr" -o "$work/m0.exr"
[ ! -e "$work/z.exr" ] && pass || fail "a refused merge wrote its output"

# --- A full disk: every writer reports it (exit 1), keeps the old file and leaves no temporary.
if [ "$(id -u)" -eq 0 ] && mkdir -p "$work/disk" && mount -t tmpfs -o size=384k tmpfs "$work/disk" 2>/dev/null; then
  mounted="$work/disk"
  "$bin" render "$scene" -o "$work/disk/a.exr" --width 64 --spp 1 -q --stats-json "$work/disk/a.json" >/dev/null || fail "render onto the small disk"
  e=$(sum "$work/disk/a.exr"); p=$(sum "$work/disk/a.png"); j=$(sum "$work/disk/a.json")
  dd if=/dev/zero of="$work/disk/fill" bs=4k 2>/dev/null
  expect 1 "a.png: write failed: No space left on device" -- "$bin" render "$scene" -o "$work/elsewhere.exr" --png "$work/disk/a.png" --width 200 --spp 1 -q
  unchanged "$work/disk/a.png" "$p"
  expect 1 "a.exr: write failed" -- "$bin" render "$scene" -o "$work/disk/a.exr" --no-png --width 200 --spp 1 -q
  unchanged "$work/disk/a.exr" "$e"
  rm -f "$work/disk/fill"; dd if=/dev/zero of="$work/disk/fill" bs=1k count=$(( $(df -k --output=avail "$work/disk" | tail -1) - 1 )) 2>/dev/null
  expect 1 "a.json: .*No space left on device" -- "$bin" render "$scene" -o "$work/else2.exr" --no-png "${small[@]}" --stats-json "$work/disk/a.json"
  unchanged "$work/disk/a.json" "$j"
  no_temporaries "$work/disk"
  umount "$work/disk" && mounted=""
else
  echo "note: not root or no tmpfs: full-disk checks not exercised"
fi
no_temporaries "$work"

echo "output safety: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
