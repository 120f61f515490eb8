#!/usr/bin/env bash
# `penumbra submit slurm` on a throw-away single-node Slurm cluster (tests/apps/slurm_cluster.sh):
# a job of 2 shots x 3 frames, frame 2 of the second (denoised) shot tiled 4 ways, goes in as one array job
# of 9 units and a merge job after it; every frame (EXR and PNG) must be byte-identical (cmp) to
# `penumbra batch` of the same shots in one local process, and no stripe may be left. Then one
# finished frame is deleted and two others are rendered again, one of whose tasks is cancelled
# (scancel) while it renders: the array ends with that task CANCELLED, its frame absent or marked
# unfinished beside its resume state, no temporary left; a re-submission queues exactly that unit,
# resumes it and completes the job, identical again. A third submission has nothing to do. Skipped (with the reason) when the
# cluster cannot start.
# Usage: slurm_farm_test.sh PENUMBRA SRC
set -u
bin="$1"; src="$2"
# shellcheck source=slurm_cluster.sh
. "$(dirname "$0")/slurm_cluster.sh"

slurm_cluster_scratch penumbra-farm || exit 1
start=$(date +%s)
if ! slurm_cluster_start "$dir"; then
  echo "PENUMBRA_SKIP: $SLURM_CLUSTER_ERROR"
  exit 0
fi
dir="$SLURM_CLUSTER_DIR"
echo "cluster up in $(($(date +%s) - start)) s on node $SLURM_CLUSTER_NODE"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# The job: sh010 the fly-through (a camera flight and a turning box: the local batch poses one
# loaded scene, each farm task loads its frame) with the Whitted integrator, sh020 path traced
# and slow enough (a few seconds per frame on one thread) for a task to be caught running.
write_job() {  # write_job FILE OUTPUT_FOLDER
  cat >"$1" <<EOF
{
  "version": 1,
  "defaults": {"width": 64, "height": 36, "threads": 1, "max-memory": "1G", "seed": 7},
  "shots": [
    {"name": "sh010", "scene": "$src/scenes/flythrough.gltf", "frames": "1-3",
     "output": "$2/sh010.####.exr", "png": "$2/sh010.####.png", "settings": {"spp": 2}},
    {"name": "sh020", "scene": "$src/scenes/spheres.gltf", "frames": "1-3", "tiles": 4, "tile_frames": "2",
     "output": "$2/sh020.####.exr", "png": "$2/sh020.####.png",
     "settings": {"integrator": "path", "spp": 48, "width": 96, "height": 54, "aov": ["Z", "N"], "denoise": true}}
  ]
}
EOF
}
write_job "$dir/farm.json" "$dir/out"
write_job "$dir/local.json" "$dir/local"
frames="sh010.0001 sh010.0002 sh010.0003 sh020.0001 sh020.0002 sh020.0003"

if ! "$bin" batch "$dir/local.json" -q >"$dir/local.log" 2>&1; then fail "local batch failed"; cat "$dir/local.log"; fi

# submit [ARGS]: submits farm.json; sets $array and $merge to the job ids it printed (or "").
submit() {
  "$bin" submit slurm "$dir/farm.json" --partition test "$@" >"$dir/submit.out" 2>"$dir/submit.err"
  submit_rc=$?
  array="$(sed -n 's/^array //p' "$dir/submit.out")"
  merge="$(sed -n 's/^merge //p' "$dir/submit.out")"
}

# identical: every frame's EXR and PNG equal the local render's, and no stripe or temporary is left.
identical() {
  for f in $frames; do
    for ext in exr png; do
      if [ ! -f "$dir/out/$f.$ext" ]; then
        fail "$1: $f.$ext is missing"
      elif ! cmp -s "$dir/local/$f.$ext" "$dir/out/$f.$ext"; then
        fail "$1: $f.$ext differs from the local render"
      fi
    done
  done
  leftovers="$(cd "$dir/out" && ls -a | grep -E 'tile-|\.tmp-|\.resume' | xargs)"
  [ -z "$leftovers" ] || fail "$1: left behind: $leftovers"
}

# --- 1. the whole job.
submit
if [ "$submit_rc" -ne 0 ] || [ -z "$array" ] || [ -z "$merge" ]; then
  fail "submit exited $submit_rc (array '$array', merge '$merge')"; cat "$dir/submit.err"
elif ! slurm_cluster_wait_jobs 240 "$array" "$merge"; then
  fail "jobs $array and $merge did not finish within 240 s"; squeue
