#!/usr/bin/env bash
# The two set-up commands of README.md:
#   scripts/setup.sh render   install deps, Release build, render scenes/default.gltf (EXR + PNG)
#   scripts/setup.sh test     install deps, Release build, run the whole test suite with ctest,
#                             then again in a Sanitize (ASan + UBSan) build (SANITIZE=0 skips)
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

# The test suite also needs Blender, pytest, Slurm, munge, mkdocs and Chromium; a render needs none of them.
if [ "$mode" = test ]; then bash scripts/install-deps.sh --test; else bash scripts/install-deps.sh; fi
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
    # The same suite again under AddressSanitizer + UndefinedBehaviorSanitizer (build type
    # Sanitize): the unit tests, every hostile corpus file and hostile job file through the CLI,
    # and the command-line scripts. Each slow check runs once, in the stage where it tells the
    # most: these run in the Release suite above only, and their targets are not built here:
    # - the accelerator cross-check over all corpus models (11 minutes instrumented) and the one
    #   of huge and tiny coordinates;
    # - the end-to-end, frame-range, extension and ray-limit scripts (hundreds of renders of the
    #   shipped scenes through paths the unit tests and the other scripts also take here);
    # - the two Slurm tests (they drive slurmctld, slurmd and munge around the same commands the
    #   other CLI tests run), the Blender compositor check (Penumbra's side of it runs in
    #   cli.cryptomatte), the Blender depth-of-field cross-check (Penumbra's lens is in
    #   cli.camera and the unit tests), the install and package tests (packaging, not code paths);
    # - the Python tests (an instrumented module cannot load into Debian's uninstrumented
    #   python3), the benchmark's smoke runs and tests (measurement code), and the format and
    #   OCIO-config checks and the documentation site (the same in any build).
    # SANITIZE=0 skips this stage.
    if [ "${SANITIZE:-1}" != 0 ]; then
      SAN_DIR="${SAN_BUILD_DIR:-build-sanitize}"
      cmake -S . -B "$SAN_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Sanitize -DPENUMBRA_BUILD_PYTHON=OFF
      cmake --build "$SAN_DIR" -j "$JOBS" --target penumbra renderer_tests io_tests render_tests
      ctest --test-dir "$SAN_DIR" --output-on-failure -j "$JOBS" \
        -E "cross-check: every valid corpus model|cross-check: huge and tiny coordinates|cli\.end_to_end|cli\.frames|cli\.extensions|cli\.ray_limits|cli\.slurm_farm|cli\.slurm_cluster|cli\.compositor|cli\.blender_dof|cli\.vector|install\.|python\.|bench\.|scenegen\.|bench_tests_NOT_BUILT|format\.|ocio\.|docs\.|layout\."
    fi
    ;;
esac
