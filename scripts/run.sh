#!/usr/bin/env bash
# A new user's first command: install what is missing, build, and run the main job on its
# defaults: the servo loop with the simulated robot and camera (config/servo-sim.yaml;
# output in out/servo/).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
exec build/app/oalservo servo "$@"
