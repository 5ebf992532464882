#!/usr/bin/env bash
# The whole test suite built with AddressSanitizer + UndefinedBehaviorSanitizer (GCC), no
# recovery, leaks checked: under build-asan/, beside the Release build. Third-party leaks are
# suppressed by scripts/sanitizers/lsan.supp, each entry with its reason. CI runs it after
# scripts/test.sh (which installs the packages). Extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)
# Line tables: the reports name file and line. -O0 for the app and the tests (half the build
# time of -O1); the libraries keep -O1 (OAL_SANITIZE_HOT_FLAGS), the suite's running time.
# Each test executable runs as four shards, not a process per case (tests/CMakeLists.txt:
# OAL_TEST_SHARDS): a process's start and end under the sanitizers cost half a second.
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O0 -g1" \
  -DOAL_SANITIZE=address,undefined -DOAL_BUILD_BENCH=OFF -DOAL_TEST_SHARDS=4
cmake --build build-asan -j "$jobs"
here=$(pwd)
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_init_order=1:detect_stack_use_after_return=1"
export LSAN_OPTIONS="suppressions=$here/scripts/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$here/scripts/sanitizers/ubsan.supp"
cd build-asan
ctest --output-on-failure -j "$jobs" "$@"
