#!/usr/bin/env bash
# Builds the libFuzzer target for the glTF loader with clang (ASan + UBSan) and runs it for
# SECONDS (default 300), seeded with the shared corpus's valid and invalid files.
# Findings (crash-*, leak-*, timeout-*) land in build-fuzz/findings/.
# Usage: scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
seconds="${1:-300}"
bash scripts/install-deps.sh
if ! command -v clang++ >/dev/null; then
  apt-get install -y --no-install-recommends clang
fi
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DPENUMBRA_FUZZ=ON -DPENUMBRA_BUILD_TESTS=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=undefined"
cmake --build build-fuzz --target gltf_loader_fuzz
corpus="${PENUMBRA_CORPUS:-../shared/corpus}"
mkdir -p build-fuzz/work build-fuzz/findings
seeds=()
[ -d "$corpus" ] && seeds+=("$corpus/invalid" "$corpus/valid")
seeds+=(scenes)
LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp" \
  build-fuzz/fuzz/gltf_loader_fuzz -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 \
  -timeout=20 -artifact_prefix=build-fuzz/findings/ build-fuzz/work "${seeds[@]}"
