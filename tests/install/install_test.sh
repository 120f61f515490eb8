#!/usr/bin/env bash
# The installed tree end to end: `cmake --install` into a fresh prefix, which is then moved (the
# install must be relocatable); every promised file is there (commands, libraries, all headers
# under include/penumbra/, the CMake package, the OCIO config, the man pages); the installed
# `penumbra` and `penumbra-bench` run from the moved prefix and render a shipped scene; the man
# page is roff whose text has a section for every subcommand with each of `render`'s options;
# a project outside the tree (tests/install/consumer) finds the package with find_package,
# builds against it and loads, counts (equal to `penumbra info`), renders and writes a scene.
# Usage: install_test.sh BUILD SRC LIBDIR CXX [CXXFLAGS [LDFLAGS]]
set -u
build="$1"; src="$2"; libdir="$3"; cxx="$4"; cxxflags="${5:-}"; ldflags="${6:-}"
work="$(mktemp -d "${TMPDIR:-/tmp}/penumbra-install.XXXXXX")"
trap 'rm -rf "$work"' EXIT
fails=0; passes=0

# expect CODE PATTERN -- command...: counts a pass or a failure in $passes / $fails.
source "$src/tests/apps/expect.sh"
check() {  # check DESCRIPTION command...: a pass if the command succeeds
  local what="$1"; shift
  if "$@"; then passes=$((passes + 1)); else echo "FAIL: $what"; fails=$((fails + 1)); fi
}
magic() {  # magic FILE HEX: the file starts with these bytes
  [ -f "$1" ] && [ "$(head -c $((${#2} / 2)) "$1" | od -An -tx1 | tr -d ' \n')" = "$2" ]
}

# Install, then move the prefix: nothing may point back to where it was installed.
expect 0 "Installing: .*/bin/penumbra" -- cmake --install "$build" --prefix "$work/staged"
[ "$fails" -eq 0 ] || { echo "install: the install failed"; exit 1; }
mv "$work/staged" "$work/prefix"
p="$work/prefix"

# Every promised file.
for f in bin/penumbra bin/penumbra-bench share/penumbra/ocio/config.ocio \
         share/man/man1/penumbra.1 share/man/man1/penumbra-bench.1 \
         "$libdir/libpenumbra_renderer.a" "$libdir/libpenumbra_io.a" "$libdir/libpenumbra_draco.so" \
         "$libdir/cmake/Penumbra/PenumbraConfig.cmake" "$libdir/cmake/Penumbra/PenumbraConfigVersion.cmake" \
         "$libdir/cmake/Penumbra/PenumbraTargets.cmake"; do
  check "$f installed" test -s "$p/$f"
done
check "bin/penumbra is executable" test -x "$p/bin/penumbra"
check "the installed OCIO config is the shipped one" cmp -s "$src/io/image/ocio/config.ocio" "$p/share/penumbra/ocio/config.ocio"
missing=0
while IFS= read -r h; do
  [ -f "$p/include/penumbra/$h" ] || { echo "FAIL: header include/penumbra/$h not installed"; missing=$((missing + 1)); }
done < <(cd "$src" && find renderer io \( -name '*.h' -o -name '*.inl' \) | sort)
check "every renderer/ and io/ header installed ($missing missing)" test "$missing" -eq 0
check "no source file installed as a header" \
  test -z "$(find "$p/include" -name '*.cpp' -o -name 'CMakeLists.txt')"
check "the package names no build or source folder" \
  test -z "$(grep -lF -e "$build" -e "$src/" "$p/$libdir/cmake/Penumbra/"*.cmake)"

# The installed commands run from the moved prefix with its own libpenumbra_draco.so.
draco=$(env -u LD_LIBRARY_PATH ldd "$p/bin/penumbra" | awk '$1 == "libpenumbra_draco.so" {print $3}')
check "penumbra finds libpenumbra_draco.so in the prefix (ldd: '$draco')" \
  test -n "$draco" -a "$(readlink -f "$draco")" = "$(readlink -f "$p/$libdir/libpenumbra_draco.so")"
mkdir -p "$work/run"
cd "$work/run" || exit 1
expect 0 "^penumbra [0-9]+\.[0-9]+\.[0-9]+" -- env -u LD_LIBRARY_PATH "$p/bin/penumbra" --version
expect 0 "default\.exr" -- env -u LD_LIBRARY_PATH -u OCIO "$p/bin/penumbra" render "$src/scenes/default.gltf" \
  -o "$work/run/default.exr" --width 48 --height 27 --spp 1 --threads 2
check "the installed penumbra wrote an OpenEXR file" magic "$work/run/default.exr" 762f3101
check "the installed penumbra wrote a PNG display image" magic "$work/run/default.png" 89504e47
expect 0 "embree" -- env -u LD_LIBRARY_PATH "$p/bin/penumbra-bench" "$src/scenes/default.gltf" --accel embree \
  --width 16 --height 9 --builds 1 --repeats 1 --threads 1

