#!/usr/bin/env bash
# Numbers on the command line are strict and their errors read alike (pipeline/cli.h): overflow,
# nan, inf, blanks, trailing junk and empty list elements are refused with one line
# "OPTION wants ..., not 'TEXT'" and exit 1, before any file is read. The old parsers took
# 4294967297x720 as 1x720 (sscanf %d overflow), a 25-digit seed (strtoull without errno),
# nan and inf lambdas and "5," as a list of one.
source "$(dirname "$0")/shell_checks.sh"
ws="$tmp/no-such-workspace"

refused() { # refused OPTION COMMAND ARGS...: exit 1 and one line naming OPTION and "wants"
  local option=$1
  shift
  expect 1 "$*" -- "$tool" "$@"
  one_line_naming "$*" "$option wants"
}
refused --size ingest --size 4294967297x720 "$tmp/video.mp4" "$ws"
refused --size ingest --size 640x "$tmp/video.mp4" "$ws"
refused --size ingest --size " 640x480" "$tmp/video.mp4" "$ws"
refused --seed attack "$ws" --seed 99999999999999999999999
refused --seed attack "$ws" --seed -1
refused --lambda attack "$ws" --lambda nan
refused --lambda attack "$ws" --lambda inf
refused --steps attack "$ws" --steps " 5"
refused --steps attack "$ws" --steps 5x
refused --minutes train "$ws" --minutes inf
refused --minutes train "$ws" --minutes 0
refused --depth train "$ws" --depth nan
refused --viewpoint render "$ws" --viewpoint 1,2,3,4,5,6,
refused --viewpoint render "$ws" --viewpoint 1,2,,3,4,5
refused --viewpoint render "$ws" --viewpoint 1,2,3,4,5,nan
refused --top classify --top 0 "$tmp/video.mp4"
refused --tolerance score "$ws" x.mp4 --tolerance 1e400
refused --board calib board --board 9x6x -o "$tmp/board.png"
refused --seed benchmark build "$ws" --seed 4294967296x

# One meaning per option name (README, "Options"): the spellings that meant something else
# in one command still work there, with one line saying what to use.
deprecated() { # deprecated OLD NEW COMMAND ARGS...: warns "OLD is deprecated: use NEW"
  local old=$1 new=$2
  shift 2
  "$tool" "$@" >"$tmp/out" 2>"$tmp/err"
  grep -q -- "$old is deprecated: use $new" "$tmp/err" && ok || bad "$*: no deprecation line: $(cat "$tmp/err")"
}
deprecated -n --steps attack "$ws" -n 5
deprecated -k --samples attack "$ws" -k 5
deprecated --steps --train-steps train "$ws" --steps 5
deprecated -n --count export "$ws" -n 2
deprecated --samples --render-samples ingest "$tmp/model.glb" -o "$ws" --samples 4
deprecated --out -o/--output eval "$ws" --transforms "$tmp/t.json" --out "$tmp/e"
deprecated --size --marker-size calib scale "$ws" --marker 3 --size 40

# A number that is in range still works the same (the parse is strict, not different).
expect 1 "a good --lambda reaches the workspace" -- "$tool" attack "$ws" --lambda 0.01 --seed 18446744073709551615
grep -q "wants" "$tmp/err" && bad "a good number refused: $(cat "$tmp/err")" || ok
cli_finish
