# `cmake --install BUILD [--prefix DIR]`: bin/nmbake, bin/nmdiff, bin/nmview (when the viewer is
# built), and the Python package nmbake in NMBAKE_PYTHON_INSTALL_DIR (when it is built: python/).
# Everything else is linked statically or is a Debian package, so the installed tree is
# relocatable.
include(GNUInstallDirs)

install(TARGETS nmbake nmdiff RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET nmview)
  install(TARGETS nmview RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
if(TARGET nmbake_python)
  install(TARGETS nmbake_python LIBRARY DESTINATION ${NMBAKE_PYTHON_INSTALL_DIR}/nmbake)
  install(FILES python/nmbake/__init__.py DESTINATION ${NMBAKE_PYTHON_INSTALL_DIR}/nmbake)
endif()
