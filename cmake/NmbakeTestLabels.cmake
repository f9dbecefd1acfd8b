# Every ctest test carries one of three labels (docs/testing.md):
#   fast        the unit and known-answer tests and the commands' plain cases: what to run while
#               editing (`ctest -L fast`);
#   robustness  hostile inputs, faults, limits, signals, closed streams, thread identity, install;
#   viewer      what runs nmview or the viewer's code (llvmpipe: slow on the CPU);
#   integration where others call nmbake: the Python module, the Blender add-on, a Slurm array job
#               (python.*, blender.*, slurm.*; never under the sanitizers).
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
    elseif(name MATCHES "^(python|blender|slurm)\\.")
      set(labels integration)
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

# The tests of each file in `files` (test_*.cpp, compiled into the GoogleTest program `target`)
# registered with ctest under the label `label`, or `robustness` for the files named in
# ROBUSTNESS: one entry per file named after it, running a --gtest_filter of the TEST names the
# file holds (NMBAKE_TEST_PER_PROGRAM: one process start per file), or one entry per test.
# BATCH n: up to n files of one label in one entry (one process start for them all; under ASan a
# start costs ~0.45 s of CPU, most of a small file's run), named after its files joined by "+", so
# `ctest -R test_bake` still finds the file's entry. A file with ENVIRONMENT_OF keeps an entry of
# its own. A TEST(...) must sit on one line for its name to be read. ENVIRONMENT_OF file
# "VAR=value" pairs add an ENVIRONMENT_MODIFICATION to that file's tests.
# nmbake_test_files(TARGET LABEL TIMEOUT FILES f... [BATCH n] [ROBUSTNESS f...] [ENVIRONMENT_OF f op...])
function(nmbake_test_files target label timeout)
  cmake_parse_arguments(ARG "" "BATCH" "FILES;ROBUSTNESS;ENVIRONMENT_OF" ${ARGN})
  set(env_file)
  set(env_ops)
  if(ARG_ENVIRONMENT_OF)
    list(POP_FRONT ARG_ENVIRONMENT_OF env_file)
    set(env_ops ${ARG_ENVIRONMENT_OF})
  endif()
  set(batch 1)
  if(ARG_BATCH AND NMBAKE_TEST_PER_PROGRAM)
    set(batch ${ARG_BATCH})
  endif()
  set(pending_fast)
  set(pending_robustness)
  foreach(src ${ARG_FILES})
    get_filename_component(name ${src} NAME_WE)
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${src})  # its TEST names make the filter
    file(STRINGS ${src} lines REGEX "^(TEST|TEST_F|TEST_P)\\(")
    set(filter)
    foreach(line ${lines})
      string(REGEX REPLACE "^TEST(_F|_P)?\\(([A-Za-z0-9_]+), *([A-Za-z0-9_]+).*" "\\2.\\3" test "${line}")
      if(line MATCHES "^TEST_P")
        set(test "*/${test}/*")  # INSTANTIATE_TEST_SUITE_P names them Prefix/Suite.Name/Param
      endif()
      if(NOT test MATCHES "^[A-Za-z0-9_*/]+\\.[A-Za-z0-9_*/]+$")
        message(FATAL_ERROR "${src}: cannot read the test's name from: ${line}")
      endif()
      list(APPEND filter ${test})
    endforeach()
    if(NOT filter)
      message(FATAL_ERROR "${src}: no TEST found")
    endif()
    string(REPLACE ";" ":" filter "${filter}")
    set(file_label ${label})
    if(name IN_LIST ARG_ROBUSTNESS)
      set(file_label robustness)
    endif()
    set(environment)
    if(name STREQUAL env_file)
      set(environment ENVIRONMENT_MODIFICATION ${env_ops})
    endif()
    if(NOT NMBAKE_TEST_PER_PROGRAM)
      gtest_discover_tests(${target} TEST_FILTER ${filter} DISCOVERY_TIMEOUT 60 NO_PRETTY_VALUES
                           PROPERTIES TIMEOUT ${timeout} LABELS ${file_label} ${environment})
    elseif(name STREQUAL env_file OR batch EQUAL 1)
      _nmbake_test_entry(${target} ${file_label} ${timeout} "${name}" "${filter}" ${environment})
    else()
      set(kind fast)
      if(file_label STREQUAL "robustness")
        set(kind robustness)
      endif()
      list(APPEND pending_${kind} "${name}=${filter}")
      list(LENGTH pending_${kind} count)
      if(count EQUAL batch)
        _nmbake_test_batch(${target} ${file_label} ${timeout} pending_${kind})
        set(pending_${kind})
      endif()
    endif()
  endforeach()
  if(pending_fast)
    _nmbake_test_batch(${target} ${label} ${timeout} pending_fast)
  endif()
  if(pending_robustness)
    _nmbake_test_batch(${target} robustness ${timeout} pending_robustness)
  endif()
endfunction()

# One ctest entry NAME running `target --gtest_filter=FILTER`.
function(_nmbake_test_entry target label timeout name filter)
  add_test(NAME ${name} COMMAND ${target} --gtest_filter=${filter})
  set_tests_properties(${name} PROPERTIES TIMEOUT ${timeout} LABELS ${label} ${ARGN})
endfunction()

# One ctest entry for the files in the list variable `var` (items "name=filter").
function(_nmbake_test_batch target label timeout var)
  set(names)
  set(filters)
  foreach(item IN LISTS ${var})
    string(FIND "${item}" "=" at)
    string(SUBSTRING "${item}" 0 ${at} name)
    math(EXPR from "${at} + 1")
    string(SUBSTRING "${item}" ${from} -1 filter)
    list(APPEND names ${name})
    list(APPEND filters ${filter})
  endforeach()
  string(REPLACE ";" "+" name "${names}")
  string(REPLACE ";" ":" filter "${filters}")
  _nmbake_test_entry(${target} ${label} ${timeout} "${name}" "${filter}")
endfunction()
