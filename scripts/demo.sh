#!/usr/bin/env bash
# The main job on the bundled default input: the whole pipeline (ingest, COLMAP poses, radiance
# field, ViewFool attack with the paper's budget, export of target shots) on the 27 real photos
# of a spray can in ../shared/data (background removed), attacked with MobileNetV2 as "hair
# spray". About 6 minutes on 2 cores; a second run finds every stage up to date and only prints
# the summary.
# usage: scripts/demo.sh [WORKSPACE]   (default out/spray)
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
shared="${VF_SHARED_DIR:-$(cd .. && pwd)/shared}"
build/vfcapture run "$shared/data/real_captures/spray_can_photoroom/images" \
  -o "${1:-out/spray}" --label "hair spray"
