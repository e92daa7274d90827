#!/usr/bin/env bash
# The main job on the bundled default input: the whole pipeline (import, radiance field,
# ViewFool attack with the paper's budget, export of target shots) on the NeRF-synthetic chair
# from ../shared/data, attacked with MobileNetV2 as a folding/rocking chair. About 12 minutes on
# 2 cores; a second run finds every stage up to date and only prints the summary.
# usage: scripts/demo.sh [WORKSPACE]   (default out/chair)
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
shared="${VF_SHARED_DIR:-$(cd .. && pwd)/shared}"
build/vfcapture run "$shared/data/nerf_synthetic/chair/transforms_train.json" \
  -o "${1:-out/chair}" --label "folding chair,rocking chair"
