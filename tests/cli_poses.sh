#!/usr/bin/env bash
# `vfcapture poses` bad input as a user meets it: each mistake ends with one line naming it,
# exit 1, and the workspace exactly as it was (no COLMAP run needed: these are caught first).
# The expensive failures (a video COLMAP cannot register) are in test_data_poses_video.c.
source "$(dirname "$0")/shell_checks.sh"

spray="$shared/data/real_captures/spray_can_photoroom/images"
export TMPDIR="$tmp" # where a failed run keeps COLMAP's log
snapshot() { (cd "$ws" && find . -type f | sort | xargs md5sum) >"$tmp/$1"; }

expect 0 "poses --help" -- "$tool" poses --help
grep -q "usage: vfcapture poses" "$tmp/out" && ok || bad "poses --help prints its usage"
expect 1 "no workspace given" -- "$tool" poses
one_line_naming "no workspace given" "give one workspace folder"
expect 1 "missing workspace" -- "$tool" poses "$tmp/nowhere"
one_line_naming "missing workspace" "nowhere"

# A workspace with two photos: too few for structure from motion.
ws="$tmp/ws"
mkdir -p "$tmp/two" && cp "$spray"/Photoroom-20240806_225723_1{,0}.png "$tmp/two/"
expect 0 "ingest two photos" -- "$tool" ingest "$tmp/two" -o "$ws" --quiet
snapshot before
expect 1 "two frames" -- "$tool" poses "$ws" --quiet
one_line_naming "two frames" "only 2 frames"

# Options checked before anything runs.
expect 1 "bad matcher" -- "$tool" poses "$ws" --matcher fast
one_line_naming "bad matcher" "--matcher"
expect 1 "bad overlap" -- "$tool" poses "$ws" --overlap 0
one_line_naming "bad overlap" "--overlap"
expect 1 "bad camera model" -- "$tool" poses "$ws" --camera-model FISHEYE
one_line_naming "bad camera model" "--camera-model"
expect 1 "bad intrinsics" -- "$tool" poses "$ws" --intrinsics 700,700
one_line_naming "bad intrinsics" "--intrinsics"
expect 1 "missing camera file" -- "$tool" poses "$ws" --camera "$tmp/lens.json"
one_line_naming "missing camera file" "lens.json"
echo '{"fl_x": 800, "fl_y": 800, "cx": 500}' >"$tmp/half.json"
expect 1 "incomplete camera file" -- "$tool" poses "$ws" --camera "$tmp/half.json"
one_line_naming "incomplete camera file" "need fl_x, fl_y, cx, cy, w and h"
echo '{"fl_x": 800, "fl_y": 800, "cx": 500, "cy": 500, "w": 1000, "h": 1000}' >"$tmp/square.json"
expect 1 "known camera and a model" -- \
  "$tool" poses "$ws" --camera "$tmp/square.json" --camera-model OPENCV
one_line_naming "known camera and a model" "drop --camera-model"
expect 1 "bad min-registered" -- "$tool" poses "$ws" --min-registered 2
one_line_naming "bad min-registered" "--min-registered"
snapshot after
cmp -s "$tmp/before" "$tmp/after" && ok || bad "failed poses left the workspace as it was"

# A calibration for square images does not fit 750x1000 frames (found before COLMAP runs).
cp "$spray"/Photoroom-20240806_225723_11.png "$tmp/two/"
expect 0 "ingest three photos" -- "$tool" ingest "$tmp/two" -o "$ws" --quiet
snapshot before
expect 1 "camera of another aspect" -- "$tool" poses "$ws" --camera "$tmp/square.json" --quiet
one_line_naming "camera of another aspect" "another aspect ratio or orientation"
snapshot after
cmp -s "$tmp/before" "$tmp/after" && ok || bad "failed poses left the workspace as it was"
ls -a "$ws" | grep -q partial && bad "no staging folder left behind" || ok
[ ! -e "$ws/poses" ] && ok || bad "no poses folder made"

cli_finish