# The man page: help2man's roff, with a section per subcommand (read from the installed
# command's own --help), every option of `penumbra render --help` in the render section (roff
# escapes hyphens: \-\-spp), and in the text `man -l` formats (when man is installed).
man1="$p/share/man/man1/penumbra.1"
check "penumbra.1 is help2man roff" grep -q '^\.TH PENUMBRA "1"' "$man1"
check "penumbra.1 has a SUBCOMMANDS section" grep -q '^\.SH SUBCOMMANDS' "$man1"
subs=$("$p/bin/penumbra" --help | sed -n '/^Subcommands:/,/^$/p' | sed -n 's/^  \([a-z][a-z0-9_-]*\).*/\1/p')
check "penumbra --help lists subcommands" test -n "$subs"
for s in $subs; do
  check "penumbra.1 has a 'penumbra $s' section" grep -q "^\.SS \"penumbra $s\"" "$man1"
done
check "penumbra.1 has the nested 'penumbra submit slurm' section" grep -q '^\.SS "penumbra submit slurm"' "$man1"
sed -n '/^\.SS "penumbra render"/,/^\.S[SH] /p' "$man1" >"$work/render.roff"
opts=$("$p/bin/penumbra" render --help | grep -oE -- '--[a-z][a-z0-9-]*' | sort -u)
check "penumbra render --help lists options" test -n "$opts"
missing=0
for o in $opts; do
  grep -qF -- "${o//-/\\-}" "$work/render.roff" || { echo "FAIL: render's $o not in penumbra.1"; missing=$((missing + 1)); }
done
check "every render option in penumbra.1's render section ($missing missing)" test "$missing" -eq 0
check "penumbra-bench.1 is help2man roff" grep -q '^\.TH PENUMBRA-BENCH "1"' "$p/share/man/man1/penumbra-bench.1"
if command -v man >/dev/null; then
  MANWIDTH=200 man -l "$man1" >"$work/penumbra.txt" 2>"$work/man.err"
  check "man -l formats penumbra.1" grep -q '^ *penumbra render$' "$work/penumbra.txt"
  missing=0
  for o in $opts; do grep -qF -- "$o" "$work/penumbra.txt" || missing=$((missing + 1)); done
  check "man -l shows every render option ($missing missing)" test "$missing" -eq 0
  check "man -l penumbra-bench.1 shows --accel" \
    grep -qF -- '--accel' <(MANWIDTH=200 man -l "$p/share/man/man1/penumbra-bench.1")
else
  echo "note: man not installed, the formatted man page is not checked"
fi

# A consumer project: find_package(Penumbra) from the moved prefix only.
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
expect 0 "Build files have been written" -- cmake -S "$src/tests/install/consumer" -B "$work/consumer" "${generator[@]}" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_CXX_FLAGS="$cxxflags" \
  -DCMAKE_EXE_LINKER_FLAGS="$ldflags" -DCMAKE_PREFIX_PATH="$p" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
check "the consumer found the installed package" \
  grep -qx "Penumbra_DIR:PATH=$p/$libdir/cmake/Penumbra" "$work/consumer/CMakeCache.txt"
expect 0 "penumbra_consumer" -- cmake --build "$work/consumer"
[ -x "$work/consumer/penumbra_consumer" ] || sed 's/^/  | /' "$work/out" | tail -20
info=$(env -u LD_LIBRARY_PATH "$p/bin/penumbra" info "$src/scenes/default.gltf")
rendered=$(grep -oE '[0-9]+ triangles rendered' <<<"$info" | grep -oE '^[0-9]+')
stored=$(grep -oE 'triangle meshes, [0-9]+ triangles' <<<"$info" | grep -oE '[0-9]+ triangles' | grep -oE '^[0-9]+')
check "penumbra info gives the triangle counts ('$rendered', '$stored')" test -n "$rendered" -a -n "$stored"
expect 0 "^triangles rendered $rendered$" -- env -u OCIO "$work/consumer/penumbra_consumer" \
  "$src/scenes/default.gltf" "$work/consumer/tiny.exr" "$work/consumer/tiny.png"
check "the consumer's stored triangle count is info's ($stored)" grep -qx "triangles stored $stored" "$work/out"
check "the consumer's render lit some of its 576 pixels" grep -qE '^lit pixels ([1-9][0-9]*)$' "$work/out"
check "the consumer wrote an OpenEXR file" magic "$work/consumer/tiny.exr" 762f3101
check "the consumer wrote a PNG display image" magic "$work/consumer/tiny.png" 89504e47

echo "install: $passes passed, $fails failed"
[ "$fails" -eq 0 ]
