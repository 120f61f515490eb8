#!/usr/bin/env bash
# Installs Penumbra's build and runtime dependencies from Debian 12's archive, and the tools
# its tests run against (Blender's glTF importer, which needs NumPy; Slurm and munge for the
# throw-away single-node cluster).
# Idempotent: only packages that are missing are installed. Needs root (or sudo).
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libembree-dev libtbb-dev
  libopenimageio-dev openimageio-tools libopenexr-dev openexr
  libopencolorio-dev opencolorio-tools
  libtinygltf-dev libstb-dev nlohmann-json3-dev libeigen3-dev
  libdraco-dev draco libmeshoptimizer-dev gltfpack
  catch2 libcli11-dev libbenchmark-dev
  python3 clang-format
  blender python3-numpy
  slurm-wlm munge
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "penumbra: all ${#PACKAGES[@]} Debian packages already installed" >&2
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "penumbra: installing ${missing[*]}" >&2
$SUDO apt-get update -q
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
