#!/usr/bin/env bash
# The two set-up commands of README.md:
#   scripts/setup.sh render   install deps, Release build, render scenes/default.gltf (EXR + PNG)
#   scripts/setup.sh test     install deps, Release build, run the whole test suite with ctest,
#                             the unit tests and bad-input scripts in a Sanitize (ASan + UBSan)
#                             build (SANITIZE=0 skips it)
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
    # The suite runs in two stages, each check once, in the stage where it tells the most.
    # Release (build/): everything but the Catch2 files' light cases (label unit) and the
    # scripts labelled bad-input, when the sanitizer stage follows.
    # Sanitize (build-sanitize/, ASan + UBSan; SANITIZE=0 skips it, and the Release stage then
    # runs everything): the unit tests' light cases and the scripts that feed the command hostile
    # input, where a memory error is what a test must catch:
    # - the scripts labelled bad-input: cli.hostile_input (every malformed corpus file) and
    #   cli.job_hardening (hostile job files);
    # - every unit test case not tagged [heavy].
    # In Release only:
    # - the cases tagged [heavy] (label unit-heavy: the accelerator and raster cross-checks over
    #   every corpus model and at huge and tiny coordinates, the renders with every accelerator,
    #   the grid's stadium, the corpus's counts and materials re-read after every file has
    #   loaded, the denoiser's error on a shipped scene, and the statistical estimates of many
    #   samples: BSDF albedo furnaces, the path tracer's convergence rate, the refitted BVH
    #   against brute force, the noise bounds), too slow under the sanitizers;
    # - the other scripts: they render the shipped scenes through the command's options, paths
    #   the unit tests take under the sanitizers; so do the Slurm tests (daemons around the same
    #   commands), the Blender checks, install and package, Python (an instrumented module cannot
    #   load into Debian's uninstrumented python3), the benchmark's smoke runs and tests
    #   (measurement code, not built there; label benchmark-unit), the FCL and CGAL oracles
    #   (label oracle: test-only libraries, not built there), and the format, OCIO-config,
    #   layering and documentation checks (the same in any build).
    if [ "${SANITIZE:-1}" != 0 ]; then
      ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" -LE '^(bad-input|unit)$'
      SAN_DIR="${SAN_BUILD_DIR:-build-sanitize}"
      cmake -S . -B "$SAN_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Sanitize -DPENUMBRA_BUILD_PYTHON=OFF
      cmake --build "$SAN_DIR" -j "$JOBS" --target penumbra renderer_tests io_tests render_tests
      ctest --test-dir "$SAN_DIR" --output-on-failure -j "$JOBS" -L '^(unit|bad-input)$'
    else
      ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS"
    fi
    ;;
esac
