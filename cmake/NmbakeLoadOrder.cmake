# The dynamic loader's share of loading OpenImageIO: which libraries it searches first. Only
# libnmbake-oiio.so links it (baker/io/oiio_module.h); the rule is the same for a module dlopen
# loads as for a program, its own libraries searched in its DT_NEEDED order after the program's.
#
# OpenImageIO loads ~260 shared libraries (OpenVDB, GDAL through OpenCV, DCMTK, ...), most linked
# with BIND_NOW, so each start of a program that links it resolves ~157,000 symbols before main.
# The loader looks each symbol up library by library in load order (breadth first from the
# program's DT_NEEDED), and the libraries that define most of them (OpenVDB binds ~57,000, nearly
# all its own) sit about a hundred libraries deep. Naming the NMBAKE_LOAD_ORDER_COUNT libraries
# with the most symbol relocations first in the program's DT_NEEDED moves them to the front of
# that search; what is loaded and which definition wins for the program's own symbols do not
# change (the C and C++ runtimes keep their place). Measured here: `nmbake --version` 0.34 -> 0.20 s
# of CPU. The list is computed at configure time from the libraries installed (cmake/load_order.sh,
# ldd and readelf), kept in the cache; NMBAKE_LOAD_ORDER=OFF leaves the linker's order alone.
option(NMBAKE_LOAD_ORDER "List the libraries with the most symbol relocations first (faster process start)" ON)
set(NMBAKE_LOAD_ORDER_COUNT 12 CACHE STRING "How many libraries nmbake_load_order names first")

# nmbake_load_order(TARGET LIBRARY): every program or module linking TARGET (an INTERFACE library) names,
# first, the heaviest libraries that LIBRARY (a shared library's path) loads.
function(nmbake_load_order target library)
  if(NOT NMBAKE_LOAD_ORDER OR NOT EXISTS "${library}" OR NOT CMAKE_SYSTEM_NAME STREQUAL "Linux")
    return()
  endif()
  if(NOT "${NMBAKE_LOAD_ORDER_FOR}" STREQUAL "${library};${NMBAKE_LOAD_ORDER_COUNT}")
    execute_process(COMMAND sh "${CMAKE_CURRENT_FUNCTION_LIST_DIR}/load_order.sh" "${library}" "${NMBAKE_LOAD_ORDER_COUNT}"
                    OUTPUT_VARIABLE libs RESULT_VARIABLE code ERROR_QUIET)
    string(REGEX REPLACE "\n+$" "" libs "${libs}")
    string(REPLACE "\n" ";" libs "${libs}")
    if(NOT code EQUAL 0)
      set(libs "")
    endif()
    set(NMBAKE_LOAD_ORDER_LIBS "${libs}" CACHE INTERNAL "")
    set(NMBAKE_LOAD_ORDER_FOR "${library};${NMBAKE_LOAD_ORDER_COUNT}" CACHE INTERNAL "")
  endif()
  if(NMBAKE_LOAD_ORDER_LIBS)
    list(JOIN NMBAKE_LOAD_ORDER_LIBS " " joined)
    target_link_options(${target} INTERFACE "SHELL:-Wl,--push-state,--no-as-needed ${joined} -Wl,--pop-state")
    list(LENGTH NMBAKE_LOAD_ORDER_LIBS n)
    message(STATUS "nmbake: ${n} libraries named first at link (NMBAKE_LOAD_ORDER)")
  endif()
endfunction()
