# Warnings as one INTERFACE target that every project target links.
add_library(nmbake_warnings INTERFACE)
add_library(nmbake::warnings ALIAS nmbake_warnings)
target_compile_options(nmbake_warnings INTERFACE -Wall -Wextra -Wshadow -Wconversion -Wno-sign-conversion)
if(NMBAKE_WERROR)
  target_compile_options(nmbake_warnings INTERFACE -Werror)
endif()
