#!/usr/bin/env bash
# `penumbra` runs on a throw-away single-node Slurm cluster (tests/apps/slurm_cluster.sh): an array
# job of 3 tasks renders the default scene at 32 pixels, each frame's pixels bit-identical to a local
# render (oiiotool --diff --fail 0; the files differ in capDate, penumbra:command_line and
# penumbra:render_seconds); a job depending on the array (afterok) runs after all 3 tasks; scancel ends a running
# job as CANCELLED and kills its process; stopping the cluster leaves none of its daemons running.
# Skipped (reported by ctest as skipped, with the reason) when the cluster cannot start: not root,
# Slurm, munge or oiiotool not installed, or a daemon failing to start.
# Usage: slurm_cluster_test.sh PENUMBRA SRC
set -u
bin="$1"; src="$2"
# shellcheck source=slurm_cluster.sh
. "$(dirname "$0")/slurm_cluster.sh"

slurm_cluster_scratch penumbra-slurm || exit 1
start=$(date +%s)
if ! command -v oiiotool >/dev/null; then
  echo "PENUMBRA_SKIP: oiiotool is not installed (scripts/install-deps.sh installs openimageio-tools)"
  exit 0
fi
if ! slurm_cluster_start "$dir"; then
  echo "PENUMBRA_SKIP: $SLURM_CLUSTER_ERROR"
  exit 0
fi
dir="$SLURM_CLUSTER_DIR"
daemons="$SLURM_CLUSTER_PIDS"
echo "cluster up in $(($(date +%s) - start)) s: node $SLURM_CLUSTER_NODE, daemons $daemons"
jobs="$dir/jobs"; out="$dir/out"
mkdir -p "$out"
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# Prints the value of KEY of the job (the first array task's for an array job).
job_field() { scontrol -o show job "$1" 2>/dev/null | head -n 1 | tr ' ' '\n' | sed -n "s/^$2=//p"; }

render=(render "$src/scenes/default.gltf" --width 32 --spp 1)
if ! "$bin" "${render[@]}" -o "$out/local.exr" >"$jobs/local.log" 2>&1; then
  fail "the local render failed"; cat "$jobs/local.log"
fi

cat >"$jobs/render.sh" <<'EOF'
#!/bin/bash
bin="$1"; out="$2"; shift 2
exec "$bin" "$@" -o "$out/frame-$SLURM_ARRAY_TASK_ID.exr"
EOF
array="$(sbatch --parsable --array=0-2 --chdir="$jobs" --output="$jobs/render-%a.log" \
  "$jobs/render.sh" "$bin" "$out" "${render[@]}")"
array="${array%%;*}"
after="$(sbatch --parsable --dependency="afterok:$array" --kill-on-invalid-dep=yes --chdir="$jobs" \
  --output="$jobs/after.log" \
  --wrap="ls $out/frame-*.exr | wc -l >$out/after.txt")"
after="${after%%;*}"
if [ -z "$array" ] || [ -z "$after" ]; then
  fail "sbatch did not submit the jobs"
elif ! slurm_cluster_wait_jobs 120 "$array" "$after"; then
  fail "jobs $array and $after did not finish within 120 s"; squeue
else
  states="$(slurm_cluster_job_states "$array" | sort | uniq -c | xargs)"
  [ "$states" = "3 COMPLETED" ] || fail "array job $array: states '$states', expected 3 COMPLETED"
  for i in 0 1 2; do
    if [ ! -s "$out/frame-$i.exr" ]; then
      fail "task $i wrote no frame"; cat "$jobs/render-$i.log"
    elif ! oiiotool "$out/local.exr" "$out/frame-$i.exr" --fail 0 --warn 0 --diff >"$jobs/diff-$i.log" 2>&1; then
      fail "frame $i's pixels differ from the local render"; cat "$jobs/diff-$i.log"
    fi
  done
  [ "$(slurm_cluster_job_states "$after")" = "COMPLETED" ] ||
    fail "dependent job $after: state '$(slurm_cluster_job_states "$after")'"
  [ "$(cat "$out/after.txt" 2>/dev/null)" = "3" ] ||
    fail "the dependent job saw '$(cat "$out/after.txt" 2>/dev/null)' frames, expected 3"
  ends="$(scontrol -o show job "$array" | tr ' ' '\n' | sed -n 's/^EndTime=//p' | sort | tail -n 1)"
  began="$(job_field "$after" StartTime)"
  [[ "$began" > "$ends" || "$began" == "$ends" ]] ||
    fail "the dependent job started at $began, before the array's last task ended at $ends"
fi

# scancel ends a running job and its process.
sleeper="$(sbatch --parsable --chdir="$jobs" --output="$jobs/sleep.log" \
  --wrap="echo \$\$ >$jobs/sleep.pid; exec sleep 600")"
sleeper="${sleeper%%;*}"
for i in $(seq 1 300); do
  [ -s "$jobs/sleep.pid" ] && [ "$(slurm_cluster_job_states "$sleeper")" = "RUNNING" ] && break
  sleep 0.1
done
pid="$(cat "$jobs/sleep.pid" 2>/dev/null)"
if [ -z "$pid" ]; then
  fail "the sleep job $sleeper did not start within 30 s (state '$(slurm_cluster_job_states "$sleeper")')"
else
  kill -0 "$pid" 2>/dev/null || fail "the sleep job's process $pid is not running"
  scancel "$sleeper" || fail "scancel $sleeper failed"
  slurm_cluster_wait_jobs 30 "$sleeper" || fail "job $sleeper still queued 30 s after scancel"
  [ "$(slurm_cluster_job_states "$sleeper")" = "CANCELLED" ] ||
    fail "job $sleeper: state '$(slurm_cluster_job_states "$sleeper")' after scancel, expected CANCELLED"
  slurm_cluster_wait_exit 10 "$pid" || fail "the cancelled job's process $pid is still running"
fi

[ "$fails" -eq 0 ] || slurm_cluster_logs
slurm_cluster_stop
for pid in $daemons; do
  if kill -0 "$pid" 2>/dev/null; then fail "daemon $pid is still running after the cluster stopped"; fi
done
[ ! -e "$dir" ] || fail "the cluster's directory $dir is still there"
echo "slurm cluster: $fails failures in $(($(date +%s) - start)) s"
[ "$fails" -eq 0 ]
