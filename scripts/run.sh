#!/usr/bin/env bash
# A new user's first command: install what is missing, build, and run the main job on its
# defaults (today the detection demo; output in out/demo/).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh
exec build/app/oalservo demo "$@"
