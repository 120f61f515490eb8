#!/usr/bin/env bash
# `penumbra batch` and `penumbra submit slurm` end to end on tiny job files of the shipped
# scene: --list prints the work units (a tiled frame as one unit per stripe) in order; --unit
# renders exactly one file and refuses an index out of range; --merge refuses a missing stripe;
# the units merged equal a local batch of the same job byte for byte and a plain `render` of the
# same settings pixel for pixel; --skip-existing keeps complete files and renders a deleted one
# again; bad job files exit 2 naming the job file, the shot and the key, and write no file;
# `submit slurm --dry-run` prints the scripts (array, CPUs and memory from the settings) and
# writes none (also for a job of a million units, which --list prints one per line);
# submission without or with a failing sbatch exits 1, with a fake sbatch it prints the job ids
# and writes the scripts under JOB.slurm/.
# Usage: batch_test.sh PENUMBRA_BINARY SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0

# expect CODE PATTERN -- command...: counts a pass or a failure in $passes / $fails.
source "$(dirname "$0")/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
# run CODE -- command...: like expect, for commands that may print nothing.
run() {
  local code="$1"; shift 2
  "$@" >"$work/out" 2>"$work/err"; local rc=$?
  if [ "$rc" -ne "$code" ]; then
    echo "FAIL: [$*] exit $rc (want $code)"; sed 's/^/  | /' "$work/err" | head -5; fails=$((fails + 1))
  else
    passes=$((passes + 1))
  fi
}
for tool in oiiotool cmp sha256sum; do
  command -v "$tool" >/dev/null || { echo "PENUMBRA_SKIP: $tool is not installed"; exit 0; }
done
# Equal pixels (the EXR metadata may differ).
same_pixels() {
  oiiotool "$1" "$2" --fail 0 --diff >"$work/diff.txt" 2>&1 || { fail "pixels of $1 and $2 differ"; sed 's/^/  | /' "$work/diff.txt" | head -5; return; }
  passes=$((passes + 1))
}

cp "$src/scenes/default.gltf" "$work/scene.gltf"
settings='"width": 32, "height": 24, "spp": 1, "threads": 1, "max-memory": "256M"'
# job_file FILE OUT: a still with a display image, and three frames whose frame 2 is split in
# two stripes (with its own spp), writing into OUT.
job_file() {
  cat >"$1" <<EOF
{"version": 1, "defaults": {$settings},
 "shots": [
  {"name": "still", "scene": "scene.gltf", "output": "$2/still.exr", "png": "$2/still.png"},
  {"name": "anim", "scene": "scene.gltf", "output": "$2/anim.####.exr", "frames": "1-3",
   "tiles": 2, "tile_frames": 2, "settings": {"spp": 2}}]}
EOF
}
job="$work/job.json"
job_file "$job" farm
job_file "$work/local.json" local

# --list: one tab-separated line per unit, shots in order, frames ascending, stripes top first.
tab=$'\t'
expect 0 "anim" -- "$bin" batch "$job" --list
cat >"$work/want_list" <<EOF
0${tab}still${tab}-${tab}-${tab}$work/farm/still.exr
1${tab}anim${tab}1${tab}-${tab}$work/farm/anim.0001.exr
2${tab}anim${tab}2${tab}0/2${tab}$work/farm/anim.0002.exr
3${tab}anim${tab}2${tab}1/2${tab}$work/farm/anim.0002.exr
4${tab}anim${tab}3${tab}-${tab}$work/farm/anim.0003.exr
EOF
cmp -s "$work/out" "$work/want_list" || { fail "--list printed:"; sed 's/^/  | /' "$work/out"; }
# --tiles splits the shots without "tiles" only: the still, not the animation's frames.
expect 0 "still${tab}-${tab}2/3" -- "$bin" batch "$job" --list --tiles 3
[ "$(wc -l <"$work/out")" -eq 7 ] || fail "--list --tiles 3 printed $(wc -l <"$work/out") units, want 7"

