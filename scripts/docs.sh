#!/usr/bin/env bash
# Builds the documentation site (mkdocs.yml, docs/) with the pictures rendered by Penumbra itself.
#
#   scripts/docs.sh build PENUMBRA OUTDIR   the site into OUTDIR (mkdocs build --strict)
#   scripts/docs.sh stage PENUMBRA DIR      only the staged sources into DIR, for
#                                           `mkdocs serve -f DIR/mkdocs.yml` while writing
#
# Both copy mkdocs.yml and docs/ into a staging folder, render the pictures into its docs/images
# (scripts/docs_images.sh) and copy the repository files the pages link to outside docs/, such as
# benchmarks/RESULTS.md, into its docs/repo (scripts/docs_stage_links.py). The pictures are never
# written into the source tree. `build` removes the staging folder afterwards.
# Needs Debian's mkdocs (scripts/install-deps.sh --test installs it) and oiiotool.
set -euo pipefail

usage() { echo "usage: scripts/docs.sh build PENUMBRA OUTDIR | stage PENUMBRA DIR" >&2; exit 2; }
[ $# -eq 3 ] || usage
mode="$1"; bin="$2"; dest="$3"
case "$mode" in build|stage) ;; *) usage ;; esac
src="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
[ -x "$bin" ] || { echo "docs: $bin is not an executable" >&2; exit 2; }
bin="$(realpath "$bin")"

if [ "$mode" = build ]; then
  command -v mkdocs >/dev/null || { echo "docs: mkdocs not found (Debian: mkdocs)" >&2; exit 2; }
  # mkdocs empties the site folder first: never let that be anything but a site.
  if [ -d "$dest" ] && [ -n "$(ls -A "$dest")" ] && [ ! -f "$dest/index.html" ]; then
    echo "docs: $dest is a non-empty folder that holds no site; give an empty or new folder" >&2
    exit 2
  fi
  stage="$(mktemp -d)"
  trap 'rm -rf "$stage"' EXIT
else
  if [ -e "$dest" ] && [ -n "$(ls -A "$dest")" ]; then
    echo "docs: $dest exists and is not empty" >&2
    exit 2
  fi
  mkdir -p "$dest"
  stage="$(realpath "$dest")"
fi

start=$SECONDS
cp "$src/mkdocs.yml" "$stage/mkdocs.yml"
cp -r "$src/docs" "$stage/docs"
bash "$src/scripts/docs_images.sh" "$bin" "$stage/docs/images"
python3 "$src/scripts/docs_stage_links.py" "$stage/docs" "$src"

if [ "$mode" = stage ]; then
  echo "docs: staged in $stage; preview with: mkdocs serve -f $stage/mkdocs.yml" >&2
  exit 0
fi
mkdir -p "$dest"
dest="$(realpath "$dest")"
mkdocs build --strict --clean -f "$stage/mkdocs.yml" -d "$dest"
echo "docs: site in $dest ($((SECONDS - start)) s)" >&2
echo "$dest/index.html"
