#!/usr/bin/env bash
# Soak: memory and file descriptors over long runs (docs/BENCHMARKS.md, "Soak"), on the Release
# build in build/:
#   1. the tracker + pose over FRAMES frames (default 100000): resident memory after the
#      warm-up (a tenth of the frames) against its maximum after it;
#   2. the serial port, then the controller simulator's pty, opened and closed OPENS times
#      (default 10000): open file descriptors before and after;
#   3. `oalservo evaluate` on a video of VIDEO_FRAMES frames (default 30000): its resident
#      memory sampled every half second, after the first fifth of its run against the maximum
#      after it (its statistics and plots fill their bounded buffers over the first 4096
#      frames, a fifth of the run at the default length).
# Exit 1 when memory grew by more than 1 MB after the warm-up or a descriptor leaked.
#   scripts/soak.sh                       # the figures
#   FRAMES=5000 OPENS=200 VIDEO_FRAMES=1000 scripts/soak.sh   # a quick look
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${FRAMES:-100000}
opens=${OPENS:-10000}
video_frames=${VIDEO_FRAMES:-30000}
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs" --target oal_soak oalservo
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
build/bench/oal_soak tracker --frames "$frames" || status=1
build/bench/oal_soak links --opens "$opens" || status=1
build/bench/oal_soak video --out "$work/video" --frames "$video_frames" >/dev/null

build/app/oalservo evaluate "$work/video/sweep.avi" --out "$work/eval" --no-video \
  >"$work/evaluate.log" 2>&1 &
pid=$!
samples=()
while kill -0 "$pid" 2>/dev/null; do
  rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
  [ -n "$rss" ] && samples+=("$rss")
  sleep 0.5
done
if ! wait "$pid"; then
  echo "soak.sh: oalservo evaluate failed:" >&2
  cat "$work/evaluate.log" >&2
  exit 1
fi
count=${#samples[@]}
if [ "$count" -lt 10 ]; then
  echo "evaluate: $video_frames frames in $count samples: too short a run to judge (more frames)"
  exit $status
fi
warm=${samples[$((count / 5))]}
max=$warm
for ((i = count / 5; i < count; ++i)); do
  [ "${samples[$i]}" -gt "$max" ] && max=${samples[$i]}
done
growth=$((max - warm))
verdict=flat
if [ "$growth" -gt 1024 ]; then verdict=GROWS; status=1; fi
echo "evaluate: $video_frames frames, $count samples every 0.5 s; resident $warm kB after the" \
  "first fifth, at most $max kB after, ${samples[$((count - 1))]} kB at the last sample:" \
  "growth $growth kB ($verdict, allowed 1024 kB)"
exit $status
