#!/usr/bin/env bash
# The Debian package: `cpack -G DEB` from the build folder into a temporary folder; its control
# fields (package, version, section, maintainer, description); Depends names the Debian package
# of every shared library the built `penumbra` needs (found with dpkg -S, the package's own
# libpenumbra_draco.so excepted) and no Draco (linked statically); the promised files are in it
# under /usr; the unpacked penumbra runs.
# Usage: deb_test.sh BUILD VERSION LIBDIR
set -u
build="$1"; version="$2"; libdir="$3"
work="$(mktemp -d "${TMPDIR:-/tmp}/penumbra-deb.XXXXXX")"
trap 'rm -rf "$work"' EXIT
fails=0; passes=0

# expect CODE PATTERN -- command...: counts a pass or a failure in $passes / $fails.
source "$(dirname "$0")/../apps/expect.sh"
check() {  # check DESCRIPTION command...: a pass if the command succeeds
  local what="$1"; shift
  if "$@"; then passes=$((passes + 1)); else echo "FAIL: $what"; fails=$((fails + 1)); fi
}

mkdir -p "$work/pkg"
expect 0 "package: .*\.deb generated" -- cpack -G DEB --config "$build/CPackConfig.cmake" -B "$work/pkg"
deb=$(find "$work/pkg" -maxdepth 1 -name 'penumbra_*.deb' | head -1)
check "cpack wrote penumbra_${version}_<arch>.deb ($deb)" test -n "$deb" -a -s "$deb"
[ -n "$deb" ] || { echo "deb: $passes passed, $fails failed"; exit 1; }

dpkg-deb -f "$deb" >"$work/control"
field() { sed -n "s/^$1: //p" "$work/control"; }
check "Package is penumbra" test "$(field Package)" = penumbra
check "Version is $version" test "$(field Version)" = "$version"
check "Section is graphics" test "$(field Section)" = graphics
check "Maintainer is set" test -n "$(field Maintainer)"
check "Description has a summary" grep -q '^Description: glTF 2.0 batch renderer' "$work/control"
check "the long description names the CMake package" grep -q '^ .*find_package(Penumbra)' "$work/control"
check "the long description is one text, not a CMake list" test -z "$(grep -F ';' "$work/control")"
depends=$(field Depends)
echo "Depends: $depends"

# The Debian package of each shared library the built binary needs, by dpkg -S (on merged-/usr
# systems dpkg knows some under /lib, some under /usr/lib).
has_dep() { tr ',' '\n' <<<"$depends" | sed 's/^ *//; s/ .*//' | grep -qxF -- "$1"; }
owner() {
  local real; real=$(readlink -f "$1")
  for f in "$1" "$real" "${real#/usr}" "/usr${real#/usr}"; do
    dpkg -S "$f" 2>/dev/null | head -1 | cut -d: -f1 | grep . && return 0
  done
  return 1
}
needed=$(objdump -p "$build/apps/penumbra" | awk '$1 == "NEEDED" {print $2}')
check "objdump lists penumbra's shared libraries" test -n "$needed"
for lib in $needed; do
  [ "$lib" = libpenumbra_draco.so ] && continue
  path=$(ldconfig -p | awk -v l="$lib" '$1 == l && /x86-64/ {print $NF; exit}')
  [ -n "$path" ] || path=$(ldconfig -p | awk -v l="$lib" '$1 == l {print $NF; exit}')
  pkg=$(owner "$path")
  check "$lib has a Debian package ($path)" test -n "$pkg"
  [ -n "$pkg" ] && check "Depends names $pkg (for $lib)" has_dep "$pkg"
done
for pkg in libembree3-3 libtbb12 libopenimageio2.4 libopencolorio2.1 libtinygltf2d libmeshoptimizer2d; do
  check "Depends names $pkg" has_dep "$pkg"
done
check "Depends names no Draco package (linked statically)" test -z "$(grep -o 'libdraco[^ ,]*' <<<"$depends")"

# The files, under /usr.
dpkg-deb -c "$deb" | awk '{print $NF}' >"$work/files"
for f in ./usr/bin/penumbra ./usr/bin/penumbra-bench ./usr/share/penumbra/ocio/config.ocio \
         ./usr/share/man/man1/penumbra.1 ./usr/share/man/man1/penumbra-bench.1 \
         ./usr/include/penumbra/renderer/core/math.h ./usr/include/penumbra/io/gltf/loader.h \
         "./usr/$libdir/libpenumbra_renderer.a" "./usr/$libdir/libpenumbra_io.a" "./usr/$libdir/libpenumbra_draco.so" \
         "./usr/$libdir/cmake/Penumbra/PenumbraConfig.cmake" "./usr/$libdir/cmake/Penumbra/PenumbraConfigVersion.cmake" \
         "./usr/$libdir/cmake/Penumbra/PenumbraTargets.cmake"; do
  check "the package holds $f" grep -qxF "$f" "$work/files"
done

# Unpacked anywhere, the command runs with the package's own libpenumbra_draco.so.
dpkg-deb -x "$deb" "$work/root"
expect 0 "^penumbra $version" -- env -u LD_LIBRARY_PATH "$work/root/usr/bin/penumbra" --version

echo "deb: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
