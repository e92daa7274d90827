#!/usr/bin/env bash
# `vfcapture classify` as a user meets it: top-5 text and JSON, a label set with its accuracy,
# and bad input (missing image, not an image, not a model, unknown class) failing with one
# line and exit 1.
source "$(dirname "$0")/shell_checks.sh"

samples="$shared/data/imagenet_samples"
tench="$samples/000_n01440764.jpg"
fox="$samples/280_n02120505.jpg"

expect 0 "classify two photos" -- "$tool" classify "$tench" "$fox"
grep -q "tench" "$tmp/out" && grep -q "fox" "$tmp/out" && ok || bad "top-5 names the right classes: $(cat "$tmp/out")"

expect 0 "classify --json with a label set" -- "$tool" classify "$tench" "$fox" --label "tench,grey fox,kit fox,red fox" --json --quiet
json_check "both correct, accuracy 1" 'd["accuracy"] == 1.0 and all(i["correct"] for i in d["images"]) and len(d["images"][0]["top"]) == 5'
expect 0 "a wrong label set" -- "$tool" classify "$tench" --label 1 --json --quiet
json_check "tench is not class 1" 'd["accuracy"] == 0.0 and not d["images"][0]["correct"]'
expect 0 "another model by name" -- "$tool" classify "$tench" --model mobilenet_v1_0.5_160_quant --top 1 --json --quiet
json_check "the 160-pixel model is used" 'd["input_size"] == 160 and d["images"][0]["top"][0]["class"] == 0'

expect 1 "missing image" -- "$tool" classify "$tmp/nope.jpg"
one_line_naming "missing image" "nope.jpg"
echo "plain text" >"$tmp/text.jpg"
expect 1 "not an image" -- "$tool" classify "$tmp/text.jpg"
one_line_naming "not an image" "text.jpg"
expect 1 "not a model" -- "$tool" classify "$tench" --model "$tmp/text.jpg"
one_line_naming "not a model" "text.jpg"
expect 1 "unknown model name" -- "$tool" classify "$tench" --model no_such_net
one_line_naming "unknown model name" "no_such_net"
expect 1 "unknown class name" -- "$tool" classify "$tench" --label "tenchy"
one_line_naming "unknown class name" "tenchy"
expect 1 "class index out of range" -- "$tool" classify "$tench" --label 1000
one_line_naming "class index out of range" "1000"
expect 1 "bad --top" -- "$tool" classify "$tench" --top 0
one_line_naming "bad --top" "--top"

cli_finish
