# Finds Penumbra's Debian-packaged dependencies as imported targets and repairs the known
# packaging faults of Debian 12 (bookworm). Nothing is downloaded.
find_package(Threads REQUIRED)
find_package(embree 3 CONFIG REQUIRED)            # target: embree
find_package(TBB CONFIG REQUIRED)                 # TBB::tbb
find_package(TinyGLTF CONFIG REQUIRED)            # TinyGLTF::TinyGLTF (shared library)
find_package(nlohmann_json 3 CONFIG REQUIRED)     # nlohmann_json::nlohmann_json
find_package(CLI11 CONFIG REQUIRED)               # CLI11::CLI11
find_package(OpenImageIO CONFIG REQUIRED)         # OpenImageIO::OpenImageIO
find_package(meshoptimizer CONFIG REQUIRED)       # meshoptimizer::meshoptimizer
find_package(Qhull CONFIG REQUIRED)               # Qhull::qhull_r (reentrant C library)

# Debian's OpenImageIO target lists /usr/include/opencv4, which does not exist without OpenCV.
foreach(_oiio_target OpenImageIO::OpenImageIO OpenImageIO::OpenImageIO_Util)
  if(TARGET ${_oiio_target})
    get_target_property(_dirs ${_oiio_target} INTERFACE_INCLUDE_DIRECTORIES)
    if(_dirs)
      list(FILTER _dirs EXCLUDE REGEX "opencv4")
      set_target_properties(${_oiio_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_dirs}")
    endif()
  endif()
endforeach()

# Debian's OpenColorIOConfig.cmake is broken; its pkg-config file is not.
find_package(PkgConfig REQUIRED)
pkg_check_modules(OCIO REQUIRED IMPORTED_TARGET OpenColorIO)
add_library(Penumbra::OpenColorIO ALIAS PkgConfig::OCIO)
# Draco, linked statically: Debian's libdraco.so exports its own copy of tinygltf, whose
# symbols would interpose on libtinygltf's; the decoder objects of libdraco.a use none of it.
find_path(DRACO_INCLUDE_DIR draco/compression/decode.h REQUIRED)
find_library(DRACO_STATIC_LIBRARY NAMES libdraco.a REQUIRED)
add_library(Penumbra::Draco STATIC IMPORTED)
set_target_properties(Penumbra::Draco PROPERTIES IMPORTED_LOCATION "${DRACO_STATIC_LIBRARY}"
                      INTERFACE_INCLUDE_DIRECTORIES "${DRACO_INCLUDE_DIR}")

if(PENUMBRA_BUILD_TESTS)
  find_package(Catch2 2 CONFIG REQUIRED)          # Catch2::Catch2 (v2, single header)
  find_package(Eigen3 3.3 CONFIG REQUIRED)        # Eigen3::Eigen (reference maths in tests)
endif()
