#!/usr/bin/env bash
# The folder-level arrows point one way: each folder below includes only folders to its right.
#   apps/, python/, benchmarks/  ->  render/  ->  io/  ->  renderer/
#   io/: image/ -> farm/ -> gltf/ -> files/, mesh/ -> files/; no file at io/'s top level
# Usage: layering_test.sh SRC
set -u
cd "$1" || exit 1
bad=0
check() {  # check FOLDER FORBIDDEN-INCLUDE-REGEX
  local hits
  hits=$(grep -rnE "#include \"($2)" "$1" --include='*.h' --include='*.cpp' --include='*.inl' 2>/dev/null)
  if [ -n "$hits" ]; then echo "$1 includes what it must not ($2):"; echo "$hits" | head -5; bad=$((bad + 1)); fi
}
check renderer 'io/|render/|apps/|python/|benchmarks/'
check io 'render/|apps/|python/|benchmarks/'
check render 'apps/|python/|benchmarks/'
check io/files 'io/(gltf|mesh|image|farm)/'
check io/gltf 'io/(mesh|image|farm)/'
check io/mesh 'io/(gltf|image|farm)/'
check io/farm 'io/(image|mesh)/'
loose=$(find io -maxdepth 1 -type f \( -name '*.h' -o -name '*.cpp' \))
if [ -n "$loose" ]; then echo "files at io/'s top level: $loose"; bad=$((bad + 1)); fi
echo "layering: $bad violation(s)"
[ "$bad" -eq 0 ]
