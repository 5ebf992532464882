#!/usr/bin/env bash
# The lens check's figures on one rendered set: renders FRAMES frames of the target through a
# lens of kdu LENS_KDU, writes copies of the set's camera.xml that miss the lens (kdu off by
# -0.1 and +0.1, and one without distortion), runs `oalservo pose --independent` with the
# right file and with each wrong one, and prints a markdown row per camera file: frames with a
# pose, frames whose lines contradict the file, the median bend (straightness_px) and the
# median kdu error the lines tell. Extra arguments go to `oalservo render`.
#   scripts/lens-check.sh OUT SEED LENS_KDU [FRAMES] [render options...]
# e.g. scripts/lens-check.sh out/lens/a3 91 0.15 200 --config config/servo-sim.yaml \
#        --noise 4 --blur 1 --gradient 0.2 --min-distance 0.3 --max-distance 0.85
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 3 ]; then
  echo "usage: scripts/lens-check.sh OUT SEED LENS_KDU [FRAMES] [render options...]" >&2
  exit 2
fi
out=$1 seed=$2 lens=$3
frames=${4:-200}
shift $(($# < 4 ? $# : 4))
oal=build/app/oalservo
mkdir -p "$out"
"$oal" render --count "$frames" --seed "$seed" --kdu "$lens" --out "$out/data" --overwrite "$@" \
  > /dev/null
right="$out/data/camera.xml"
shifted() { awk -v a="$lens" -v d="$1" 'BEGIN { printf "%.4f", a + d }'; }
sed "s#<kdu>.*</kdu>#<kdu>$(shifted -0.1)</kdu>#" "$right" > "$out/kdu-minus-0.1.xml"
sed "s#<kdu>.*</kdu>#<kdu>$(shifted 0.1)</kdu>#" "$right" > "$out/kdu-plus-0.1.xml"
sed -e "s#<kdu>.*</kdu>#<kdu>0</kdu>#" -e "s#<kud>.*</kud>#<kud>0</kud>#" "$right" \
  > "$out/no-distortion.xml"

# The median of the numbers on stdin ("-" when none).
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR == 0) print "-";
  else printf "%.3f", NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

echo "| camera file | pose | contradicting | median bend, px | median kdu error |"
echo "|---|---:|---:|---:|---:|"
for camera in "$right" "$out/kdu-minus-0.1.xml" "$out/kdu-plus-0.1.xml" "$out/no-distortion.xml"; do
  # Through a lens without distortion the right file is the one without distortion.
  if [ "$camera" = "$out/no-distortion.xml" ] && [ "$(shifted 0)" = 0.0000 ]; then continue; fi
  name=$(basename "$camera" .xml)
  [ "$camera" = "$right" ] && name="right (kdu $lens)"
  poses="$out/$(basename "$camera" .xml).jsonl"
  "$oal" pose "$out/data" --independent --camera "$camera" --out "$poses" 2> /dev/null
  ok=$(grep -c '"status":"ok"' "$poses" || true)
  contradicting=$(grep -c '"contradicts_camera":true' "$poses" || true)
  bend=$(grep -o '"straightness_px":[-0-9.e]*' "$poses" | cut -d: -f2 | median)
  error=$(grep -o '"kdu_error":[-0-9.e]*' "$poses" | cut -d: -f2 | median)
  echo "| $name | $ok / $frames | $contradicting | $bend | $error |"
done
