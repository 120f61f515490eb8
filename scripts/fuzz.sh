#!/usr/bin/env bash
# Builds Penumbra's libFuzzer targets with clang (ASan + UBSan) in build-fuzz/ and runs one or
# all of them for SECONDS each (default 300). Findings (crash-*, leak-*, timeout-*, oom-*) land in
# build-fuzz/findings/TARGET/, the growing corpus in build-fuzz/work/TARGET/.
# Usage: scripts/fuzz.sh [TARGET] [SECONDS]
#   TARGET: gltf_loader (default; seeded with the shared corpus's valid and invalid files and
#           scenes/), checkpoint (resume state reader), exr_merge (merge part reader), or all.
#           checkpoint and exr_merge write their seeds at run time with Penumbra's own writers
#           (PENUMBRA_FUZZ_WRITE_SEEDS) into build-fuzz/seeds/TARGET/.
#   A lone number is taken as SECONDS for gltf_loader (scripts/fuzz.sh 600).
# On a shared machine, wrap the call in the build lock: flock /tmp/penumbra-build.lock scripts/fuzz.sh ...
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
target="${1:-gltf_loader}"
if [[ "$target" =~ ^[0-9]+$ ]]; then
  set -- gltf_loader "$target"
  target=gltf_loader
fi
seconds="${2:-300}"
case "$target" in
  gltf_loader | checkpoint | exr_merge | job_file) targets=("$target") ;;
  all) targets=(gltf_loader checkpoint exr_merge job_file) ;;
  *) echo "usage: scripts/fuzz.sh [gltf_loader|checkpoint|exr_merge|job_file|all] [SECONDS]" >&2; exit 2 ;;
esac
bash scripts/install-deps.sh
if ! command -v clang++ >/dev/null; then
  apt-get install -y --no-install-recommends clang
fi
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DPENUMBRA_FUZZ=ON -DPENUMBRA_BUILD_TESTS=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=undefined"
cmake --build build-fuzz --target "${targets[@]/%/_fuzz}"
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp"
for t in "${targets[@]}"; do
  bin="build-fuzz/fuzz/${t}_fuzz"
  mkdir -p "build-fuzz/work/$t" "build-fuzz/findings/$t"
  seeds=()
  case "$t" in
    gltf_loader)
      corpus="${PENUMBRA_CORPUS:-../shared/corpus}"
      [ -d "$corpus" ] && seeds+=("$corpus/invalid" "$corpus/valid")
      seeds+=(scenes)
      max_len=65536
      extra=()
      ;;
    job_file)
      rm -rf "build-fuzz/seeds/$t"
      PENUMBRA_FUZZ_WRITE_SEEDS="build-fuzz/seeds/$t" "$bin"
      seeds+=("build-fuzz/seeds/$t")
      max_len=16384
      extra=(-malloc_limit_mb=512)
      ;;
    checkpoint | exr_merge)
      rm -rf "build-fuzz/seeds/$t"
      PENUMBRA_FUZZ_WRITE_SEEDS="build-fuzz/seeds/$t" "$bin"
      seeds+=("build-fuzz/seeds/$t")
      max_len=16384
      extra=(-malloc_limit_mb=512)  # the targets bound what they decode far below this
      ;;
  esac
  echo "fuzz.sh: running $t for $seconds s" >&2
  "$bin" -max_total_time="$seconds" -max_len="$max_len" -rss_limit_mb=2048 -timeout=20 \
    -artifact_prefix="build-fuzz/findings/$t/" "${extra[@]}" "build-fuzz/work/$t" "${seeds[@]}"
done
