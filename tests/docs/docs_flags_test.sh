#!/usr/bin/env bash
# The command reference and the programs agree: for `penumbra` and every subcommand its --help
# lists (and penumbra-bench, and penumbra-scenegen beside it, when PENUMBRA_BENCH is given), every
# option --help prints is in the first column of that command's option table in
# docs/reference/commands.md (its "## penumbra render" section, ...), and every option the table
# lists is in --help. Every help text that lists acceleration structures must name all of them
# (embree, bvh, kdtree, grid, octree, bsp, brute), and so must each section's --accel row.
# Usage: docs_flags_test.sh PENUMBRA [PENUMBRA_BENCH]
set -u
if [ $# -lt 1 ] || [ $# -gt 2 ]; then echo "usage: docs_flags_test.sh PENUMBRA [PENUMBRA_BENCH]" >&2; exit 2; fi
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
src="$(cd "$here/../.." && pwd)"
for b in "$@"; do [ -x "$b" ] || { echo "FAIL: $b is not an executable"; exit 1; }; done
args=("$(realpath "$1")")
[ $# -eq 2 ] && args+=("$(realpath "$2")")
python3 "$here/docs_checks.py" flags "$src" "${args[@]}"
