# `cmake --install BUILD [--prefix DIR]`: the commands and what they load at run time.
#   bin/nmbake, bin/nmdiff, bin/nmview (when the viewer is built)
#   lib/nmbake/libnmbake_oiio.so   nmbake's image module (OpenImageIO), loaded by the three commands
# (GNUInstallDirs names the folders: lib/<multiarch> when the prefix is /usr on Debian.) Everything
# else is linked statically or is a Debian package, so the installed tree is relocatable: each command
# looks for the module next to itself, then at NMBAKE_IMAGE_MODULE_DIR relative to
# its own folder (baker/io/image_io_loader.cpp).
include(GNUInstallDirs)

set(NMBAKE_INSTALL_MODULEDIR "${CMAKE_INSTALL_LIBDIR}/nmbake")
file(RELATIVE_PATH _nmbake_module_from_bin "${CMAKE_INSTALL_FULL_BINDIR}"
     "${CMAKE_INSTALL_FULL_LIBDIR}/nmbake")
target_compile_definitions(nmbake_imageio_loader PRIVATE NMBAKE_IMAGE_MODULE_DIR="${_nmbake_module_from_bin}")

install(TARGETS nmbake nmdiff RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS nmbake_oiio_module LIBRARY DESTINATION ${NMBAKE_INSTALL_MODULEDIR})
if(TARGET nmview)
  install(TARGETS nmview RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
