# `cmake --install BUILD [--prefix DIR]`: bin/nmbake, bin/nmdiff, bin/nmview (when the viewer is
# built), OpenImageIO's module LIBDIR/nmbake/libnmbake-oiio.so (baker/io/oiio_module.h), and the
# Python package nmbake in NMBAKE_PYTHON_INSTALL_DIR (when it is built: python/), with its own
# copy of the module beside the extension.
# Everything else is linked statically or is a Debian package, so the installed tree is
# relocatable.
include(GNUInstallDirs)

install(TARGETS nmbake nmdiff RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS nmbake_oiio_module LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/nmbake)
# The programs look for the module this far from their own folder (relative, so the installed tree
# stays relocatable); a program in the build tree also finds the build's module.
file(RELATIVE_PATH _nmbake_module_dir ${CMAKE_INSTALL_FULL_BINDIR} ${CMAKE_INSTALL_FULL_LIBDIR}/nmbake)
get_filename_component(_nmbake_build_root "${PROJECT_BINARY_DIR}" REALPATH)
target_compile_definitions(nmbake_io PRIVATE NMBAKE_OIIO_MODULE_DIR="${_nmbake_module_dir}"
                                             NMBAKE_BUILD_ROOT="${_nmbake_build_root}/")
if(TARGET nmview)
  install(TARGETS nmview RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
if(TARGET nmbake_python)
  install(TARGETS nmbake_python nmbake_oiio_module LIBRARY DESTINATION ${NMBAKE_PYTHON_INSTALL_DIR}/nmbake)
  install(FILES python/nmbake/__init__.py DESTINATION ${NMBAKE_PYTHON_INSTALL_DIR}/nmbake)
endif()
