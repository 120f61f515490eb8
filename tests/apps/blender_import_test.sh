#!/usr/bin/env bash
# Tools that do not know PENUMBRA_shapes or PENUMBRA_procedural still load the shipped scenes that
# use them (the extensions are only in extensionsUsed): Blender's glTF importer imports each
# without a Python error. Skipped (reported by ctest as skipped) when `blender` is not installed.
# Usage: blender_import_test.sh SRC WORK_DIR
set -u
src="$1"; work="$2"
if ! command -v blender >/dev/null; then
  echo "PENUMBRA_SKIP: blender is not installed"
  exit 0
fi
rm -rf "$work"; mkdir -p "$work"
fails=0
for scene in csg spheres procedural focus; do
  file="$src/scenes/$scene.gltf"
  blender -b --factory-startup --python-exit-code 1 \
    --python-expr "import bpy; bpy.ops.import_scene.gltf(filepath=r'''$file''')" >"$work/$scene.log" 2>&1
  code=$?
  if [ "$code" -ne 0 ] || grep -q "Traceback" "$work/$scene.log"; then
    echo "FAIL: blender could not import $file (exit $code)"; tail -20 "$work/$scene.log"
    fails=$((fails + 1))
  fi
done
echo "blender import: $fails failures"
[ "$fails" -eq 0 ]
