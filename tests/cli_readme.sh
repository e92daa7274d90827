#!/usr/bin/env bash
# The README's sample outputs are what the commands print: each `$ vfcapture ...` example of
# the walk is run on the shared data (the fox video made from its 50 photos; the chair's posed
# set for train, at a few steps) and its first line compared with the README's, numbers and a
# trailing "..." taken as wildcards. (The README once showed a poses line the command no
# longer printed.) `poses` is left out here: COLMAP on 50 frames takes two minutes, and
# tests/test_data_poses_*.c run it.
source "$(dirname "$0")/shell_checks.sh"
readme="${VF_SOURCE_DIR:?}/README.md"
fox="$shared/data/real_captures/instant_ngp_fox/images"
chair="$shared/data/nerf_synthetic/chair"

# the line after the README's "$ vfcapture COMMAND ..." example
sample() { grep -A1 -- "^ *\$ vfcapture $1" "$readme" | sed -n 2p | sed 's/^ *//'; }
# same_shape WHAT SAMPLE ACTUAL: numbers in the sample match any number, "..." anything
same_shape() {
  python3 - "$2" "$3" <<'PY' && ok || bad "$1: README says '$2', the command printed '$3'"
import re, sys
sample, actual = sys.argv[1], sys.argv[2]
pattern = re.escape(sample.rstrip(". ").rstrip())
pattern = re.sub(r"\d+(?:\\\.\d+)?", r"\\d+(?:\\.\\d+)?", pattern)
sys.exit(0 if sample and re.match(pattern, actual) else 1)
PY
}

ffmpeg -loglevel error -y -framerate 10 -pattern_type glob -i "$fox/*.jpg" -vf scale=540:960 \
  -c:v libx264 -crf 18 -pix_fmt yuv420p "$tmp/fox.mp4" && ok || bad "made fox.mp4"
line=$(cd "$tmp" && "$tool" ingest fox.mp4 -o WS -n 50 2>/dev/null | head -1)
same_shape "ingest" "$(sample 'ingest fox.mp4')" "$line"

"$tool" ingest --transforms "$chair/transforms_train.json" -o "$tmp/chair" --quiet >/dev/null 2>&1 \
  && ok || bad "ingest the chair's posed set"
line=$("$tool" train "$tmp/chair" --train-steps 40 2>/dev/null | head -1)
same_shape "train" "$(sample 'train WS')" "$line"
cli_finish
