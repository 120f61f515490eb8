#!/usr/bin/env bash
# Installs Penumbra's build and runtime dependencies from Debian 12's archive; with --test also
# the tools its tests run against (Blender for the glTF-import and compositor checks, with NumPy;
# pytest for the Python API; Slurm and munge for the throw-away single-node cluster; mkdocs and
# Chromium to build the documentation site and look at it headless; FCL and CGAL, the oracles of the
# collision tests and benchmark).
# Idempotent: only packages that are missing are installed. Needs root (or sudo).
# Usage: install-deps.sh [--test]
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libembree-dev libtbb-dev
  libopenimageio-dev openimageio-tools libopenexr-dev openexr
  libopencolorio-dev opencolorio-tools
  libtinygltf-dev libstb-dev nlohmann-json3-dev libeigen3-dev
  libdraco-dev draco libmeshoptimizer-dev gltfpack
  catch2 libcli11-dev libbenchmark-dev libnanoflann-dev libqhull-dev
  python3 python3-dev python3-numpy pybind11-dev help2man clang-format
)
case "${1:-}" in
  --test) PACKAGES+=(blender python3-pytest slurm-wlm munge mkdocs chromium libfcl-dev libcgal-dev) ;;
  "") ;;
  *) echo "usage: install-deps.sh [--test]" >&2; exit 2 ;;
esac

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
