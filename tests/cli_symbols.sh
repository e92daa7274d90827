#!/usr/bin/env bash
# The library exports only its API (vf_*) and internal functions marked as such (vf__*): a bare
# name such as `nes_step` or `plot_text` exported from libvf.a would collide with a user's own.
# And no files, nor modules (folders), of the library or the commands call each other in a
# circle (tests/link_cycles.py; the old viewfool attack.c <-> nes.c, cmd_calib.c <->
# calib_scale.c, board.c <-> charuco_cv.cpp and model_io.c <-> train.c were such circles).
source "$(dirname "$0")/shell_checks.sh"

lib="$(dirname "$tool")/libvf.a"
[ -f "$lib" ] && ok || bad "no $lib"
bare=$(nm -g --defined-only "$lib" 2>/dev/null | awk '$2 ~ /^[TDBR]$/ {print $3}' |
  grep -v -e '^vf_' -e '^_Z' | sort -u)
[ -z "$bare" ] && ok || bad "libvf.a exports unprefixed symbols: $(echo $bare | head -c 400)"

python3 "$VF_SOURCE_DIR/tests/link_cycles.py" "$(dirname "$tool")" vf vfcapture >"$tmp/cycles" \
  && ok || bad "files or modules that call each other in a circle: $(cat "$tmp/cycles")"
# The module check catches an upward call (the tree before src/stages had two module cycles:
# {attack, capture, cutout, field, object3d, sfm} and {localize, physical}).
python3 "$VF_SOURCE_DIR/tests/link_cycles.py" --self-test >"$tmp/self" && ok || bad "$(cat "$tmp/self")"

# Every double written to JSON goes through vf_json_number (null for nan and inf): jansson's
# json_real(NAN) is NULL and makes a whole json_pack document NULL (studio.c once returned
# success with no report, real.c exited 2 "cannot encode JSON"). So no json_pack format has
# an "f" and json_real is called only by vf_json_number.
python3 - "$VF_SOURCE_DIR" >"$tmp/json_f" <<'PY'
import glob, re, sys
root = sys.argv[1]
for path in sorted(glob.glob(root + "/src/**/*.c*", recursive=True) + glob.glob(root + "/pipeline/*.c") + glob.glob(root + "/calib/*.c*") + glob.glob(root + "/bench/*.c")):
    text = open(path).read()
    for m in re.finditer(r'json_pack\(\s*((?:"(?:[^"\\]|\\.)*"\s*)+)', text):
        fmt = "".join(re.findall(r'"((?:[^"\\]|\\.)*)"', m.group(1)))
        if re.search(r"(?<![A-Za-z])f", fmt):
            print(f"{path}:{text.count(chr(10), 0, m.start()) + 1}: json_pack format {fmt}")
    if not path.endswith("core/json.c"):
        for m in re.finditer(r"\bjson_real\(", text):
            print(f"{path}:{text.count(chr(10), 0, m.start()) + 1}: json_real")
PY
[ ! -s "$tmp/json_f" ] && ok || bad "doubles written around vf_json_number: $(head -5 "$tmp/json_f")"

cli_finish
