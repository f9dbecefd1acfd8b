# `cmake --install BUILD [--prefix DIR]`: bin/nmbake, bin/nmdiff, bin/nmview (when the viewer is
# built). Everything else is linked statically or is a Debian package, so the installed tree is
# relocatable.
include(GNUInstallDirs)

install(TARGETS nmbake nmdiff RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET nmview)
  install(TARGETS nmview RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
