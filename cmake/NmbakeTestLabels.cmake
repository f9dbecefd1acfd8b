# Every ctest test carries one of three labels (docs/testing.md):
#   fast        the unit and known-answer tests and the commands' plain cases: what to run while
#               editing (`ctest -L fast`);
#   robustness  hostile inputs, faults, limits, signals, closed streams, thread identity, install;
#   viewer      what runs nmview or the viewer's code (llvmpipe: slow on the CPU).
# GoogleTest programs label their tests where they are discovered. nmbake_label_tests(), called at
# the end of each folder's CMakeLists.txt, labels that folder's other tests by name: one rule here,
# whichever folder adds a test. The test tests_labelled fails when a test has none.
function(nmbake_label_tests)
  get_property(names DIRECTORY PROPERTY TESTS)
  foreach(name ${names})
    get_test_property(${name} LABELS labels)
    if(labels)
      continue()
    endif()
    if(name MATCHES "^cli\\.nmview\\.")
      set(labels viewer)
    elseif(name MATCHES "hostile|assimp_malformed|fault_injection|disk_full|under_ulimit|beyond_memory_budget|signals|interrupt|output_contract|^cli\\.nmbake\\.outputs$|gltf_buffer|\\.numbers$|image_module|^install\\.|^threads\\.|^fuzz\\.")
      set(labels robustness)
    else()
      set(labels fast)
    endif()
    set_tests_properties(${name} PROPERTIES LABELS ${labels})
  endforeach()
endfunction()

# A GoogleTest program of its own (the viewer's): one ctest entry running all its tests
# (NMBAKE_TEST_PER_PROGRAM, one process start), or one per test. nmbake_gtest_program(TARGET
# TIMEOUT LABEL [COST N]).
function(nmbake_gtest_program target timeout label)
  cmake_parse_arguments(ARG "" "COST" "" ${ARGN})
  set(cost)
  if(ARG_COST)
    set(cost COST ${ARG_COST})
  endif()
  if(NMBAKE_TEST_PER_PROGRAM)
    add_test(NAME ${target} COMMAND ${target})
    set_tests_properties(${target} PROPERTIES TIMEOUT ${timeout} LABELS ${label} ${cost})
  else()
    gtest_discover_tests(${target} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT ${timeout} LABELS ${label} ${cost})
  endif()
endfunction()
