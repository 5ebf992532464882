#!/usr/bin/env bash
# The tests that run threads, built with ThreadSanitizer under build-tsan/: evaluate's
# pipeline (--jobs), the stop signals and the servo loop's interruption, the Scorbot driver
# against the controller simulator on a pseudo-terminal (a thread serves the link), the fault
# campaign (runs in parallel, a timer thread injecting the faults). No
# recovery: the first race fails the test; third-party reports are suppressed, each with its
# reason, in scripts/sanitizers/tsan.supp. Extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -g1" \
  -DOAL_SANITIZE=thread -DOAL_BUILD_BENCH=OFF
cmake --build build-tsan -j "$jobs" --target app_tests robots_tests
here=$(pwd)
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$here/scripts/sanitizers/tsan.supp"
cd build-tsan
ctest --output-on-failure -j "$jobs" \
  -R 'Evaluate\.|EvaluateJobs|StopSignalScope|ServoCommand\.|ServoLoop\.Interrupt|ServoScorbot|ScorbotRobot|ScorbotControllerSim|AclClient|FaultCampaign' "$@"
