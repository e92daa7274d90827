#!/usr/bin/env bash
# The main job on the bundled default input: import the NeRF-synthetic chair (real Blender
# renders with poses, from ../shared/data) into a workspace and classify a few of its views
# with a real ImageNet model.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/setup.sh
shared="${VF_SHARED_DIR:-$(cd .. && pwd)/shared}"
ws="${1:-out/chair}"
rm -rf "$ws"
build/vfcapture ingest --transforms "$shared/data/nerf_synthetic/chair/transforms_train.json" -o "$ws"
build/vfcapture classify "$ws"/ingest/images/000{0,1,2,3}_*.png
build/vfcapture info "$ws"
