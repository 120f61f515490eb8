# Installation: `cmake --install build --prefix P` puts the commands in P/bin, the libraries
# penumbra_renderer, penumbra_io, penumbra_render and penumbra_draco in P/lib with their headers
# in P/include/penumbra/{renderer,io,render}/, the CMake package Penumbra (Penumbra::renderer,
# Penumbra::io, Penumbra::render) in P/lib/cmake/Penumbra, the shipped OCIO config in P/share/penumbra/ocio and
# the man pages (generated from --help by help2man) in P/share/man/man1. Packaging: Packaging.cmake.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(PENUMBRA_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/Penumbra")

# The commands find libpenumbra_draco.so beside them in the prefix, wherever it is moved.
set_target_properties(penumbra penumbra-bench PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
install(TARGETS penumbra penumbra-bench RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# The exported libraries. penumbra_warnings and penumbra_arch appear in the static libraries'
# link interface only as $<LINK_ONLY:...> and carry no link items, so exporting them gives
# consumers no compile flags.
set_target_properties(penumbra_renderer PROPERTIES EXPORT_NAME renderer)
set_target_properties(penumbra_io PROPERTIES EXPORT_NAME io)
set_target_properties(penumbra_render PROPERTIES EXPORT_NAME render)
set_target_properties(penumbra_draco PROPERTIES EXPORT_NAME draco)
set_target_properties(penumbra_warnings PROPERTIES EXPORT_NAME warnings)
set_target_properties(penumbra_arch PROPERTIES EXPORT_NAME arch)
install(TARGETS penumbra_renderer penumbra_io penumbra_render penumbra_draco penumbra_warnings penumbra_arch
        EXPORT PenumbraTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# Headers keep their source paths: #include "renderer/core/math.h", "io/gltf/loader.h".
foreach(_penumbra_dir renderer io render)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${_penumbra_dir}/
          DESTINATION include/penumbra/${_penumbra_dir}
          FILES_MATCHING PATTERN "*.h" PATTERN "*.inl")
endforeach()

install(EXPORT PenumbraTargets NAMESPACE Penumbra:: FILE PenumbraTargets.cmake
        DESTINATION ${PENUMBRA_INSTALL_CMAKEDIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/PenumbraConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/PenumbraConfig.cmake
                              INSTALL_DESTINATION ${PENUMBRA_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/PenumbraConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/PenumbraConfig.cmake ${PROJECT_BINARY_DIR}/PenumbraConfigVersion.cmake
        DESTINATION ${PENUMBRA_INSTALL_CMAKEDIR})

# The shipped OpenColorIO config (the binaries also embed it; this copy is for $OCIO and other tools).
install(FILES ${PROJECT_SOURCE_DIR}/io/image/ocio/config.ocio DESTINATION ${CMAKE_INSTALL_DATADIR}/penumbra/ocio)

# Man pages from --help, each command's subcommands' --help included as sections
# (ManInclude.cmake writes them), rebuilt whenever the executable is.
find_program(HELP2MAN help2man)
if(HELP2MAN)
  set(_penumbra_man_dir ${PROJECT_BINARY_DIR}/man)
  file(MAKE_DIRECTORY ${_penumbra_man_dir})
  set(_penumbra_man_pages "")
  foreach(_penumbra_cmd penumbra penumbra-bench)
    if(_penumbra_cmd STREQUAL "penumbra")
      set(_penumbra_man_name "glTF 2.0 batch renderer (Embree, TBB, OpenEXR, OpenColorIO)")
      set(_penumbra_man_version "")
    else()
      set(_penumbra_man_name "acceleration-structure benchmark of the Penumbra renderer")
      set(_penumbra_man_version --version-string "${_penumbra_cmd} ${PROJECT_VERSION}")
    endif()
    set(_penumbra_h2m ${_penumbra_man_dir}/${_penumbra_cmd}.h2m)
    set(_penumbra_page ${_penumbra_man_dir}/${_penumbra_cmd}.1)
    add_custom_command(
      OUTPUT ${_penumbra_page}
      COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:${_penumbra_cmd}> -DOUTPUT=${_penumbra_h2m}
              -P ${CMAKE_CURRENT_LIST_DIR}/ManInclude.cmake
      COMMAND ${HELP2MAN} --no-info --no-discard-stderr --section 1 --name ${_penumbra_man_name}
              ${_penumbra_man_version} --include ${_penumbra_h2m} --output ${_penumbra_page}
              $<TARGET_FILE:${_penumbra_cmd}>
      DEPENDS ${_penumbra_cmd} ${CMAKE_CURRENT_LIST_DIR}/ManInclude.cmake
      COMMENT "Generating man page ${_penumbra_cmd}.1 with help2man"
      VERBATIM)
    list(APPEND _penumbra_man_pages ${_penumbra_page})
  endforeach()
  add_custom_target(penumbra_man ALL DEPENDS ${_penumbra_man_pages})
  install(FILES ${_penumbra_man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
else()
  message(STATUS "help2man not found: the man pages penumbra.1 and penumbra-bench.1 are not generated")
endif()

include(${CMAKE_CURRENT_LIST_DIR}/Packaging.cmake)
