#!/usr/bin/env bash
# 3D models at the command line (`ingest MODEL.glb`, `real`): help, and the inputs that must
# fail with one clear line while an existing workspace stays exactly as it was and a new one is
# not left behind: a file that is not a glTF, a compressed glTF (EXT_meshopt_compression, which
# Debian's Blender importer lacks), a model whose only material is fully transparent (it
# renders empty), a model whose vertices are all at one point, a Blender that hangs (stopped
# after $VF_BLENDER_TIMEOUT silent seconds; its log is kept in $TMPDIR), a missing Blender, and `real` on
# a workspace that was not made from a model or has no attack yet; and that `--scene room` renders
# opaque RGB views and records its scene.
source "$(dirname "$0")/shell_checks.sh"

models="$shared/data/models_3d"
help_works ingest real
grep -q "MODEL.glb" <("$tool" ingest --help) && ok || bad "ingest --help names 3D models"

tiny=(--views 3 --test-views 1 --render-size 16 --render-samples 1 --quiet)
ws="$tmp/ws"
expect 0 "a small capture of the bell pepper" -- \
  "$tool" ingest "$models/bell_pepper__yellow_bell_pepper.glb" -o "$ws" "${tiny[@]}"
python3 -c "
import json, sys
o = json.load(open('$ws/ingest/object.json'))
t = json.load(open('$ws/ingest/transforms.json'))
ok = o['model'].endswith('bell_pepper__yellow_bell_pepper.glb') and abs(o['radius'] - 1) < 1e-3 \
     and o['transform']['scale'] > 0 and len(t['frames']) == 3
sys.exit(0 if ok else 1)" && ok || bad "object.json records the model, its unit-sphere transform, 3 views"
# the room: the object on a textured floor inside a wall, opaque RGB renders
expect 0 "a small capture in the room" -- \
  "$tool" ingest "$models/bell_pepper__yellow_bell_pepper.glb" -o "$tmp/room" "${tiny[@]}" --scene room
python3 -c "
import json, struct, sys
o = json.load(open('$tmp/room/ingest/object.json'))
png = open('$tmp/room/ingest/images/r_000.png', 'rb').read(26)
colour_type = png[25]  # IHDR: 2 is RGB, 6 is RGBA
sys.exit(0 if o['render']['scene'] == 'room' and o['mean_coverage'] is None and colour_type == 2 else 1)" \
  && ok || bad "a room capture records its scene and renders opaque RGB"
expect 1 "bad scene" -- "$tool" ingest "$models/bell_pepper__yellow_bell_pepper.glb" -o "$tmp/room2" \
  "${tiny[@]}" --scene beach
one_line_naming "bad scene" "--scene"
snapshot() { (cd "$ws" && find . -type f -exec md5sum {} + | sort); }
snapshot >"$tmp/before"

# models made here: not a glTF, fully transparent, all at one point
head -c 4096 /dev/urandom >"$tmp/noise.glb"
python3 - "$tmp" <<'PY'
import base64, json, struct, sys
def gltf(path, points, alpha):
    data = b"".join(struct.pack("<3f", *p) for p in points)
    doc = {"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "scene": 0,
           "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
           "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, alpha]},
                          "alphaMode": "BLEND", "doubleSided": True}],
           "buffers": [{"byteLength": len(data),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
           "bufferViews": [{"buffer": 0, "byteLength": len(data)}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(points),
                          "type": "VEC3", "min": [min(p[k] for p in points) for k in range(3)],
                          "max": [max(p[k] for p in points) for k in range(3)]}]}
    json.dump(doc, open(path, "w"))
tri = [(-1, 0, -1), (1, 0, -1), (0, 0, 1)]
gltf(sys.argv[1] + "/clear.gltf", tri, 0.0)
gltf(sys.argv[1] + "/point.gltf", [(0.5, 0.5, 0.5)] * 3, 1.0)
PY

fails() { # CODE DESCRIPTION NEEDLE MODEL [env...]
  local code=$1 what=$2 needle=$3 model=$4; shift 4
  expect "$code" "$what" -- env "$@" "$tool" ingest "$model" -o "$ws" "${tiny[@]}"
  one_line_naming "$what" "$needle"
  expect "$code" "$what (new workspace)" -- env "$@" "$tool" ingest "$model" -o "$tmp/new" "${tiny[@]}"
  [ -e "$tmp/new" ] && bad "$what: no new workspace left behind" || ok
}
fails 1 "not a glTF" "cannot import" "$tmp/noise.glb"
fails 1 "compressed glTF" "EXT_meshopt_compression" "$models/ToyCar_meshopt_webp.glb"
grep -q "gltf-transform" "$tmp/err" && ok || bad "the compressed glTF's line says how to convert it"
fails 1 "transparent model" "renders empty" "$tmp/clear.gltf"
fails 1 "degenerate model" "one point" "$tmp/point.gltf"
fails 1 "missing model" "no such file" "$tmp/nothing.glb"
printf '#!/bin/sh\necho "Blender 3.4.1"\nexec sleep 60\n' >"$tmp/hung-blender"
chmod +x "$tmp/hung-blender"
fails 1 "a Blender that hangs" "printed nothing for 2 s" "$models/bell_pepper__yellow_bell_pepper.glb" \
  VF_BLENDER="$tmp/hung-blender" VF_BLENDER_TIMEOUT=2 TMPDIR="$tmp"
kept=$(grep -o "Blender's log: [^)]*" "$tmp/err" | cut -d' ' -f3)
[ -n "$kept" ] && grep -q "Blender 3.4.1" "$kept" && ok ||
  bad "the line names Blender's log, kept outside the removed staging folder"
fails 2 "missing Blender" "blender is not installed" "$models/bell_pepper__yellow_bell_pepper.glb" \
  PATH=/nonexistent VF_BLENDER=
snapshot >"$tmp/after"
cmp -s "$tmp/before" "$tmp/after" && ok || bad "failed ingests left the workspace as it was"
ls -a "$ws" | grep -q partial && bad "no staging folder left behind" || ok

# real: needs a model's workspace with an attack
expect 1 "real before attack" -- "$tool" real "$ws"
one_line_naming "real before attack" "vfcapture attack"
chair="$shared/data/nerf_synthetic/chair/transforms_train.json"
expect 0 "ingest chair" -- "$tool" ingest --transforms "$chair" -o "$tmp/chair" --quiet
expect 1 "real on a posed set" -- "$tool" real "$tmp/chair"
one_line_naming "real on a posed set" "not made from a 3D model"
expect 1 "real: bad option" -- "$tool" real "$ws" --fluctuation-samples 0
one_line_naming "real: bad option" "fluctuation-samples"
cli_finish