else
  grep -q "9 of 9 units (0-8)" "$dir/submit.err" || fail "first submission: $(cat "$dir/submit.err")"
  states="$(slurm_cluster_job_states "$array" | sort | uniq -c | xargs)"
  [ "$states" = "9 COMPLETED" ] || fail "array $array: states '$states', expected 9 COMPLETED"
  [ "$(slurm_cluster_job_states "$merge")" = "COMPLETED" ] || fail "merge job $merge: $(slurm_cluster_job_states "$merge")"
  grep -q "^#SBATCH --cpus-per-task=1$" "$dir/farm.slurm/render.sbatch" || fail "CPUs per task not from threads"
  grep -q "^#SBATCH --mem=1536M$" "$dir/farm.slurm/render.sbatch" || fail "memory not from max-memory + 512M"
  identical "first submission"
fi
[ "$fails" -eq 0 ] || { cat "$dir"/farm.slurm/*.log 2>/dev/null | tail -n 40; }

# --- 2. a deleted frame, two frames to render again, one of them cancelled while it runs.
rm -f "$dir/out/sh010.0002.exr" "$dir/out/sh020.0001.exr" "$dir/out/sh020.0003.exr"
submit
if [ "$submit_rc" -ne 0 ] || [ -z "$array" ]; then
  fail "second submit exited $submit_rc"; cat "$dir/submit.err"
else
  grep -q "3 of 9 units (1,3,8)" "$dir/submit.err" || fail "second submission: $(cat "$dir/submit.err")"
  [ -z "$merge" ] || fail "a merge job ($merge) was submitted with every tiled frame complete"
  # Cancelled once its render has made progress: mid-frame, not before the scene loads.
  log="$dir/farm.slurm/render-${array}_8.log"
  for i in $(seq 1 600); do
    grep -q "^render .*%" "$log" 2>/dev/null && break
    sleep 0.1
  done
  if ! grep -q "^render .*%" "$log" 2>/dev/null; then
    fail "unit 8 never rendered (state '$(slurm_cluster_job_states "${array}_8")')"; cat "$log" 2>/dev/null
  else
    scancel "${array}_8" || fail "scancel ${array}_8 failed"
  fi
  slurm_cluster_wait_jobs 120 "$array" || fail "array $array still queued 120 s after scancel"
  [ "$(slurm_cluster_job_states "${array}_8")" = "CANCELLED" ] ||
    fail "unit 8: state '$(slurm_cluster_job_states "${array}_8")' after scancel, expected CANCELLED"
  # The interrupted frame is either absent or marked unfinished with its resume state beside it.
  if [ -e "$dir/out/sh020.0003.exr" ]; then
    grep -aq "complete=0" "$dir/out/sh020.0003.exr" || fail "the cancelled unit left a frame not marked unfinished"
    [ -f "$dir/out/sh020.0003.exr.resume" ] || fail "the cancelled unit left no resume state"
  fi
  leftovers="$(cd "$dir/out" && ls -a | grep -E '\.tmp-' | xargs)"
  [ -z "$leftovers" ] || fail "the cancelled unit left temporaries: $leftovers"
  [ -f "$dir/out/sh010.0002.exr" ] || fail "unit 1 did not render sh010.0002 again"
fi
submit
if [ "$submit_rc" -ne 0 ] || [ -z "$array" ]; then
  fail "third submit exited $submit_rc"; cat "$dir/submit.err"
else
  grep -q "1 of 9 units (8)" "$dir/submit.err" || fail "re-submission: $(cat "$dir/submit.err")"
  slurm_cluster_wait_jobs 240 "$array" || fail "array $array did not finish within 240 s"
  [ "$(slurm_cluster_job_states "$array")" = "COMPLETED" ] || fail "array $array: $(slurm_cluster_job_states "$array")"
  identical "re-submission"
fi
submit
[ "$submit_rc" -eq 0 ] && [ -z "$array$merge" ] && grep -q "nothing to submit" "$dir/submit.err" ||
  fail "a complete job was submitted again: exit $submit_rc, array '$array', merge '$merge'"

[ "$fails" -eq 0 ] || { slurm_cluster_logs; cat "$dir"/farm.slurm/*.log 2>/dev/null | tail -n 40; }
slurm_cluster_stop
echo "slurm farm: $fails failures in $(($(date +%s) - start)) s"
[ "$fails" -eq 0 ]