# --unit out of range names the range; nothing is rendered.
expect 2 "--unit 5: .*job.json has units 0 to 4" -- "$bin" batch "$job" --unit 5
expect 2 "--unit -1: .*has units 0 to 4" -- "$bin" batch "$job" --unit -1
[ -z "$(find "$work/farm" -type f 2>/dev/null)" ] || fail "a refused --unit wrote $(find "$work/farm" -type f)"

# --unit renders exactly one file: the stripe of unit 2.
run 0 -- "$bin" batch "$job" --unit 2 -q
[ "$(find "$work/farm" -type f | sort)" = "$work/farm/anim.0002.tile-0-of-2.exr" ] ||
  fail "--unit 2 wrote: $(find "$work/farm" -type f | tr '\n' ' ')"
# --merge with the other stripe missing names its unit and writes no frame.
expect 1 "cannot merge .*anim.0002.exr: the stripes of units 3 are missing" -- "$bin" batch "$job" --merge
[ -e "$work/farm/anim.0002.exr" ] && fail "--merge with a missing stripe wrote the frame"

# Every unit, then --merge: the stripes are gone and the frames equal a local batch, byte for byte.
for n in 0 1 3 4; do run 0 -- "$bin" batch "$job" --unit "$n" -q; done
expect 0 "merged 2 stripes into .*anim.0002.exr" -- "$bin" batch "$job" --merge
run 0 -- "$bin" batch "$work/local.json" -q
files="still.exr still.png anim.0001.exr anim.0002.exr anim.0003.exr"
for f in $files; do
  if cmp -s "$work/farm/$f" "$work/local/$f"; then passes=$((passes + 1)); else fail "farm/$f differs from local/$f"; fi
done
[ -n "$(find "$work/farm" -name '*.tile-*')" ] && fail "--merge left the stripes: $(find "$work/farm" -name '*.tile-*')"
[ "$(find "$work/farm" -type f | wc -l)" -eq 5 ] || fail "the farm folder holds: $(ls "$work/farm" | tr '\n' ' ')"

# ... and the pixels of plain renders of the same settings.
mkdir -p "$work/plain"
common=(--width 32 --height 24 --threads 1 --max-memory 256M -q)
run 0 -- "$bin" render "$work/scene.gltf" -o "$work/plain/still.exr" --no-png --spp 1 "${common[@]}"
same_pixels "$work/farm/still.exr" "$work/plain/still.exr"
for n in 1 2 3; do
  run 0 -- "$bin" render "$work/scene.gltf" --frame "$n" -o "$work/plain/anim.$n.exr" --no-png --spp 2 "${common[@]}"
  same_pixels "$work/farm/anim.000$n.exr" "$work/plain/anim.$n.exr"
done

