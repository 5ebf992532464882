#!/usr/bin/env bash
# The tracker comparison: renders the six tracking sequences on the 2 m four-line board (the
# target they are made for; render's default is the A3 sheet) and ViSP's real line/
# sequence's reference, runs `oalservo compare` on each and gathers the tables in out/compare/.
#   scripts/compare-sequences.sh [FRAMES] [SEED]
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-60}
seed=${2:-1}
oal=build/app/oalservo
out=out/compare
mkdir -p "$out"
summary="$out/summary.md"
: > "$summary.tmp"
for kind in slow fast occlusion illumination leave-reenter distortion; do
  "$oal" render --sequence "$kind" --target four-line-board --count "$frames" --seed "$seed" \
    --out "$out/$kind/frames" --overwrite > /dev/null
  camera=()
  [ "$kind" = distortion ] && camera=(--camera "$out/$kind/frames/camera.xml")
  "$oal" compare "$out/$kind/frames" "${camera[@]}" --out "$out/$kind" > /dev/null
  { echo "### $kind ($frames frames, seed $seed)"; echo; cat "$out/$kind/compare.md"; echo; } >> "$summary.tmp"
done
line=/usr/share/visp-images-data/ViSP-images/line/image.%04d.pgm
"$oal" edge-reference "$line" --out "$out/line-truth.csv" > /dev/null
"$oal" compare "$line" --truth "$out/line-truth.csv" --config config/visp_line_edges.yaml \
  --out "$out/line" > /dev/null
{ echo "### ViSP line/ (33 real frames, edge reference)"; echo; cat "$out/line/compare.md"; } >> "$summary.tmp"
mv "$summary.tmp" "$summary"
echo "wrote $summary"
