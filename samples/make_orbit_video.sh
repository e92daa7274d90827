#!/usr/bin/env bash
# Make a phone-style test video from a folder of orbit photos: the frames in name order, as
# H.264 in an MP4 whose frames are stored landscape with a rotation flag, as phones do.
# usage: samples/make_orbit_video.sh PHOTO_DIR OUT.mp4 [FPS]
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 PHOTO_DIR OUT.mp4 [FPS]" >&2
  exit 1
fi
dir=$1 out=$2 fps=${3:-5}
first=$(ls "$dir" | grep -iE '\.(jpe?g|png)$' | head -1)
if [ -z "$first" ]; then
  echo "$0: no JPEG or PNG photos in $dir" >&2
  exit 1
fi
ext=${first##*.}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# Store the frames turned a quarter counter-clockwise with a display matrix that turns them
# back clockwise (ffprobe: "rotation=-90"), as a phone held upright writes them. FFmpeg 5.1
# spells that matrix "rotate=270".
ffmpeg -loglevel error -y -framerate "$fps" -pattern_type glob -i "$dir/*.$ext" \
  -vf "transpose=2,scale=trunc(iw/2)*2:trunc(ih/2)*2" -c:v libx264 -pix_fmt yuv420p "$tmp/stored.mp4"
ffmpeg -loglevel error -y -i "$tmp/stored.mp4" -c copy -metadata:s:v:0 rotate=270 "$out"
echo "wrote $out"
