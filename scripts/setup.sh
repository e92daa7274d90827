#!/usr/bin/env bash
# Install what vfcapture needs (Debian 12 packages) and build it into build/.
# Installs only missing packages, so a second run does nothing but an incremental build.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake pkg-config
  colmap ffmpeg libavformat-dev libavcodec-dev libswscale-dev
  libopencv-dev libopenimageio-dev openimageio-tools libceres-dev libeigen3-dev
  libv4l-dev v4l-utils libjansson-dev libcairo2-dev libsqlite3-dev python3
  blender python3-numpy
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

build_dir="${VF_BUILD_DIR:-build}"
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$build_dir" -j"$(nproc)"
echo "setup: built $build_dir/vfcapture"