# --skip-existing: complete files stay untouched (contents and times), for the whole job, a unit
# of a merged frame and the merge.
sums() { (cd "$work/farm" && sha256sum $files); }
before="$(sums)"
touch -d '2001-01-01' "$work"/farm/*
run 0 -- "$bin" batch "$job" --skip-existing -q
expect 0 "frame .*anim.0002.exr is complete; skipped" -- "$bin" batch "$job" --unit 3 --skip-existing
run 0 -- "$bin" batch "$job" --unit 0 --skip-existing -q
run 0 -- "$bin" batch "$job" --merge --skip-existing -q
[ "$(sums)" = "$before" ] || fail "--skip-existing changed complete files"
[ -n "$(find "$work/farm" -type f -newermt '2001-01-02')" ] &&
  fail "--skip-existing rewrote: $(find "$work/farm" -type f -newermt '2001-01-02' | tr '\n' ' ')"
[ -n "$(find "$work/farm" -name '*.tile-*')" ] && fail "--skip-existing rendered a stripe of a merged frame"
# A deleted frame is rendered again, the same as before; the others stay untouched.
rm "$work/farm/anim.0003.exr"
run 0 -- "$bin" batch "$job" --skip-existing -q
[ "$(sums)" = "$before" ] || fail "--skip-existing did not render the deleted frame 3 as before"
[ "$(find "$work/farm" -type f -newermt '2001-01-02')" = "$work/farm/anim.0003.exr" ] ||
  fail "--skip-existing rewrote: $(find "$work/farm" -type f -newermt '2001-01-02' | tr '\n' ' ')"
# A deleted tiled frame: its units render its stripes again and --merge completes it.
rm "$work/farm/anim.0002.exr"
run 0 -- "$bin" batch "$job" --unit 2 --skip-existing -q
run 0 -- "$bin" batch "$job" --unit 3 --skip-existing -q
expect 0 "merged 2 stripes" -- "$bin" batch "$job" --merge --skip-existing
[ "$(sums)" = "$before" ] || fail "the deleted tiled frame was not rendered again as before"

# A boolean setting is an on/off flag: true gives it ("float": 32-bit channels).
cat >"$work/flag.json" <<EOF
{"shots": [{"name": "f", "scene": "scene.gltf", "output": "flag/f.exr", "settings": {$settings, "float": true}}]}
EOF
run 0 -- "$bin" batch "$work/flag.json" -q
if [ -f "$work/flag/f.exr" ]; then
  oiiotool --info -v "$work/flag/f.exr" 2>/dev/null | grep -q "float" || fail "\"float\": true did not write float channels"
fi

# Bad job files exit 2 naming the job file, the shot and the key, and write no file.
bad="$work/bad"
mkdir -p "$bad"; cp "$work/scene.gltf" "$bad/scene.gltf"
shot='"name": "sh1", "scene": "scene.gltf", "output": "out/a.exr"'
at='shots\[0\] \(sh1\)'
refused() {  # refused PATTERN SHOTS...: the job of these shots exits 2 with the message PATTERN
  local pattern="$1"; shift
  local shots; shots="$(printf '%s,' "$@")"
  printf '{"version": 1, "defaults": {%s}, "shots": [%s]}\n' "$settings" "${shots%,}" >"$bad/job.json"
  expect 2 "penumbra: error: $bad/job.json: $pattern" -- "$bin" batch "$bad/job.json"
  expect 2 "penumbra: error: $bad/job.json: $pattern" -- "$bin" submit slurm "$bad/job.json" --dry-run
  if [ -n "$(find "$bad" -type f ! -name job.json ! -name scene.gltf)" ]; then
    fail "a refused job ($*) wrote $(find "$bad" -type f ! -name job.json ! -name scene.gltf | tr '\n' ' ')"
  fi
  if [ -e "$bad/job.slurm" ]; then fail "a refused job ($*) created $bad/job.slurm"; fi
}
refused "$at\.settings\.spppp: 'spppp' is not a setting" "{$shot, \"settings\": {\"spppp\": 4}}"
printf '{"defaults": {"spppp": 4}, "shots": [{%s}]}\n' "$shot" >"$bad/job.json"
expect 2 "$bad/job.json: defaults\.spppp: 'spppp' is not a setting" -- "$bin" batch "$bad/job.json"
refused "$at\.settings\.output: is set by the shot's \"output\"" "{$shot, \"settings\": {\"output\": \"x.exr\"}}"
refused "$at\.settings\.frames: is set by the shot's \"frames\"" "{$shot, \"settings\": {\"frames\": \"1-3\"}}"
refused "$at\.settings\.tile: is set by the shot's \"tiles\"" "{$shot, \"settings\": {\"tile\": \"0/2\"}}"
refused "$at\.settings\.float: is an on/off flag" "{$shot, \"settings\": {\"float\": 3}}"
refused "$at\.settings\.spp: takes a value, not true or false" "{$shot, \"settings\": {\"spp\": true}}"
refused "$at\.settings.*--spp: .*0" "{$shot, \"settings\": {\"spp\": 0}}"
refused "$at\.settings.*--integrator: foo" "{$shot, \"settings\": {\"integrator\": \"foo\"}}"
refused "shots\[1\] \(sh2\): .*out/a.exr would be written by $at" "{$shot}" \
  '{"name": "sh2", "scene": "scene.gltf", "output": "out/a.exr"}'
refused "$at: .*needs a run of '#' in -o" '{"name": "sh1", "scene": "scene.gltf", "output": "out/a.exr", "frames": "1-3"}'
refused "$at\.scene: .*missing\.gltf: file not found" '{"name": "sh1", "scene": "missing.gltf", "output": "out/a.exr"}'
grep -q "missing.gltf" "$work/err" || fail "the missing scene's message does not name missing.gltf"

# submit slurm --dry-run: both scripts, the array of every unit, CPUs and memory from the shots'
# threads and memory budget (the largest, plus 512 MiB); no script written.
sub="$work/submit"
mkdir -p "$sub"; cp "$work/scene.gltf" "$sub/scene.gltf"
cat >"$sub/tiled.json" <<EOF
{"defaults": {"width": 32, "spp": 1},
 "shots": [
  {"name": "a", "scene": "scene.gltf", "output": "out/a.exr", "settings": {"threads": 1, "max-memory": "300M"}},
  {"name": "b", "scene": "scene.gltf", "output": "out/b.####.exr", "frames": "1-2", "tiles": 3,
   "settings": {"threads": 3, "max-memory": "100M"}}]}
EOF
expect 0 "#SBATCH --array=0-6$" -- "$bin" submit slurm "$sub/tiled.json" --dry-run
for want in "^# $sub/tiled.slurm/render.sbatch$" "^# $sub/tiled.slurm/merge.sbatch$" \
            "#SBATCH --cpus-per-task=3$" "#SBATCH --mem=812M$" \
            "batch '$sub/tiled.json' --unit \"\\\$SLURM_ARRAY_TASK_ID\" --skip-existing" \
            "batch '$sub/tiled.json' --merge --skip-existing" \
            "# sbatch --parsable --job-name=.* --dependency=afterok:"; do
  grep -qE -- "$want" "$work/out" || fail "--dry-run printed no line matching '$want'"
done
[ "$(grep -c '^#SBATCH --cpus-per-task=' "$work/out")" -eq 2 ] || fail "--dry-run did not print two scripts"
grep -q "^#SBATCH --cpus-per-task=1$" "$work/out" || fail "the merge script does not ask for 1 CPU"
[ -e "$sub/tiled.slurm" ] && fail "--dry-run created $sub/tiled.slurm"
# --threads and --max-memory give the resources of shots without them; a job without tiles has
# no merge script.
cat >"$sub/plain.json" <<EOF
{"defaults": {"width": 32, "spp": 1},
 "shots": [{"name": "a", "scene": "scene.gltf", "output": "out/p.####.exr", "frames": "1-4"}]}
EOF
expect 0 "#SBATCH --array=0-3$" -- "$bin" submit slurm "$sub/plain.json" --dry-run --threads 2 --max-memory 1G
grep -q "^#SBATCH --cpus-per-task=2$" "$work/out" || fail "--threads 2 is not the CPUs per task"
grep -q "^#SBATCH --mem=1536M$" "$work/out" || fail "--max-memory 1G is not --mem=1536M"
grep -q "merge" "$work/out" && fail "a job without tiled frames printed a merge script"
grep -q -- "--unit \"\$SLURM_ARRAY_TASK_ID\" --skip-existing --threads 2 --max-memory '1G'" "$work/out" ||
  fail "the tasks do not pass on --threads and --max-memory"
# A shot without threads or without a memory budget cannot be sized.
expect 2 "plain.json: shots\[0\] \(a\): gives no \"threads\" setting" -- "$bin" submit slurm "$sub/plain.json" --dry-run --max-memory 1G
expect 2 "plain.json: shots\[0\] \(a\): gives no \"max-memory\" setting" -- "$bin" submit slurm "$sub/plain.json" --dry-run --threads 2
[ -e "$sub/plain.slurm" ] && fail "--dry-run created $sub/plain.slurm"

# Without sbatch on PATH: exit 1, nothing written.
expect 1 "sbatch is not on PATH" -- env PATH=/nonexistent "$bin" submit slurm "$sub/tiled.json"
[ -e "$sub/tiled.slurm" ] && fail "a submission without sbatch created $sub/tiled.slurm"
# A failing sbatch: exit 1 with its output.
fake="$work/fake"
mkdir -p "$fake"
printf '#!/bin/sh\necho "sbatch: error: Batch job submission failed: Invalid partition" >&2\nexit 1\n' >"$fake/sbatch"
chmod +x "$fake/sbatch"
expect 1 "render.sbatch failed with exit 1" -- env PATH="$fake:$PATH" "$bin" submit slurm "$sub/tiled.json"
grep -q "Invalid partition" "$work/err" || fail "sbatch's own message is not shown"
# A working sbatch: the array job and the merge job, the scripts under JOB.slurm/.
printf '#!/bin/sh\nprintf "%%s\\n" "$*" >>"%s/args"\necho 123\n' "$fake" >"$fake/sbatch"
run 0 -- env PATH="$fake:$PATH" "$bin" submit slurm "$sub/tiled.json"
[ "$(cat "$work/out")" = "$(printf 'array 123\nmerge 123')" ] || { fail "submit printed:"; sed 's/^/  | /' "$work/out"; }
[ -x "$sub/tiled.slurm/render.sbatch" ] || fail "no executable $sub/tiled.slurm/render.sbatch"
[ -f "$sub/tiled.slurm/merge.sbatch" ] || fail "no $sub/tiled.slurm/merge.sbatch"
grep -q -- "--array=0-6" "$sub/tiled.slurm/render.sbatch" 2>/dev/null || fail "render.sbatch has no --array=0-6"
grep -q -- "--dependency=afterok:123 .*merge.sbatch" "$fake/args" || fail "the merge job does not wait for array 123"
# Only the incomplete units are submitted again: a complete frame 1 of b leaves its stripes out.
run 0 -- "$bin" batch "$sub/tiled.json" --threads 1 --max-memory 256M -q
rm "$sub"/out/b.0002.exr
expect 0 "#SBATCH --array=4-6$" -- "$bin" submit slurm "$sub/tiled.json" --dry-run
run 0 -- "$bin" batch "$sub/plain.json" --threads 1 --max-memory 256M -q
expect 0 "every frame of .*plain.json is complete; nothing to submit" -- env PATH="$fake:$PATH" "$bin" submit slurm "$sub/plain.json" --threads 1 --max-memory 1G
[ -e "$sub/plain.slurm" ] && fail "a complete job created $sub/plain.slurm"

# A million units (a hundred thousand frames of ten stripes): listed one per line and dry-run
# submitted as one array, without a file written.
cp "$src/scenes/default.gltf" "$work/million-scene.gltf"
printf '{"defaults": {"width": 16, "height": 24, "spp": 1, "threads": 1, "max-memory": "256M"}, "shots": [%s]}\n' \
  '{"name": "m", "scene": "million-scene.gltf", "output": "m/m.#######.exr", "frames": "1-100000", "tiles": 10}' \
  >"$work/million.json"
if "$bin" batch "$work/million.json" --list >"$work/million.txt" 2>"$work/err"; then
  [ "$(wc -l <"$work/million.txt")" -eq 1000000 ] && passes=$((passes + 1)) ||
    fail "batch --list printed $(wc -l <"$work/million.txt") units"
  [ "$(tail -1 "$work/million.txt")" = "999999	m	100000	9/10	$work/m/m.0100000.exr" ] &&
    passes=$((passes + 1)) || fail "the last unit is '$(tail -1 "$work/million.txt")'"
else
  fail "batch --list of a million units failed: $(head -3 "$work/err")"
fi
expect 0 "^#SBATCH --array=0-999999$" -- "$bin" submit slurm "$work/million.json" --dry-run
[ -e "$work/m" ] || [ -e "$work/million.slurm" ] && fail "a dry run of a million units wrote files"
rm -f "$work/million.txt"

echo "batch: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
