#!/usr/bin/env bash
# Fuzzes each target of tests/fuzz with libFuzzer for SECONDS seconds (default 60) each:
# builds them with clang, ASan and UBSan under build-fuzz/ (-DOAL_FUZZ=ON), starts from the seed
# corpus in the repository (a working copy under build-fuzz/corpus/, so the repository's stays
# as committed) and its dictionary, and prints the executions and findings per target.
# Inputs that crash are kept in build-fuzz/findings/NAME/. Exit 1 when any target found one.
#   scripts/fuzz.sh 600                  # ten minutes each
#   scripts/fuzz.sh 60 acl_client_fuzz   # one target
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(acl_reply_fuzz acl_client_fuzz config_fuzz camera_file_fuzz truth_file_fuzz
           image_decode_fuzz detector_pose_fuzz)
fi
if ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: clang++ is needed (apt-get install clang)" >&2
  exit 1
fi
jobs=$(nproc 2>/dev/null || echo 2)
CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Fuzz -DCMAKE_CXX_FLAGS_FUZZ="-O1 -g1" \
  -DOAL_FUZZ=ON -DOAL_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j "$jobs" --target "${targets[@]}"
here=$(pwd)
export ASAN_OPTIONS="detect_leaks=1"
export LSAN_OPTIONS="suppressions=$here/scripts/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
summary=""
for target in "${targets[@]}"; do
  corpus=build-fuzz/corpus/$target
  findings=build-fuzz/findings/$target
  mkdir -p "$corpus" "$findings"
  cp -n tests/fuzz/corpus/"$target"/* "$corpus"/ 2>/dev/null || true
  # The target's own dictionary, else its family's (acl_reply_fuzz, acl_client_fuzz: acl.dict).
  dict=()
  for file in tests/fuzz/"$target".dict tests/fuzz/"${target%%_*}".dict; do
    if [ -f "$file" ]; then dict=(-dict="$file"); break; fi
  done
  log=build-fuzz/$target.log
  echo "fuzz.sh: $target for $seconds s" >&2
  if build-fuzz/tests/fuzz/"$target" "$corpus" "${dict[@]}" -max_total_time="$seconds" \
       -artifact_prefix="$findings/" -print_final_stats=1 >"$log" 2>&1; then
    result="no finding"
  else
    result="FINDING (see $log, $findings/)"
    status=1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
  summary+=$(printf '| %s | %s | %s s | %s |' "$target" "$runs" "$seconds" "$result")$'\n'
done
echo "| target | executions | time | result |"
echo "|---|---:|---:|---|"
printf '%s' "$summary"
exit $status
