#!/usr/bin/env bash
# The pipeline end to end on a small budget: `run` on the chair (import; poses skipped, its
# background is removed; train, attack, export), a second `run` that finds every stage up to
# date, `render` and `eval` of the trained field, a benchmark set built and scored by every
# shared model, transfer and benchmark eval with CNNs and a (small, random-weight)
# transformer in one run, and bad input to those commands failing with one line while the
# workspace stays as it was.
source "$(dirname "$0")/shell_checks.sh"

chair="$shared/data/nerf_synthetic/chair"
ws="$tmp/chair"
budget=(--train-steps 500 --steps 2 --samples 6 --label "folding chair,rocking chair")

expect 0 "run on the chair" -- "$tool" run "$chair/transforms_train.json" -o "$ws" "${budget[@]}" --json
json_check "run reports the attack" 'd["attack"]["asr_v_star"] >= 0 and d["shot_card"].endswith("shot_card.png")'
attack=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["attack_name"])' "$tmp/out")
[ "$attack" = "mobilenet_v2_1.0_224_quant-nes-l0.01-both" ] && ok || bad "run names its attack by model, method, lambda and space: $attack"
for f in train/model.vff train/report.json train/held_out.jpg "attack/$attack/attack.json" "attack/$attack/v_star.png" export/targets.json export/shot_card.png; do
  [ -s "$ws/$f" ] && ok || bad "run wrote $f"
done
python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); assert r["held_out_psnr"] > 22, r["held_out_psnr"]' "$ws/train/report.json" \
  && ok || bad "held-out PSNR after 500 steps is above 22 dB (a white image scores 14.4 dB): $(cat "$ws/train/report.json" | head -c 300)"
python3 -c '
import json, sys
r = json.load(open(sys.argv[1]))
held, fit = r["held_out"], r["training_scored"]
assert len(held) <= len(fit) <= len(held) + 2, (len(held), len(fit))
held_psnr = r.get("held_out_psnr_object", r["held_out_psnr"])  # inside the masks when given
assert abs(r["psnr_gap"] - (r["training_psnr"] - held_psnr)) < 1e-9, r
assert abs(r["psnr_gap"]) < 4, r["psnr_gap"]' "$ws/train/report.json" \
  && ok || bad "train scores as many training views and reports the train/held-out gap (under 4 dB on the chair): $(cat "$ws/train/report.json" | head -c 400)"
python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); assert r["surroundings"] == "none" and "background-removed" in r["field"], r' "$ws/train/report.json" \
  && ok || bad "auto: no outer grid for the chair's transparent background, and the report says so"
python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); assert r["color"] == "view" and r["view_smoothing"] == 0, r' "$ws/train/report.json" \
  && ok || bad "the report names the colour model (view-dependent, not smoothed for photos)"
python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); assert r["distortion"] == 0 and r["depth_points"] == 0, r' "$ws/train/report.json" \
  && ok || bad "background-removed photos: no distortion loss, no depth points"
python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); assert m["stages"]["train"]["params"]["minutes"] == 3, m["stages"]["train"]' "$ws/manifest.json" \
  && ok || bad "photos get the 3-minute default budget (recorded with the stage)"

expect 0 "run again" -- "$tool" run "$chair/transforms_train.json" -o "$ws" "${budget[@]}"
[ "$(grep -c "is up to date" "$tmp/err")" -eq 4 ] && ok || bad "every stage up to date on the second run: $(cat "$tmp/err")"
grep -q "poses is skipped: a posed set without a background" "$tmp/err" && ok \
  || bad "the chair (background removed) skips the poses stage: $(grep poses "$tmp/err")"

expect 0 "render a viewpoint" -- "$tool" render "$ws" --viewpoint 30,0,60,0,0,0 --size 128 -o "$tmp/view.png"
[ -s "$tmp/view.png" ] && ok || bad "render wrote the image"
expect 0 "render a pose" -- "$tool" render "$ws" --pose 1,0,0,0,0,1,0,0,0,0,1,4,0,0,0,1 -o "$tmp/pose.png" --quiet
expect 0 "eval on the test views" -- "$tool" eval "$ws" --transforms "$chair/transforms_test.json" -o "$tmp/eval" --json
json_check "eval: 10 views, mean PSNR above 21 dB (white: 14.4)" 'd["views"] == 10 and d["psnr"] > 21 and len(d["per_view"]) == 10'
[ -s "$tmp/eval/render_009.png" ] && [ -s "$tmp/eval/error_009.png" ] && ok || bad "eval --out saved renders and error images"

