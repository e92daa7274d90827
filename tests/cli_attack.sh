#!/usr/bin/env bash
# `vfcapture attack` and `transfer` at the command line: help, and bad input (unknown label,
# missing model, no trained field, malformed options) that fails with exit 1 and one clear
# line while the workspace stays exactly as it was.
source "$(dirname "$0")/shell_checks.sh"

chair="$shared/data/nerf_synthetic/chair/transforms_train.json"

help_works attack transfer

ws="$tmp/ws"
expect 0 "ingest chair" -- "$tool" ingest --transforms "$chair" -o "$ws" --quiet
snapshot() { (cd "$ws" && find . -type f -exec md5sum {} + | sort); }
snapshot >"$tmp/before"

# Checked before anything heavy, in the order: options, model, label set, workspace stages.
expect 1 "unknown label" -- "$tool" attack "$ws" --label "folding chair,not a class"
one_line_naming "unknown label" "not a class"
expect 1 "label index out of range" -- "$tool" attack "$ws" --label 1000
one_line_naming "label index out of range" "1000"
expect 1 "missing model" -- "$tool" attack "$ws" --model no_such_model
one_line_naming "missing model" "no_such_model"
expect 1 "missing train stage" -- "$tool" attack "$ws" --label "folding chair"
one_line_naming "missing train stage" "vfcapture train"
expect 1 "bad method" -- "$tool" attack "$ws" --method simplex
one_line_naming "bad method" "simplex"
expect 1 "bad bounds" -- "$tool" attack "$ws" --bounds "yaw=0:10"
one_line_naming "bad bounds" "yaw=0:10"
expect 1 "empty bounds" -- "$tool" attack "$ws" --bounds "psi=10:0"
one_line_naming "empty bounds" "psi"
expect 1 "bad samples" -- "$tool" attack "$ws" --samples 1
one_line_naming "bad samples" "samples"
expect 1 "mixture needs nes" -- "$tool" attack "$ws" --method pepg --components 2
one_line_naming "mixture needs nes" "components"
expect 1 "no workspace" -- "$tool" attack "$tmp/nowhere"
one_line_naming "no workspace" "nowhere"
expect 1 "transfer: missing model" -- "$tool" transfer "$ws" --models mobilenet_v2_1.0_224_quant,nope
one_line_naming "transfer: missing model" "nope"
expect 1 "transfer: no models" -- "$tool" transfer "$ws"
one_line_naming "transfer: no models" "--models"
expect 1 "transfer: no trained field" -- "$tool" transfer "$ws" --models mobilenet_v1_0.25_128_quant
one_line_naming "transfer: no trained field" "vfcapture train"

snapshot >"$tmp/after"
cmp -s "$tmp/before" "$tmp/after" && ok || bad "failed attacks left the workspace as it was"
ls -a "$ws" | grep -q partial && bad "no staging folder left behind" || ok

cli_finish
