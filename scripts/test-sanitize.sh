#!/usr/bin/env bash
# The sanitizer configuration: builds nmbake and its tests with AddressSanitizer and
# UndefinedBehaviorSanitizer (NMBAKE_SANITIZE, gcc) in build-asan/ (-O1 -g1: line tables, so the
# reports name file and line, at a quarter less compile time than -g and half the object size;
# asserts on, no bench, no viewer) and runs the whole test suite there with ctest, one process per
# batch of test files (NMBAKE_TEST_PER_PROGRAM, NMBAKE_TEST_BATCH: an ASan process start costs
# ~0.45 s CPU, and ~190 of them were a third of the run). Any ASan/UBSan report fails the test that triggered it; LeakSanitizer ignores only
# the known leaks listed in tests/sanitize/lsan.supp.
# The viewer is off here (not tried under ASan): its tests draw through Mesa's llvmpipe via EGL and
# GLFW, uninstrumented driver code that is slow on the CPU already and whose allocations would
# need suppressions of libraries we do not own; the viewer reads meshes and maps through the same
# mesh_io/image_io that this run covers.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${NMBAKE_ASAN_BUILD_DIR:-$root/build-asan}
jobs=$(nproc 2>/dev/null || echo 2)
# Also in force while building: gtest_discover_tests runs the test programs to list their tests.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/tests/sanitize/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DNMBAKE_SANITIZE=ON -DNMBAKE_VIEWER=OFF -DNMBAKE_BENCH=OFF -DNMBAKE_TESTS=ON -DNMBAKE_TEST_PER_PROGRAM=ON >/dev/null
cmake --build "$build" -j "$jobs"
cd "$build"
ctest --output-on-failure -j "$jobs" --timeout 900
