#!/usr/bin/env bash
# glTF extensions through `penumbra`: info reports each used extension as supported, partially
# supported or not supported, lists KHR_materials_variants' variants and a file's image-based
# light; render --variant renders a listed variant and refuses an unknown one (exit 2, naming the
# variants, no output left), and stripes of two variants do not merge; a file packed by gltfpack
# (meshopt, quantized) renders.
# Usage: extensions_test.sh PENUMBRA_BINARY SRC WORK_DIR
set -u
bin="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
fails=0; passes=0
source "$(dirname "$0")/expect.sh"

# A file the test writes: one triangle using an unknown extension and a supported one.
printf '{"asset":{"version":"2.0"},"extensionsUsed":["EXT_not_a_real_extension","KHR_materials_clearcoat"],"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],"materials":[{"extensions":{"KHR_materials_clearcoat":{"clearcoatFactor":1}}}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],"bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]}\n' >"$work/mixed.gltf"
expect 0 "KHR_materials_clearcoat +supported" -- "$bin" info "$work/mixed.gltf"
expect 0 "EXT_not_a_real_extension +not supported \(ignored\)" -- "$bin" info "$work/mixed.gltf"

corpus="${PENUMBRA_CORPUS:-${PENUMBRA_CORPUS_DEFAULT:-$src/../shared/corpus}}"
shoe="$corpus/extensions/MaterialsVariantsShoe/glTF/MaterialsVariantsShoe.gltf"
lamp="$corpus/extensions/AnisotropyBarnLamp/glTF-KTX2-Basisu/AnisotropyBarnLamp.gltf"
if [ -f "$shoe" ] && [ -f "$lamp" ]; then
  expect 0 "variants +midnight, beach, street \(--variant NAME\)" -- "$bin" info "$shoe"
  expect 0 "KHR_materials_variants +supported" -- "$bin" info "$shoe"
  expect 0 "KHR_texture_basisu +partially supported: KTX2 images are not decoded" -- "$bin" info "$lamp"
  expect 0 "beach.png" -- "$bin" render "$shoe" --variant beach -o "$work/beach.exr" --width 48 --spp 1 -q
  expect 0 "street.png" -- "$bin" render "$shoe" --variant street -o "$work/street.exr" --width 48 --spp 1 -q
  # Two variants are two looks: the images differ.
  if oiiotool "$work/beach.exr" "$work/street.exr" --diff 2>&1 | grep -q "PASS"; then
    echo "FAIL: the beach and street variants render the same image"; fails=$((fails + 1))
  else
    passes=$((passes + 1))
  fi
  # The variant is part of a render's identity: stripes of two variants do not merge.
  expect 0 "t1.exr" -- "$bin" render "$shoe" --variant beach --tile 0/2 -o "$work/t1.exr" --no-png --width 48 --spp 1 -q
  expect 0 "t2.exr" -- "$bin" render "$shoe" --variant street --tile 1/2 -o "$work/t2.exr" --no-png --width 48 --spp 1 -q
  expect 2 "scene.variant" -- "$bin" merge "$work/t1.exr" "$work/t2.exr" -o "$work/merged.exr"
  expect 0 "t1.exr" -- "$bin" render "$shoe" --variant street --tile 0/2 -o "$work/t1.exr" --no-png --width 48 --spp 1 -q
  expect 0 "merged.exr" -- "$bin" merge "$work/t1.exr" "$work/t2.exr" -o "$work/merged.exr"
  rm -f "$work/none.exr" "$work/none.png"
  expect 2 "no variant 'winter'; variants: 'midnight', 'beach', 'street'" -- \
    "$bin" render "$shoe" --variant winter -o "$work/none.exr" --width 48 --spp 1
  if [ -e "$work/none.exr" ] || [ -e "$work/none.png" ]; then
    echo "FAIL: a refused variant left an output"; fails=$((fails + 1))
  fi
else
  echo "PENUMBRA_SKIP: corpus extension models not found (set PENUMBRA_CORPUS); variant checks skipped"
fi

# gltfpack's meshopt-compressed, quantized default scene renders like the plain one.
if command -v gltfpack >/dev/null; then
  gltfpack -i "$src/scenes/default.gltf" -o "$work/packed.glb" -c >/dev/null 2>&1
  expect 0 "EXT_meshopt_compression +supported" -- "$bin" info "$work/packed.glb"
  expect 0 "KHR_mesh_quantization +supported" -- "$bin" info "$work/packed.glb"
  expect 0 "packed.png" -- "$bin" render "$work/packed.glb" -o "$work/packed.exr" --width 64 --spp 4 -q
else
  echo "PENUMBRA_SKIP: gltfpack not installed; compressed render skipped"
fi

echo "extensions cli: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
