# Every dependency is a Debian 12 package; scripts/setup.sh installs them.
macro(nmbake_require _pkg _deb)
  find_package(${_pkg} ${ARGN} QUIET)
  if(NOT ${_pkg}_FOUND)
    message(FATAL_ERROR "nmbake: ${_pkg} not found. Install the Debian package '${_deb}' (scripts/setup.sh does this).")
  endif()
endmacro()

nmbake_require(embree libembree-dev 3.13)
nmbake_require(assimp libassimp-dev 5.2)
# Debian's OpenImageIOConfig.cmake names /usr/include/opencv4 as an include folder even when
# OpenCV is not installed, which breaks every target linking it; use its pkg-config file instead.
find_package(PkgConfig REQUIRED)
pkg_check_modules(OIIO QUIET IMPORTED_TARGET OpenImageIO)
if(NOT OIIO_FOUND)
  message(FATAL_ERROR "nmbake: OpenImageIO not found. Install the Debian package 'libopenimageio-dev' (scripts/setup.sh does this).")
endif()
add_library(nmbake_oiio INTERFACE)
add_library(nmbake::oiio ALIAS nmbake_oiio)
target_link_libraries(nmbake_oiio INTERFACE PkgConfig::OIIO)
# OpenImageIO's libraries are most of every start's dynamic linking: the heaviest go first.
include(${CMAKE_CURRENT_LIST_DIR}/NmbakeLoadOrder.cmake)
set(_nmbake_oiio_lib "${OIIO_LINK_LIBRARIES}")
list(FILTER _nmbake_oiio_lib INCLUDE REGEX "/libOpenImageIO\\.so")
if(_nmbake_oiio_lib)
  list(GET _nmbake_oiio_lib 0 _nmbake_oiio_lib)
  nmbake_load_order(nmbake_oiio "${_nmbake_oiio_lib}")
endif()
# libpng: the bench's and tests' reference PNG encoder (bench/png_libpng.cpp).
nmbake_require(PNG libpng-dev)
# zlib compresses PNG's bands on several threads (baker/io/png_write.cpp).
nmbake_require(ZLIB zlib1g-dev)
nmbake_require(glm libglm-dev)
nmbake_require(nlohmann_json nlohmann-json3-dev)
nmbake_require(CLI11 libcli11-dev)
find_package(Threads REQUIRED)