expect 0 "benchmark build" -- "$tool" benchmark build "$ws" -o "$tmp/set" --count 4 --quiet
[ "$(ls "$tmp/set/images" | wc -l)" -eq 8 ] && ok || bad "4 natural + 4 adversarial images"
expect 0 "benchmark eval, every shared model" -- "$tool" benchmark eval "$tmp/set" --models all --json --quiet
models=$(ls "$shared/models"/*.onnx | wc -l)
json_check "$models models (all of ../shared/models), natural and adversarial rows of 4 images" \
  "len(d['results']) == 4 * $models and all(r['total'] == 4 for r in d['results']) and len({r['model'] for r in d['results']}) == $models"
[ -s "$tmp/set/accuracy.png" ] && [ -s "$tmp/set/results.md" ] && ok || bad "benchmark reports written"

# CNNs and transformers side by side (tests/onnx_ops.py: a one-block ViT and a LayerNorm net,
# graphs OpenCV 4.6 cannot load).
python=/usr/bin/python3; [ -x "$python" ] || python=python3
expect 0 "build the transformer graphs" -- "$python" "$VF_SOURCE_DIR/tests/onnx_ops.py" "$tmp/ops"
mixed="mobilenet_v2_1.0_224_quant,$tmp/ops/tiny_vit.onnx,$tmp/ops/layernorm.onnx"
expect 0 "transfer to a CNN and two transformers" -- "$tool" transfer "$ws" --models "$mixed" --json --quiet
json_check "three rows, each with its engine and input size" '[r["input_size"] for r in d["models"]] == [224, 32, 16] and all(r["engine"].startswith("onnxruntime") for r in d["models"]) and all(0 <= r["natural_accuracy"] <= 1 for r in d["models"])'
expect 0 "benchmark eval with a CNN and a transformer" -- "$tool" benchmark eval "$tmp/set" --models "mobilenet_v1_0.25_128_quant,$tmp/ops/tiny_vit.onnx" --json --quiet
json_check "rows for both models, engines named" 'len({r["model"] for r in d["results"]}) == 2 and all(r["engine"].startswith("onnxruntime") for r in d["results"])'
grep -q "tiny_vit onnxruntime" "$tmp/set/results.md" && ok || bad "results.md names the engines: $(tail -2 "$tmp/set/results.md")"

# Bad input: one line, exit 1, the workspace as it was.
cp "$ws/manifest.json" "$tmp/manifest.before"
expect 1 "train: no workspace" -- "$tool" train "$tmp/nowhere"
one_line_naming "train: no workspace" "nowhere"
expect 1 "train: bad --minutes" -- "$tool" train "$ws" --minutes -1
one_line_naming "train: bad --minutes" "--minutes"
expect 1 "train: unknown surroundings" -- "$tool" train "$ws" --surroundings room
one_line_naming "train: unknown surroundings" "--surroundings"
expect 1 "train: unknown colour model" -- "$tool" train "$ws" --color shiny
one_line_naming "train: unknown colour model" "--color"
expect 1 "train: bad smoothing" -- "$tool" train "$ws" --view-smoothing -2
one_line_naming "train: bad smoothing" "--view-smoothing"
expect 1 "train: bad depth weight" -- "$tool" train "$ws" --depth nan
one_line_naming "train: bad depth weight" "--depth"
expect 1 "render: malformed viewpoint" -- "$tool" render "$ws" --viewpoint 1,2,3 -o "$tmp/x.png"
one_line_naming "render: malformed viewpoint" "--viewpoint"
expect 1 "eval: missing test set" -- "$tool" eval "$ws" --transforms "$tmp/none.json"
one_line_naming "eval: missing test set" "none.json"
expect 1 "benchmark eval: not a set" -- "$tool" benchmark eval "$ws"
one_line_naming "benchmark eval: not a set" "index.json"
expect 1 "benchmark build: existing folder" -- "$tool" benchmark build "$ws" -o "$tmp/set"
one_line_naming "benchmark build: existing folder" "already exists"
expect 1 "run: missing input" -- "$tool" run "$tmp/missing.mp4" -o "$ws"
one_line_naming "run: missing input" "missing.mp4"
cp "$ws/train/model.vff" "$tmp/model.keep"
head -c 5000 "$tmp/model.keep" >"$ws/train/model.vff"
expect 1 "render: truncated model" -- "$tool" render "$ws" --viewpoint 0,0,60,0,0,0 -o "$tmp/x.png"
one_line_naming "render: truncated model" "model.vff"
cp "$tmp/model.keep" "$ws/train/model.vff"
cmp -s "$ws/manifest.json" "$tmp/manifest.before" && ok || bad "failed commands left the manifest as it was"

# An interrupted attack continues from its checkpoint (the old code never resumed one, and
# --resume refused every real capture), other settings are refused naming --restart, and
# --restart says what it discards.
attack_args=(attack "$ws" --steps 10 --samples 6 --label "folding chair")
"$tool" "${attack_args[@]}" --quiet 2>/dev/null &
pid=$!
checkpoint="$ws/attack/.$attack.partial/checkpoint.json"
for _ in $(seq 600); do
  python3 -c 'import json,sys; sys.exit(0 if json.load(open(sys.argv[1]))["state"]["step"] >= 3 else 1)' "$checkpoint" 2>/dev/null && break
  sleep 0.2
done
kill "$pid"; wait "$pid" 2>/dev/null  # TERM: a background job ignores INT
[ -f "$checkpoint" ] && ok || bad "the interrupted attack left its checkpoint"
expect 1 "other settings" -- "$tool" attack "$ws" --steps 30 --samples 6 --label "folding chair"
grep -q -- "--restart" "$tmp/err" && ok || bad "other settings are refused naming --restart: $(tail -1 "$tmp/err")"
expect 0 "the attack continues" -- "$tool" "${attack_args[@]}" --json
grep -Eq "continuing the interrupted attack at step [3-9] of 10" "$tmp/err" && ok || bad "continued mid-way: $(grep -i continu "$tmp/err")"
json_check "all 10 steps in the result" 'len(d["loss_per_step"]) == 10'
[ ! -e "$checkpoint" ] && ok || bad "the checkpoint goes once the attack is committed"
"$tool" "${attack_args[@]}" --steps 5 --quiet 2>/dev/null &
pid=$!
for _ in $(seq 600); do [ -f "$checkpoint" ] && break; sleep 0.2; done
kill "$pid"; wait "$pid" 2>/dev/null  # TERM: a background job ignores INT
expect 0 "--restart" -- "$tool" "${attack_args[@]}" --steps 2 --restart
grep -q "discarding what an interrupted run left" "$tmp/err" && ok || bad "--restart says it discards the checkpoint: $(head -3 "$tmp/err")"

# A checkpoint of an earlier field (trained again since, here touched) is not continued: the
# search starts over on the new one (the old code continued a scene-mode attack on an
# object-mode field).
"$tool" "${attack_args[@]}" --quiet 2>/dev/null &
pid=$!
for _ in $(seq 600); do [ -f "$checkpoint" ] && break; sleep 0.2; done
kill "$pid"; wait "$pid" 2>/dev/null  # TERM: a background job ignores INT
touch -d "+1 minute" "$ws/train/model.vff"
expect 0 "an earlier field's checkpoint" -- "$tool" "${attack_args[@]}" --json
grep -q "ran on an earlier field: starting over" "$tmp/err" && ok || bad "starts over on a new field: $(grep -i continu "$tmp/err")"
json_check "all 10 steps in the result" 'len(d["loss_per_step"]) == 10'

# Several attacks side by side on one field: random search next to the NES attack, each under
# its name; a command that reads an attack asks which when there are several.
expect 0 "a second attack" -- "$tool" attack "$ws" --method random --samples 6 --label "folding chair" --quiet
[ -s "$ws/attack/mobilenet_v2_1.0_224_quant-random-both/attack.json" ] && [ -s "$ws/attack/$attack/attack.json" ] \
  && ok || bad "both attacks kept: $(ls "$ws/attack")"
expect 1 "export with two attacks" -- "$tool" export "$ws" --quiet
one_line_naming "export with two attacks" "--attack NAME"
expect 0 "export of the named attack" -- "$tool" export "$ws" --attack mobilenet_v2_1.0_224_quant-random-both --count 2 --quiet
python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); assert m["stages"]["export"]["params"]["attack"] == "mobilenet_v2_1.0_224_quant-random-both"' "$ws/manifest.json" \
  && ok || bad "export records the attack it exported"
expect 1 "export of an attack not there" -- "$tool" export "$ws" --attack nes-l9 --quiet
one_line_naming "export of an attack not there" "has no attack 'nes-l9'"

# Another input ingested into the trained workspace: what was built on the old one is stale
# and refused with one line naming what to rerun (the old code attacked the old field).
expect 0 "re-ingest another set" -- "$tool" ingest "$chair/transforms_test.json" -o "$ws" --quiet
expect 1 "attack on a stale field" -- "$tool" attack "$ws" --steps 1 --samples 6 --label "folding chair"
one_line_naming "attack on a stale field" "train is stale"
expect 1 "export of a stale attack" -- "$tool" export "$ws" --attack "$attack"
one_line_naming "export of a stale attack" "stale"
expect 1 "render of a stale field" -- "$tool" render "$ws" --viewpoint 30,0,60,0,0,0 -o "$tmp/stale.png"
one_line_naming "render of a stale field" "vfcapture train"

cli_finish
