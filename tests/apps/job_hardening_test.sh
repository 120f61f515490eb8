#!/usr/bin/env bash
# Job files from hostile hands: the sbatch scripts generated for job files with quotes, `$(...)`,
# backquotes and non-UTF-8 bytes in their path run exactly the intended command (a stub sbatch
# takes them, and the render script is then run as a task would run it) with exactly the
# intended directives; paths with control characters exit 2; every file the units write is
# checked up front (a shot's output on another shot's stripe, more stripes than rows); and the
# output root confines what a job writes.
# Usage: job_hardening_test.sh PENUMBRA SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
source "$src/tests/apps/expect.sh"
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
ok() { passes=$((passes + 1)); }
command -v python3 >/dev/null || { echo "PENUMBRA_SKIP: python3 is not installed"; exit 0; }

# A stub sbatch: records its arguments and the script, prints a job id.
fake="$work/fake"; mkdir -p "$fake"
cat >"$fake/sbatch" <<EOF
#!/bin/sh
n=\$(ls "$fake" | grep -c '^script')
for a in "\$@"; do last="\$a"; done
cp "\$last" "$fake/script\$n"
printf '%s\n' "\$*" >"$fake/args\$n"
echo \$((100 + n))
EOF
chmod +x "$fake/sbatch"

# Hostile folder names: each gets a job file (a tiled still, so both scripts are made) and a scene.
python3 - "$work" "$src" <<'EOF'
import json, os, shutil, sys
work, src = sys.argv[1], sys.argv[2]
names = [b"quote'd \"dq\"", b"$(touch PWNED)", b"`touch PWNED`", b"semi;touch PWNED&", b"latin1-\xe9\xff",
         b"#SBATCH --wrap=touch PWNED", b"back\\slash %A %j"]
with open(f"{work}/hostile.list", "wb") as f:
    for i, n in enumerate(names):
        # The name in the folder (outputs go under it: '#' there is a frame pattern, so it
        # stands in the job file's name only) and in the job file's name.
        d = os.path.join(work.encode(), b"h%d-" % i + n.replace(b"#", b"H"))
        os.makedirs(d, exist_ok=True)
        shutil.copy(f"{src}/scenes/default.gltf", os.path.join(d, b"scene.gltf"))
        job = {"defaults": {"width": 16, "height": 8, "spp": 1, "threads": 1, "max-memory": "256M"},
               "shots": [{"name": "a", "scene": "scene.gltf", "output": "out/a.exr", "tiles": 2}]}
        path = os.path.join(d, b"job " + n + b".json")
        open(path, "w").write(json.dumps(job))
        f.write(path + b"\n")
# Control characters: a newline, a tab and an escape in the job file's name and folder.
for i, n in enumerate([b"job\ntouch PWNED\n.json", b"job\n#SBATCH --wrap=x\n.json", b"tab\tjob.json", b"esc\x1bjob.json"]):
    d = os.path.join(work.encode(), b"c%d" % i)
    os.makedirs(d, exist_ok=True)
    shutil.copy(f"{src}/scenes/default.gltf", os.path.join(d, b"scene.gltf"))
    job = {"defaults": {"threads": 1, "max-memory": "256M"}, "shots": [{"name": "a", "scene": "scene.gltf", "output": "a.exr"}]}
    open(os.path.join(d, n), "w").write(json.dumps(job))
EOF

# Scripts from hostile names: the intended directives only; run as task 0, they render the
# stripe and nothing else happens (no PWNED anywhere).
while IFS= read -r jobfile; do
  dir=$(dirname "$jobfile")
  rm -f "$fake"/script* "$fake"/args*
  if ! (cd "$work" && PATH="$fake:$PATH" "$bin" submit slurm "$jobfile" >"$work/out" 2>"$work/err"); then
    fail "submit slurm in '$dir' failed: $(head -3 "$work/err")"; continue
  fi
  ok
  for s in "$fake/script0" "$fake/script1"; do
    [ -f "$s" ] || { fail "no script submitted in '$dir'"; continue; }
    sh -n "$s" && ok || fail "$s from '$dir' is not valid sh"
    # Every #SBATCH line before the first command is one of ours.
    bad=$(awk '/^[^#]/ {exit} /^#SBATCH/ && !/^#SBATCH --(cpus-per-task|mem|requeue|array|kill-on-invalid-dep)(=|$)/' "$s")
    [ -z "$bad" ] && ok || fail "unexpected directives in the script for '$dir': $bad"
    [ "$(grep -c '^#SBATCH' "$s")" -le 5 ] && ok || fail "too many directives in the script for '$dir'"
  done
  (cd "$work" && SLURM_ARRAY_TASK_ID=0 sh "$fake/script0" >/dev/null 2>"$work/task.err") \
    && ok || fail "the render task for '$dir' failed: $(head -3 "$work/task.err")"
  [ -f "$dir/out/a.tile-0-of-2.exr" ] && ok || fail "the render task for '$dir' rendered no stripe"
  (cd "$work" && sh "$fake/script1" >/dev/null 2>&1)  # the merge: stripe 1 is missing, so it fails
