# The physical-loop commands (export, localize, reshoot, score) on bad input: exit 1 and one
# clear line saying what to do, and nothing written. (Their work on real data is checked by
# tests/test_data_physical.c.)
source "$VF_SOURCE_DIR/tests/shell_checks.sh"
fox="$shared/data/real_captures/instant_ngp_fox/images/0001.jpg"
mkdir -p "$tmp/ws"
echo '{"stages": {}}' >"$tmp/ws/manifest.json"

for c in export localize reshoot score; do
  expect 0 "$c --help" -- "$tool" "$c" --help
  grep -q "usage: vfcapture $c" "$tmp/out" && ok || bad "$c --help prints its usage"
done

expect 1 "localize without frames" -- "$tool" localize "$tmp/ws"
one_line_naming "localize without frames" "give a workspace and at least one image"
expect 1 "localize a missing file" -- "$tool" localize "$tmp/ws" "$tmp/nothing.jpg"
one_line_naming "localize a missing file" "nothing.jpg does not exist"
expect 1 "localize a text file" -- "$tool" localize "$tmp/ws" "$tmp/ws/manifest.json"
one_line_naming "localize a text file" "neither an image"
expect 1 "localize without poses" -- "$tool" localize "$tmp/ws" "$fox"
one_line_naming "localize without poses" "run 'vfcapture poses"
# A poses folder that the manifest does not mark complete (an interrupted poses, a copy) is
# not read: the old localize read WS/poses/ by its folder alone.
mkdir -p "$tmp/ws/poses/sparse" && : >"$tmp/ws/poses/sparse/cameras.txt"
expect 1 "localize with a poses folder but no completed stage" -- "$tool" localize "$tmp/ws" "$fox"
one_line_naming "localize with an unfinished poses" "has no poses yet: run 'vfcapture poses"
rm -rf "$tmp/ws/poses"
expect 1 "localize: bad --min-inliers" -- "$tool" localize "$tmp/ws" "$fox" --min-inliers 2
one_line_naming "localize: bad --min-inliers" "min-inliers"

expect 1 "export without an attack" -- "$tool" export "$tmp/ws"
one_line_naming "export without an attack" "has no attack yet: run 'vfcapture attack"
expect 1 "export: bad --count" -- "$tool" export "$tmp/ws" --count -3
one_line_naming "export: bad --count" "count"
[ ! -e "$tmp/ws/export" ] && ok || bad "a failed export writes nothing"

expect 1 "reshoot without a target" -- "$tool" reshoot "$tmp/ws" --video "$fox"
one_line_naming "reshoot without a target" "--target"
expect 1 "reshoot with two sources" -- "$tool" reshoot "$tmp/ws" --target 0 --video a.mp4 --v4l2 /dev/video9
one_line_naming "reshoot with two sources" "one source"

expect 1 "score without an attack" -- "$tool" score "$tmp/ws" "$fox"
one_line_naming "score without an attack" "has no attack yet"
expect 1 "score: bad --tolerance" -- "$tool" score "$tmp/ws" "$fox" --tolerance 0
one_line_naming "score: bad --tolerance" "tolerance"
expect 1 "score --summary without a score" -- "$tool" score --summary "$tmp/ws"
one_line_naming "score --summary without a score" "vfcapture attack"
[ ! -e "$tmp/ws/score" ] && ok || bad "a failed score writes nothing"
cli_finish
