#!/usr/bin/env bash
# The two set-up commands of README.md:
#   scripts/setup.sh render   install deps, Release build, render scenes/default.gltf (EXR + PNG)
#   scripts/setup.sh test     install deps, Release build, run the whole test suite with ctest
# BUILD_DIR (default: build) and JOBS (default: nproc) may be overridden from the environment.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
mode="${1:-}"
case "$mode" in
  render|test|build) ;;
  *) echo "usage: scripts/setup.sh render|test|build" >&2; exit 2 ;;
esac

BUILD_DIR="${BUILD_DIR:-build}"
JOBS="${JOBS:-$(nproc)}"

bash scripts/install-deps.sh
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$BUILD_DIR" -j "$JOBS"

case "$mode" in
  render)
    mkdir -p "$BUILD_DIR/renders"
    "$BUILD_DIR/apps/penumbra" render scenes/default.gltf \
      -o "$BUILD_DIR/renders/default.exr" --png "$BUILD_DIR/renders/default.png"
    ;;
  test)
    ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS"
    ;;
esac
