#!/usr/bin/env bash
# The main job on the bundled default input: the whole pipeline on a textured 3D model of a
# water bottle from ../shared/data/models_3d (CC0), so every number it prints can be checked
# against the object itself. Blender renders the paper's capture (100 views on the upper
# hemisphere, 25 held out), the radiance field trains for 3 minutes (a 3D model's default is 5:
# the demo keeps to the time it was measured with), ViewFool attacks it with
# the paper's budget (50 samples x 100 steps) against MobileNetV2 as "water bottle", `real`
# renders the model itself at v*, at the 100 samples of p*(v) and at natural views (the
# paper's Real(v*) and Real(p*(v))), and export writes the target shots. About 6 minutes on 2
# cores; a second run finds every stage up to date and only prints the summary.
#
# Why this object: MobileNetV2 names it at 84% of natural views of the model (68% of the
# field's renders), where the former default (27 photos of a spray can) was read as "hair
# spray" at 33% of the field's renders, too few for an attack's success to mean much.
# usage: scripts/demo.sh [WORKSPACE]   (default out/bottle)
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
shared="${VF_SHARED_DIR:-$(cd .. && pwd)/shared}"
build/vfcapture run "$shared/data/models_3d/water_bottle__WaterBottle.glb" \
  -o "${1:-out/bottle}" --label "water bottle" --minutes 3