done <"$work/hostile.list"
found=$(find "$work" -name PWNED | head -1)
[ -z "$found" ] && ok || fail "a hostile name ran a command: $found"

# Control characters in a path reaching the scripts or the unit list: exit 2, nothing written.
for f in "$work"/c*/*.json; do
  expect 2 "control character 0x(0a|09|1b)" -- env PATH="$fake:$PATH" "$bin" submit slurm "$f"
  expect 2 "control character 0x(0a|09|1b)" -- "$bin" batch "$f" --list
done
[ -z "$(find "$work"/c* -name '*.slurm')" ] && ok || fail "a refused job left a .slurm folder"
expect 2 "--scripts .*control character 0x0a" -- env PATH="$fake:$PATH" "$bin" submit slurm \
  "$(head -1 "$work/hostile.list")" --scripts "$work/s
x"
cp "$src/scenes/default.gltf" "$work/scene.gltf"
job() {  # NAME SHOTS-JSON [TOP-LEVEL-JSON]: a job file in $work
  printf '{%s "defaults": {"width": 16, "height": 24, "spp": 1, "threads": 1, "max-memory": "256M"}, "shots": [%s]}\n' \
    "${3:+$3,}" "$2" >"$work/$1.json"
}
job newline_output '{"name": "a", "scene": "scene.gltf", "output": "a\nb.exr"}'
expect 2 "shots\[0\] \(a\)\.output: contains the control character 0x0a" -- "$bin" batch "$work/newline_output.json" --list

# One shot's output on another shot's stripe: refused before anything runs.
job stripe '{"name": "a", "scene": "scene.gltf", "output": "r/a.exr", "tiles": 2},
            {"name": "b", "scene": "scene.gltf", "output": "r/a.tile-0-of-2.exr"}'
for mode in "batch --list" "batch" "batch --unit 2"; do
  # shellcheck disable=SC2086
  expect 2 "r/a.tile-0-of-2.exr would be written by shots\[0\] \(a\) \(unit 0, stripe 0/2\) and by shots\[1\] \(b\)" -- \
    "$bin" $mode "$work/stripe.json"
done
expect 2 "would be written by" -- env PATH="$fake:$PATH" "$bin" submit slurm "$work/stripe.json" --dry-run
[ -e "$work/r/a.tile-0-of-2.exr" ] && fail "a refused job rendered"
# A display image on another frame's resume state, a statistics file on a stripe.
job resume '{"name": "a", "scene": "scene.gltf", "output": "q/a.####.exr", "frames": "1-2"},
            {"name": "b", "scene": "scene.gltf", "output": "q/b.exr", "stats_json": "q/a.0002.exr.resume"}'
expect 2 "q/a.0002.exr.resume would be written by shots\[0\] \(a\) \(unit 1, frame 2\)" -- "$bin" batch "$work/resume.json" --list

# More stripes than rows (the height from the defaults): refused when the job is read.
job rows '{"name": "a", "scene": "scene.gltf", "output": "t/a.exr", "tiles": 4096}'
expect 2 "shots\[0\] \(a\)\.tiles: 4096 stripes of a frame 24 rows high" -- "$bin" batch "$work/rows.json" --list
expect 2 "4096 stripes of a frame 24 rows high" -- "$bin" submit slurm "$work/rows.json" --dry-run
job rows_ok '{"name": "a", "scene": "scene.gltf", "output": "t/a.exr", "tiles": 24}'
expect 0 "^23	a	-	23/24	" -- "$bin" batch "$work/rows_ok.json" --list

# The output root: the job's folder by default; --output-root allows another; the job's
# "output_root" only narrows; a symbolic link out of the root is refused.
mkdir -p "$work/jobs" "$work/elsewhere"
cp "$src/scenes/default.gltf" "$work/jobs/scene.gltf"
printf '{"shots": [{"name": "a", "scene": "scene.gltf", "output": "../elsewhere/a.exr"}]}\n' >"$work/jobs/up.json"
expect 2 "elsewhere/a.exr is outside the output root $work/jobs" -- "$bin" batch "$work/jobs/up.json" --list
expect 0 "elsewhere/a.exr" -- "$bin" batch "$work/jobs/up.json" --list --output-root "$work"
expect 2 "outside the output root" -- "$bin" submit slurm "$work/jobs/up.json" --dry-run --threads 1 --max-memory 256M
expect 0 "--output-root '$work'" -- "$bin" submit slurm "$work/jobs/up.json" --dry-run --threads 1 --max-memory 256M \
  --output-root "$work"
expect 2 "--output-root: the value is empty" -- "$bin" batch "$work/jobs/up.json" --list --output-root ""
expect 2 "--output-root: the value is empty" -- "$bin" submit slurm "$work/jobs/up.json" --dry-run --output-root ""
printf '{"shots": [{"name": "a", "scene": "scene.gltf", "output": "/tmp/penumbra-abs.exr"}]}\n' >"$work/jobs/abs.json"
expect 2 "/tmp/penumbra-abs.exr is outside the output root" -- "$bin" batch "$work/jobs/abs.json" --list
printf '{"output_root": "renders", "shots": [{"name": "a", "scene": "scene.gltf", "output": "other/a.exr"}]}\n' >"$work/jobs/narrow.json"
expect 2 "other/a.exr is outside the output root $work/jobs/renders" -- "$bin" batch "$work/jobs/narrow.json" --list
printf '{"output_root": "..", "shots": [{"name": "a", "scene": "scene.gltf", "output": "a.exr"}]}\n' >"$work/jobs/widen.json"
expect 2 "output_root: $work is outside $work/jobs" -- "$bin" batch "$work/jobs/widen.json" --list
ln -s "$work/elsewhere" "$work/jobs/link"
printf '{"shots": [{"name": "a", "scene": "scene.gltf", "output": "link/a.exr"}]}\n' >"$work/jobs/link.json"
expect 2 "outside the output root" -- "$bin" batch "$work/jobs/link.json"
[ -e "$work/elsewhere/a.exr" ] && fail "a job wrote through a link out of its root"

# Links: a file that is itself a link out of the root, an "output_root" that is a link out of
# it, a link among more than 4096 frame folders, and a root named through a link (accepted).
mkdir -p "$work/jobs/out"
ln -s "$work/elsewhere/target.exr" "$work/jobs/out/a.exr"
printf '{"shots": [{"name": "a", "scene": "scene.gltf", "output": "out/a.exr"}]}\n' >"$work/jobs/filelink.json"
expect 2 "out/a.exr \($work/elsewhere/target.exr\) is outside the output root" -- "$bin" batch "$work/jobs/filelink.json" --list
ln -s "$work/elsewhere" "$work/jobs/rootlink"
printf '{"output_root": "rootlink", "shots": [{"name": "a", "scene": "scene.gltf", "output": "rootlink/a.exr"}]}\n' >"$work/jobs/rootlink.json"
expect 2 "output_root: $work/jobs/rootlink \($work/elsewhere\) is outside $work/jobs" -- "$bin" batch "$work/jobs/rootlink.json" --list
ln -s "$work/elsewhere" "$work/jobs/f4500"
printf '{"shots": [{"name": "a", "scene": "scene.gltf", "output": "f####/x.exr", "frames": "0-5000"}]}\n' >"$work/jobs/many.json"
expect 2 "f4500/x.exr \($work/elsewhere/x.exr\) is outside the output root" -- "$bin" batch "$work/jobs/many.json" --list
[ -e "$work/jobs/f0000" ] && fail "a refused job left its frame folders"
ln -s "$work" "$work.alias"
expect 0 "elsewhere/a.exr" -- "$bin" batch "$work/jobs/up.json" --list --output-root "$work.alias"
rm -f "$work.alias"
# A frame that is a link to another frame: the two units write one file.
mkdir -p "$work/jobs/seq"
ln -s "$work/jobs/seq/f.0001.exr" "$work/jobs/seq/f.0002.exr"
printf '{"shots": [{"name": "a", "scene": "scene.gltf", "output": "seq/f.####.exr", "frames": "1-2"}]}\n' >"$work/jobs/seq.json"
expect 2 "seq/f.0002.exr would be written by shots\[0\] \(a\) \(unit 0, frame 1\) and by shots\[0\] \(a\) \(unit 1, frame 2\)" -- \
  "$bin" batch "$work/jobs/seq.json" --list
# Each shot's own frame patterns are checked (the first shot's here, not only the last one's).
printf '{"shots": [{"name": "a", "scene": "scene.gltf", "output": "p/a.exr", "frames": "1-2"},
                   {"name": "b", "scene": "scene.gltf", "output": "p/b.####.exr", "frames": "1-2"}]}\n' >"$work/jobs/patterns.json"
expect 2 "shots\[0\] \(a\): --frames needs a run of '#' in -o" -- "$bin" batch "$work/jobs/patterns.json" --list

echo "$passes passed, $fails failed"
[ "$fails" -eq 0 ]
