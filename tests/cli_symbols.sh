#!/usr/bin/env bash
# The library exports only its API (vf_*) and internal functions marked as such (vf__*): a bare
# name such as `nes_step` or `plot_text` exported from libvf.a would collide with a user's own.
# And no files of the library or the commands call each other in a circle (tests/link_cycles.py;
# the old viewfool attack.c <-> nes.c, cmd_calib.c <-> calib_scale.c, board.c <-> charuco_cv.cpp
# and model_io.c <-> train.c were such circles).
source "$(dirname "$0")/shell_checks.sh"

lib="$(dirname "$tool")/libvf.a"
[ -f "$lib" ] && ok || bad "no $lib"
bare=$(nm -g --defined-only "$lib" 2>/dev/null | awk '$2 ~ /^[TDBR]$/ {print $3}' |
  grep -v -e '^vf_' -e '^_Z' | sort -u)
[ -z "$bare" ] && ok || bad "libvf.a exports unprefixed symbols: $(echo $bare | head -c 400)"

python3 "$VF_SOURCE_DIR/tests/link_cycles.py" "$(dirname "$tool")" vf vfcapture >"$tmp/cycles" \
  && ok || bad "files that call each other in a circle: $(cat "$tmp/cycles")"

cli_finish
