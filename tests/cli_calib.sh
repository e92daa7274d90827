#!/usr/bin/env bash
# vfcapture calib from the command line: printable patterns, the clear errors of intrinsics
# and scale, and bad input that leaves a workspace as it was.
source "$(dirname "$0")/shell_checks.sh"

expect 0 "calib help" -- "$tool" calib --help
grep -q "usage: vfcapture calib" "$tmp/out" && ok || bad "calib --help prints its usage"
for sub in intrinsics scale board marker; do
  expect 0 "calib $sub --help" -- "$tool" calib "$sub" --help
  grep -q "usage: vfcapture calib $sub" "$tmp/out" && ok || bad "calib $sub --help"
done
expect 1 "unknown subcommand" -- "$tool" calib frobnicate
one_line_naming "unknown subcommand" "frobnicate"

# Printable board and marker.
expect 0 "board" -- "$tool" calib board --board 9x6 --square-px 20 -o "$tmp/board.png" --quiet
[ -s "$tmp/board.png" ] && ok || bad "board.png written"
expect 0 "charuco board" -- "$tool" calib board --board 7x5 --charuco --dict 4x4_50 -o "$tmp/charuco.png" --quiet
[ -s "$tmp/charuco.png" ] && ok || bad "charuco.png written"
expect 1 "unknown dictionary" -- "$tool" calib board --board 7x5 --charuco --dict 9x9_5 -o "$tmp/c.png"
one_line_naming "unknown dictionary" "9x9_5"
expect 0 "marker" -- "$tool" calib marker --id 5 -o "$tmp/marker.png" --json
json_check "marker --json names the file" 'd["output"].endswith("marker.png")'
expect 1 "marker id range" -- "$tool" calib marker --id 5000 -o "$tmp/m.png"
one_line_naming "marker id range" "--id"

# Intrinsics: bad board syntax; a folder with one view is too few boards.
mkdir -p "$tmp/views" && cp "$tmp/board.png" "$tmp/views/a.png"
expect 1 "bad board" -- "$tool" calib intrinsics "$tmp/views" --board 9by6 --square 25
one_line_naming "bad board" "COLSxROWS"
expect 1 "no square" -- "$tool" calib intrinsics "$tmp/views" --board 9x6
one_line_naming "no square" "--square"
expect 1 "too few boards" -- "$tool" calib intrinsics "$tmp/views" --board 9x6 --square 25 \
  -o "$tmp/cam.json" --quiet
one_line_naming "too few boards" "found in only 1 of 1 frames"
[ ! -e "$tmp/cam.json" ] && ok || bad "no camera file after a failure"
mkdir -p "$tmp/charuco_views" && cp "$tmp/charuco.png" "$tmp/charuco_views/a.png"
expect 1 "too few ChArUco boards" -- "$tool" calib intrinsics "$tmp/charuco_views" --board 7x5 \
  --square 40 --charuco 30 --dict 4x4_50 -o "$tmp/cam.json" --quiet
one_line_naming "too few ChArUco boards" "found in only 1 of 1 frames"
# A video: at most --frames frames spread over it (a still board, 30 frames: 4 searched, or 30).
ffmpeg -loglevel error -y -loop 1 -i "$tmp/board.png" -frames:v 30 -pix_fmt yuv420p \
  "$tmp/board.mp4" && ok || bad "ffmpeg made the board video"
expect 1 "video: --frames searched" -- "$tool" calib intrinsics "$tmp/board.mp4" --board 9x6 \
  --square 25 --frames 4 --quiet
one_line_naming "video: --frames searched" "found in only [0-9]* of 4 frames"
expect 1 "video shorter than --frames" -- "$tool" calib intrinsics "$tmp/board.mp4" --board 9x6 \
  --square 25 --frames 100 --min-views 40 --max-views 40 --quiet
one_line_naming "video shorter than --frames" "found in only [0-9]* of 30 frames"
expect 1 "marker larger than square" -- "$tool" calib intrinsics "$tmp/charuco_views" --board 7x5 \
  --square 40 --charuco 45
one_line_naming "marker larger than square" "--charuco"
expect 1 "missing input" -- "$tool" calib intrinsics "$tmp/nope.mp4" --board 9x6 --square 25
one_line_naming "missing input" "nope.mp4"

# Scale: option combinations, and a workspace without poses.
expect 1 "scale needs a method" -- "$tool" calib scale "$tmp/ws"
one_line_naming "scale needs a method" "--marker"
expect 1 "marker without size" -- "$tool" calib scale "$tmp/ws" --marker 3
one_line_naming "marker without size" "--marker-size"
expect 1 "distance needs three values" -- "$tool" calib scale "$tmp/ws" --distance 'a:1,2;b:3,4'
one_line_naming "distance needs three values" "three values"
ws="$tmp/ws"
expect 0 "ingest" -- "$tool" ingest --transforms "$shared/data/nerf_synthetic/chair/transforms_train.json" -o "$ws" --quiet
cp "$ws/manifest.json" "$tmp/manifest.before"
expect 1 "bad pick" -- "$tool" calib scale "$ws" --distance 'r_0:10;r_1:3,4' 'r_0:5,6;r_1:7,8' 100
one_line_naming "bad pick" "r_0:10"
expect 1 "unknown frame" -- "$tool" calib scale "$ws" --distance 'nope:1,2;r_1:3,4' 'r_0:5,6;r_1:7,8' 100
one_line_naming "unknown frame" "nope"
cmp -s "$ws/manifest.json" "$tmp/manifest.before" && ok || bad "failed scale runs left the manifest as it was"
[ ! -e "$ws/calib" ] && ok || bad "no calib folder after failures"
cli_finish
