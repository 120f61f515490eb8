# Packaging with CPack: `cpack -G DEB` in the build folder makes penumbra_<version>_<arch>.deb of
# everything Install.cmake installs, under /usr. Depends is computed by dpkg-shlibdeps from the
# linked shared libraries (libembree3-3, libtbb12, libopenimageio2.4, libopencolorio2.1,
# libimath-3-1-29, libtinygltf2d, libmeshoptimizer2d, libqhull-r8.0, the C/C++ runtime; OpenEXR comes through
# OpenImageIO; Draco is linked statically);
# Recommends lists the Debian -dev packages that find_package(Penumbra) needs to link against.
set(CPACK_PACKAGE_NAME "penumbra")
set(CPACK_PACKAGE_VENDOR "Penumbra maintainers")
set(CPACK_PACKAGE_CONTACT "Penumbra maintainers <maintainers@penumbra.invalid>")
set(CPACK_PACKAGE_VERSION "${PROJECT_VERSION}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "glTF 2.0 batch renderer (Embree, TBB, OpenEXR, OpenColorIO)")
string(JOIN "" CPACK_PACKAGE_DESCRIPTION
    "Penumbra renders glTF 2.0 scenes to scene-linear OpenEXR and display images through OpenColorIO, "
    "with a Whitted integrator and a path tracer over Embree or its own acceleration structures. "
    "The package holds the penumbra and penumbra-bench commands with their man pages, the shipped "
    "OCIO config, and the penumbra_renderer and penumbra_io libraries with headers and the CMake "
    "package Penumbra (find_package(Penumbra): Penumbra::renderer, Penumbra::io).")
set(CPACK_PACKAGING_INSTALL_PREFIX "/usr")
set(CPACK_STRIP_FILES OFF)

set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION "graphics")
set(CPACK_DEBIAN_PACKAGE_PRIORITY "optional")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${CPACK_PACKAGE_CONTACT}")
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# The package's own libpenumbra_draco.so, found by the commands through $ORIGIN/../lib.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS "${PROJECT_BINARY_DIR}/io")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS
    "libembree-dev, libtbb-dev, libopenimageio-dev, libopencolorio-dev, libtinygltf-dev, nlohmann-json3-dev, libmeshoptimizer-dev, libqhull-dev, pkg-config")

include(CPack)
