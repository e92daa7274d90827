#!/usr/bin/env bash
# `vfcapture ingest` from a video, a photo folder and a webcam, as a user meets it: the JSON
# summary, the stage's shape (images/ and report.json, no transforms.json), and bad input
# (not a video, an empty video, an empty folder, a missing or unsuitable camera) failing
# with one line, exit 1, and the earlier workspace untouched.
source "$(dirname "$0")/shell_checks.sh"

fox="$shared/data/real_captures/instant_ngp_fox/images"
spray="$shared/data/real_captures/spray_can_photoroom/images"

# A phone-style video: portrait frames stored sideways with a "turn 90 clockwise" flag
# (FFmpeg 5.1 writes the rotate tag counter-clockwise, hence 270).
ffmpeg -loglevel error -y -framerate 10 -pattern_type glob -i "$fox/*.jpg" -vf transpose=cclock \
  -c:v libx264 -preset ultrafast -crf 18 -pix_fmt yuv420p "$tmp/sideways.mp4" &&
  ffmpeg -loglevel error -y -i "$tmp/sideways.mp4" -c copy -metadata:s:v:0 rotate=270 "$tmp/fox.mp4" \
  && ok || bad "ffmpeg made the test video"

ws="$tmp/ws"
expect 0 "ingest a video" -- "$tool" ingest "$tmp/fox.mp4" -o "$ws" --frames 10 --json --quiet
json_check "video summary" 'd["source"]=="video" and d["frames"]==10 and d["frames_read"]==50 and d["rotation"]==90 and (d["width"],d["height"])==(540,960)'
[ ! -s "$tmp/err" ] && ok || bad "--quiet prints nothing on stderr: $(cat "$tmp/err")"
[ "$(ls "$ws/ingest/images" | grep -c '\.jpg$')" -eq 10 ] && ok || bad "10 frames written"
[ -f "$ws/ingest/report.json" ] && ok || bad "report.json written"
[ ! -e "$ws/ingest/transforms.json" ] && ok || bad "no transforms.json for an unposed capture"
cp "$ws/ingest/report.json" "$tmp/before.json"
ls "$ws/ingest/images" >"$tmp/before.list"

# Progress and a plain-text result without --json.
expect 0 "ingest, talking" -- "$tool" ingest "$tmp/fox.mp4" -o "$tmp/ws_talk" --frames 10
grep -q "scoring frames" "$tmp/err" && ok || bad "progress while decoding: $(cat "$tmp/err")"
grep -q "kept 10 of 50 frames" "$tmp/out" && ok || bad "result line: $(cat "$tmp/out")"

# Bad input: one line naming the input, exit 1, the workspace as it was.
echo "this is not a video" >"$tmp/notes.mp4"
expect 1 "text file named .mp4" -- "$tool" ingest "$tmp/notes.mp4" -o "$ws"
one_line_naming "text file named .mp4" "notes.mp4"
: >"$tmp/empty.mp4"
expect 1 "0-byte video" -- "$tool" ingest "$tmp/empty.mp4" -o "$ws"
one_line_naming "0-byte video" "empty.mp4"
ffmpeg -loglevel error -y -f lavfi -i color=s=64x64:d=1 -frames:v 0 -c:v libx264 "$tmp/zero.mp4"
expect 1 "video with no frames" -- "$tool" ingest "$tmp/zero.mp4" -o "$ws"
one_line_naming "video with no frames" "zero.mp4"
mkdir -p "$tmp/nophotos" && echo "notes" >"$tmp/nophotos/readme.txt"
expect 1 "folder without photos" -- "$tool" ingest "$tmp/nophotos" -o "$ws"
one_line_naming "folder without photos" "has no JPEG or PNG photos"
expect 1 "missing input" -- "$tool" ingest "$tmp/nope.mov" -o "$ws"
one_line_naming "missing input" "nope.mov: no such file"
expect 1 "missing camera" -- "$tool" ingest --v4l2 /dev/video-none-42 -o "$ws"
one_line_naming "missing camera" "/dev/video-none-42 does not exist"
expect 1 "not a camera" -- "$tool" ingest --v4l2 /dev/null -o "$ws"
one_line_naming "not a camera" "/dev/null is not a V4L2 camera"
expect 1 "two sources" -- "$tool" ingest "$tmp/fox.mp4" --v4l2 /dev/video0 -o "$ws"
one_line_naming "two sources" "give one source"
expect 1 "bad --frames" -- "$tool" ingest "$tmp/fox.mp4" -o "$ws" --frames 0
one_line_naming "bad --frames" "--frames"
expect 1 "bad --size" -- "$tool" ingest --v4l2 /dev/video0 -o "$ws" --size 640
one_line_naming "bad --size" "--size"
cmp -s "$ws/ingest/report.json" "$tmp/before.json" && ok || bad "failed ingests left the report as it was"
ls "$ws/ingest/images" | cmp -s - "$tmp/before.list" && ok || bad "failed ingests left the frames as they were"
ls -a "$ws" | grep -q partial && bad "no staging folder left behind" || ok

# A failed ingest into a new folder leaves no workspace behind.
expect 1 "failure into a new workspace" -- "$tool" ingest "$tmp/notes.mp4" -o "$tmp/fresh"
[ ! -e "$tmp/fresh" ] && ok || bad "no half-made workspace"

# Photo folder: RGBA photos composited onto white; a second ingest replaces the first.
expect 0 "ingest photos" -- "$tool" ingest "$spray" -o "$ws" --frames 5 --json --quiet
json_check "photo summary" 'd["source"]=="photos" and d["frames"]==5 and d["frames_read"]==27 and (d["width"],d["height"])==(750,1000) and d["mixed_orientation"] is False'
[ "$(ls "$ws/ingest/images" | wc -l)" -eq 5 ] && ok || bad "the new ingest replaced the old frames"
expect 0 "info" -- "$tool" info "$ws" --json
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert "ingest" in d["stages"]' "$tmp/out" \
  && ok || bad "info lists the ingest stage"

cli_finish
