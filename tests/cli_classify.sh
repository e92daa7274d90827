#!/usr/bin/env bash
# `vfcapture classify` and `models` as a user meets them: top-5 text and JSON, a label set
# with its accuracy, both engines named in the report, the models found by name, and bad input
# (missing image, not an image, not a model, unknown class or engine) failing with one line and
# exit 1.
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

help_works classify models
expect 0 "the default engine" -- "$tool" classify "$tench" --top 1 --json --quiet
json_check "onnxruntime runs it when installed" 'd["engine"].startswith("onnxruntime 1.30") and d["images"][0]["top"][0]["class"] == 0'
expect 0 "--engine opencv" -- "$tool" classify "$tench" --top 1 --json --quiet --engine opencv
json_check "opencv runs it" 'd["engine"] == "opencv 4.6.0" and d["images"][0]["top"][0]["class"] == 0'
expect 0 "VF_ENGINE=opencv" -- env VF_ENGINE=opencv "$tool" classify "$tench" --top 1 --json --quiet
json_check "the variable chooses too" 'd["engine"].startswith("opencv")'
expect 1 "unknown engine" -- "$tool" classify "$tench" --engine tensorflow
one_line_naming "unknown engine" "tensorflow"
expect 1 "unknown VF_ENGINE" -- env VF_ENGINE=tpu "$tool" classify "$tench"
one_line_naming "unknown VF_ENGINE" "VF_ENGINE"

# models: the shared six, and a user's own folder searched first.
mkdir -p "$tmp/mine"
cp "$shared/models/mobilenet_v1_0.25_128_quant.onnx" "$tmp/mine/tiny_copy.onnx"
echo "not onnx" >"$tmp/mine/broken.onnx"
expect 0 "models --json" -- env VF_MODELS_DIR="$tmp/mine" "$tool" models --json
json_check "shared and own models, the broken one with its reason" '[m["name"] for m in d["models"]][:2] == ["broken", "tiny_copy"] and "error" in d["models"][0] and d["models"][1]["input_size"] == 128 and d["folders"][0].endswith("/mine") and any(m["name"] == "mobilenet_v2_1.0_224_quant" and m["input_size"] == 224 and m["engine"].startswith("onnxruntime") for m in d["models"]) and len(d["models"]) >= 8'
expect 0 "a model by name from VF_MODELS_DIR" -- env VF_MODELS_DIR="$tmp/mine" "$tool" classify "$tench" --model tiny_copy --json --quiet
json_check "found in the user's folder" 'd["model"].endswith("mine/tiny_copy.onnx") and d["input_size"] == 128'
expect 1 "models: no such folder" -- "$tool" models --models-dir "$tmp/nowhere"
one_line_naming "models: no such folder" "nowhere"

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
