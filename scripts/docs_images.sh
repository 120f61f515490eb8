#!/usr/bin/env bash
# Renders the pictures the documentation pages show, with Penumbra's own commands, into OUTDIR
# (PNG files named as the pages link them: docs/**/*.md refer to images/NAME.png).
# Usage: scripts/docs_images.sh PENUMBRA OUTDIR
# Small on purpose (at most 480 pixels wide, few samples): the whole site builds in well under a
# minute on two cores. The EXRs go to a temporary folder that is removed afterwards; OUTDIR gets
# only the display images. Needs oiiotool (openimageio-tools) for the AOV contact sheet.
set -euo pipefail

if [ $# -ne 2 ]; then
  echo "usage: scripts/docs_images.sh PENUMBRA OUTDIR" >&2
  exit 2
fi
bin="$(realpath "$1")"
out="$2"
src="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
[ -x "$bin" ] || { echo "docs_images: $1 is not an executable" >&2; exit 2; }
command -v oiiotool >/dev/null || { echo "docs_images: oiiotool not found (Debian: openimageio-tools)" >&2; exit 2; }

mkdir -p "$out"
out="$(realpath "$out")"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$src"

step() { printf 'docs_images: %s\n' "$1" >&2; }
# render NAME ARGS...: one render whose display image becomes OUTDIR/NAME.png.
render() {
  local name="$1"; shift
  step "$name.png"
  "$bin" render "$@" -o "$work/$name.exr" --png "$out/$name.png" -q --threads 0 >/dev/null
}

# The default scene with each integrator (getting started, integrators).
render default-whitted scenes/default.gltf --width 480
render default-path scenes/default.gltf --width 480 --integrator path --spp 8
render default-raster scenes/default.gltf --width 480 --integrator raster

# Shapes and procedural textures.
render csg scenes/csg.gltf --width 480
render spheres scenes/spheres.gltf --width 480 --max-depth 8
render procedural scenes/procedural.gltf --width 480
# glTF points and lines (path traced, and the raster preview with the wireframe of the box and
# the floor, hidden edges dashed).
render curves-path scenes/curves.gltf --width 480 --integrator path --spp 32
render curves-wireframe scenes/curves.gltf --width 480 --integrator raster --wireframe \
  --wireframe-nodes box,floor --wireframe-hidden dashed --wireframe-color 1,0.8,0
# Gaussian splats among meshes: ray traced (a mirror sphere reflecting them) and the raster
# preview's EWA splatting.
render splats-whitted scenes/splats.gltf --width 480
render splats-raster scenes/splats.gltf --width 480 --integrator raster
# Depth of field: the focus study focused near and far (cameras).
render focus-near scenes/focus.gltf --width 320 --integrator path --spp 48 --aperture-radius 0.08 \
  --aperture-blades 6 --focus-distance 3.2
render focus-far scenes/focus.gltf --width 320 --integrator path --spp 48 --aperture-radius 0.08 \
  --aperture-blades 6 --focus-distance 13
# Motion blur: the fan and the ball of scenes/motion.gltf at t = 1 s (cameras).
render motion-blur scenes/motion.gltf --width 400 --integrator path --spp 32 --time 1 --motion-blur
# The white furnace without and with energy compensation (integrators).
render furnace-off scenes/furnace.gltf --width 320 --integrator path --spp 64 --env 1 --energy-compensation off
render furnace-on scenes/furnace.gltf --width 320 --integrator path --spp 64 --env 1

# Traversal-cost heat maps of two structures on the default scene (benchmarking).
for accel in bvh grid; do
  step "cost-$accel.png"
  "$bin" render scenes/default.gltf --width 480 --spp 1 --accel "$accel" --aov cost \
    -o "$work/cost-$accel.exr" --png "$work/cost-$accel.png" --cost-png "$out/cost-$accel.png" -q --threads 0 >/dev/null
done

# A turntable of the CSG scene and a frame range of the fly-through, each as one contact sheet.
step "turntable-sheet.png"
"$bin" render scenes/csg.gltf --turntable 8 --orbit 0,25,10 --width 116 --height 116 \
  -o "$work/turn.####.exr" --contact-sheet "$out/turntable-sheet.png" --contact-sheet-columns 4 \
  -q --threads 0 >/dev/null
step "flythrough-sheet.png"
"$bin" render scenes/flythrough.gltf --frames 1-240:30 --width 116 \
  -o "$work/fly.####.exr" --contact-sheet "$out/flythrough-sheet.png" --contact-sheet-columns 4 \
  -q --threads 0 >/dev/null

# The shipped OCIO views on one overexposed render: Standard clips, Filmic rolls off, Raw is linear.
step "views.png"
for view in Standard Filmic Raw; do
  "$bin" render scenes/default.gltf --width 156 --exposure 1.5 --view "$view" \
    -o "$work/view-$view.exr" --png "$work/view-$view.png" -q --threads 0 >/dev/null
done
oiiotool "$work/view-Standard.png" "$work/view-Filmic.png" "$work/view-Raw.png" \
  --mosaic:pad=4 3x1 -d uint8 -o "$out/views.png"

# Every AOV of one path-traced render as a 3 x 3 contact sheet: beauty, albedo, N, Z, P,
# object_id, diffuse_direct, diffuse_indirect, specular_direct.
step "aov-contact-sheet.png"
"$bin" render scenes/default.gltf -o "$work/all.exr" --integrator path --spp 16 --width 152 \
  --aov all --env 0.05 --no-png -q --threads 0 >/dev/null
a="$work/all.exr"
oiiotool "$a" --ch R,G,B --colorconvert linear sRGB \
  "$a" --ch albedo.R,albedo.G,albedo.B --colorconvert linear sRGB \
  "$a" --ch N.X,N.Y,N.Z --mulc 0.5 --addc 0.5 \
  "$a" --ch Z --clamp:min=0:max=8 --mulc 0.125 --colormap viridis \
  "$a" --ch P.X,P.Y,P.Z --mulc 0.2 --addc 0.5 \
  "$a" --ch object_id.X --mulc 0.083 --colormap turbo \
  "$a" --ch diffuse_direct.R,diffuse_direct.G,diffuse_direct.B --colorconvert linear sRGB \
  "$a" --ch diffuse_indirect.R,diffuse_indirect.G,diffuse_indirect.B --colorconvert linear sRGB \
  "$a" --ch specular_direct.R,specular_direct.G,specular_direct.B --colorconvert linear sRGB \
  --mosaic:pad=4 3x3 -d uint8 -o "$out/aov-contact-sheet.png"


# Proxies and collisions: each proxy kind over the corpus's Duck (a Khronos sample model), in rows
# of four: sphere, Ritter, AABB, OBB; capsule, hull, 26-DOP, composite. Without the corpus, over
# the CSG scene's implicit shapes meshed by marching cubes.
step "proxies.png"
model="${PENUMBRA_CORPUS:-$src/../shared/corpus}/valid/Duck/glTF-Binary/Duck.glb"
view=(--orbit 35,20)
if [ ! -f "$model" ]; then
  step "proxies.png: no corpus Duck at $model (set PENUMBRA_CORPUS): the meshed CSG scene instead"
  "$bin" mesh scenes/csg.gltf --resolution 40 -o "$work/csg-mesh.glb" -q >/dev/null
  model="$work/csg-mesh.glb"
  view=(--look-at 0,2.4,6.2 0,1,0)
fi
tiles=()
for kind in sphere ritter aabb obb capsule hull kdop composite; do
  "$bin" proxies "$model" --kind "$kind" --samples 0 --overlay -o "$work/proxies-$kind.glb" >/dev/null
  "$bin" render "$work/proxies-$kind.glb" --width 236 --height 160 "${view[@]}" -o "$work/proxies-$kind.exr" \
    --png "$work/proxies-$kind.png" -q --threads 0 >/dev/null
  tiles+=("$work/proxies-$kind.png")
done
oiiotool "${tiles[@]}" --mosaic:pad=4 4x2 -d uint8 -o "$out/proxies.png"

step "done: $(find "$out" -maxdepth 1 -name '*.png' | wc -l) pictures in $out"
