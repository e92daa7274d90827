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
  blender python3-numpy python3-onnx
  snakemake slurm-wlm munge bc  # studies (workflow/): Snakemake, and Slurm for the cluster test
)
# Node.js runs the ONNX Runtime worker; keep an installed node (and its npm) if there is one.
command -v node >/dev/null || packages+=(nodejs)
command -v npm >/dev/null || packages+=(npm)

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

# ONNX Runtime, the default classifier engine. Debian has no package; npm's onnxruntime-node
# carries the prebuilt CPU runtime for Linux x64. --ignore-scripts: its install script would try
# to download a CUDA add-on. Installed once per user, where vfcapture looks for it.
ort_version=1.30.0
data_home="${XDG_DATA_HOME:-$HOME/.local/share}"
[ "${data_home#/}" != "$data_home" ] || data_home="$HOME/.local/share"
ort_dir="${VF_ONNXRUNTIME_DIR:-$data_home/vfcapture/onnxruntime}"
if ! grep -qs "\"version\": \"$ort_version\"" "$ort_dir/node_modules/onnxruntime-node/package.json"; then
  echo "setup: installing onnxruntime-node $ort_version into $ort_dir"
  mkdir -p "$ort_dir"
  npm install --prefix "$ort_dir" --ignore-scripts --no-audit --no-fund --loglevel=error \
    "onnxruntime-node@$ort_version" >/dev/null ||
    echo "setup: warning: ONNX Runtime could not be installed; vfcapture falls back to OpenCV's engine" >&2
fi

build_dir="${VF_BUILD_DIR:-build}"
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$build_dir" -j"$(nproc)"
echo "setup: built $build_dir/vfcapture"
