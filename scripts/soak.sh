#!/usr/bin/env bash
# Soak: memory and file descriptors over long runs (docs/BENCHMARKS.md, "Soak"), on the Release
# build in build/:
#   1. the tracker + pose over FRAMES frames (default 100000): resident memory after the
#      warm-up (a tenth of the frames) against its maximum after it;
#   2. the serial port, then the controller simulator's pty, opened and closed OPENS times
#      (default 10000): open file descriptors before and after;
#   3. `oalservo evaluate` on a video of VIDEO_FRAMES frames (default 30000): its resident
#      memory sampled every half second, the median over the last fifth of its run against
#      the median over the second (its statistics and plots fill their bounded buffers over
#      the first 4096 frames, within the first fifth at the default length).
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
# Medians of the second fifth (warmed up) and of the last fifth: the decoder's and the writer's
# queues fill and drain by a few frames (a 640x480 frame is 300 kB), which a single sample
# would take for growth.
median_of() {  # FROM TO: the median of samples[FROM..TO)
  printf '%s\n' "${samples[@]:$1:$(($2 - $1))}" | sort -n | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'
}
warm=$(median_of $((count / 5)) $((2 * count / 5)))
last=$(median_of $((4 * count / 5)) "$count")
low=$warm high=$warm
for ((i = count / 5; i < count; ++i)); do
  [ "${samples[$i]}" -gt "$high" ] && high=${samples[$i]}
  [ "${samples[$i]}" -lt "$low" ] && low=${samples[$i]}
done
growth=$((last - warm))
verdict=flat
if [ "$growth" -gt 1024 ]; then verdict=GROWS; status=1; fi
echo "evaluate: $video_frames frames, $count samples every 0.5 s; resident median $warm kB over" \
  "the second fifth, $last kB over the last fifth: growth $growth kB ($verdict, allowed 1024" \
  "kB); samples after the first fifth between $low and $high kB"
exit $status
