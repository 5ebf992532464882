#!/usr/bin/env bash
# The full lens model's figures: for each lens of config/lenses (OpenCV's model), the pose of
# the A3 sheet on the evaluation bench over FRAMES rendered frames, posed with
#   - the true lens (the file itself),
#   - the camera `oalservo calibrate` fits from 20 rendered views of the sheet (VIEW_SEED),
#   - ViSP's one-term approximation of the true lens (`oalservo camera --out x.xml`),
# and ViSP's AprilTag on the same frames with the true lens. Prints a markdown table.
#   scripts/lens-figures.sh OUT [FRAMES] [POSE_SEED] [VIEW_SEED] [LENS...]
# e.g. scripts/lens-figures.sh out/lens 1000 5 21
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ]; then
  echo "usage: scripts/lens-figures.sh OUT [FRAMES] [POSE_SEED] [VIEW_SEED] [LENS...]" >&2
  exit 2
fi
out=$1 frames=${2:-1000} pose_seed=${3:-5} view_seed=${4:-21}
shift $(($# < 4 ? $# : 4))
lenses=("$@")
[ ${#lenses[@]} -eq 0 ] && lenses=(opencv-sample webcam-720p wide-100)
oal=build/app/oalservo
mkdir -p "$out"

# "found | wrong | translation median | rotation median" from pose-accuracy's table.
row() {
  awk -F'|' '
    /frames with a pose/ { split($3, a, " "); found = a[1] }
    /^\| wrong poses/ { wrong = $3 + 0 }
    /^\| translation error median/ { split($3, t, "/"); tr = t[1] + 0 }
    /^\| rotation error median/ { split($3, r, "/"); ro = r[1] + 0 }
    END { printf "%s | %d | %.3f %% | %.3f deg", found, wrong, tr, ro }'
}

echo "| lens | camera file the pose uses | poses of $frames | wrong | translation median | rotation median |"
echo "|---|---|---:|---:|---:|---:|"
for name in "${lenses[@]}"; do
  lens=config/lenses/$name.yaml
  views=$out/$name-views
  "$oal" render --camera "$lens" --count 20 --seed "$view_seed" --max-tilt-deg 45 --noise 3 \
    --blur 0.8 --max-offset 0.22 --min-distance 0.45 --max-distance 0.8 --out "$views" \
    --overwrite > /dev/null
  "$oal" calibrate "$views" --out "$out/$name-calibrated.yaml" > "$out/$name-calibrate.txt" 2>&1
  "$oal" camera "$lens" --out "$out/$name-one-term.xml" > /dev/null 2>&1
  accuracy=("$oal" pose-accuracy --camera "$lens" --frames "$frames" --seed "$pose_seed")
  echo "| $name | the true lens | $("${accuracy[@]}" 2>/dev/null | row) |"
  echo "| $name | calibrated from 20 views | $("${accuracy[@]}" --pose-camera \
    "$out/$name-calibrated.yaml" 2>/dev/null | row) |"
  echo "| $name | ViSP's one-term approximation | $("${accuracy[@]}" --pose-camera \
    "$out/$name-one-term.xml" 2>/dev/null | row) |"
  echo "| $name | AprilTag, the true lens | $("${accuracy[@]}" --marker apriltag 2>/dev/null | row) |"
done
