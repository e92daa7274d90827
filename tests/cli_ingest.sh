#!/usr/bin/env bash
# The command line as a user meets it: help everywhere, exit codes, JSON output, and bad
# input that leaves the workspace as it was.
source "$(dirname "$0")/shell_checks.sh"

chair="$shared/data/nerf_synthetic/chair/transforms_train.json"

expect 0 "tool help" -- "$tool" --help
grep -q "ingest" "$tmp/out" && ok || bad "tool help lists commands"
# The command list runs from "commands:" to the next blank line.
help_works $("$tool" --help | awk '/^commands:/{on=1; next} on && !NF {exit} on {print $1}')
expect 1 "unknown command" -- "$tool" frobnicate
expect 1 "unknown option" -- "$tool" ingest --frobnicate

# A good import, with JSON on stdout.
ws="$tmp/ws"
expect 0 "ingest chair" -- "$tool" ingest --transforms "$chair" -o "$ws" --json --quiet
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["frames"]==100 and d["background"]=="transparent"' "$tmp/out" \
  && ok || bad "ingest --json reports 100 frames on a transparent background"
[ "$(ls "$ws/ingest/images" | wc -l)" -eq 100 ] && ok || bad "100 images copied"
[ ! -s "$tmp/err" ] && ok || bad "--quiet prints nothing on stderr: $(cat "$tmp/err")"
cp "$ws/ingest/transforms.json" "$tmp/before.json"
expect 0 "info" -- "$tool" info "$ws" --json
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert "ingest" in d["stages"]' "$tmp/out" \
  && ok || bad "info --json lists the ingest stage"
expect 0 "a transforms.json given like a video is imported" -- "$tool" ingest "$chair" -o "$tmp/ws_plain" --json --quiet
json_check "the same 100 frames" 'd["frames"] == 100'

# Bad input: one line, non-zero exit, the earlier import untouched.
expect 1 "missing transforms" -- "$tool" ingest --transforms "$tmp/nope.json" -o "$ws"
one_line_naming "missing transforms" "nope.json"
printf '{"camera_angle_x": 0.7, "frames": [{"file_path": "gone", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]}' >"$tmp/missing_image.json"
expect 1 "missing image" -- "$tool" ingest --transforms "$tmp/missing_image.json" -o "$ws"
one_line_naming "missing image" "gone"
echo "not json" >"$tmp/garbage.json"
expect 1 "not JSON" -- "$tool" ingest --transforms "$tmp/garbage.json" -o "$ws"
one_line_naming "not JSON" "garbage.json"
mkdir -p "$tmp/corrupt/train"
head -c 3000 "$shared/data/nerf_synthetic/chair/train/r_0.png" >"$tmp/corrupt/train/r_0.png"
printf '{"camera_angle_x": 0.69, "w": 200, "h": 200, "frames": [{"file_path": "train/r_0", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]}' >"$tmp/corrupt/t.json"
expect 1 "truncated image" -- "$tool" ingest --transforms "$tmp/corrupt/t.json" -o "$ws"
one_line_naming "truncated image" "r_0.png"
cmp -s "$ws/ingest/transforms.json" "$tmp/before.json" && ok || bad "failed imports left the workspace as it was"
[ "$(ls "$ws/ingest/images" | wc -l)" -eq 100 ] && ok || bad "images still there"
ls -a "$ws" | grep -q partial && bad "no staging folder left behind" || ok

# A folder that is not a workspace is never written into.
mkdir -p "$tmp/photos" && echo keep >"$tmp/photos/note.txt"
expect 1 "foreign folder" -- "$tool" ingest --transforms "$chair" -o "$tmp/photos"
one_line_naming "foreign folder" "not a vfcapture workspace"
[ "$(ls "$tmp/photos")" = "note.txt" ] && ok || bad "foreign folder untouched"

cli_finish
