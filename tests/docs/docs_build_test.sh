#!/usr/bin/env bash
# The documentation site builds and holds together: scripts/docs.sh build (mkdocs --strict, so a
# broken link or a missing page fails) renders the pictures with PENUMBRA and builds into OUTDIR;
# then every page of docs/ must be there (the home page and the reference pages by name), every
# link and anchor resolve, every picture be a valid PNG or SVG, the extension pages' JSON parse and
# their glTF examples load with `penumbra info`, and the README's links resolve.
# Usage: docs_build_test.sh PENUMBRA OUTDIR. Exit 77 (skipped) without mkdocs or oiiotool.
set -u
if [ $# -ne 2 ]; then echo "usage: docs_build_test.sh PENUMBRA OUTDIR" >&2; exit 2; fi
bin="$1"; out="$2"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
src="$(cd "$here/../.." && pwd)"
for tool in mkdocs oiiotool python3; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: $tool not found (scripts/install-deps.sh --test installs it)"
    exit 77
  fi
done
[ -x "$bin" ] || { echo "FAIL: $bin is not an executable"; exit 1; }
bin="$(realpath "$bin")"

start=$SECONDS
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
if ! bash "$src/scripts/docs.sh" build "$bin" "$out" >"$log" 2>&1; then
  cat "$log"
  echo "FAIL: scripts/docs.sh build failed (above)"
  exit 1
fi
grep -E 'WARNING|ERROR' "$log" && { echo "FAIL: mkdocs reported warnings"; exit 1; }
echo "docs build: site in $out ($((SECONDS - start)) s)"
python3 "$here/docs_checks.py" site "$out" "$src" "$bin"
