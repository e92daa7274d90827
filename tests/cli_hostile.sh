#!/usr/bin/env bash
# Untrusted files at the command line: a workspace whose field model was tampered with (a NaN
# density, a NaN box, a tiny step ratio, an extreme density shift, a header claiming a 4000^3
# grid) makes `vfcapture render` fail with one line and exit 1 within 20 s and a 3 GB address
# space (the old loader crashed, hung or tried to allocate 4 TB); an intact copy renders.
# The model is the fuzz seed (fuzz/seeds/field_model/small.vff, a 6x5x4 grid).
source "$(dirname "$0")/shell_checks.sh"

seed="${VF_SOURCE_DIR:?}/fuzz/seeds/field_model/small.vff"
ws="$tmp/ws"
mkdir -p "$ws/train"
echo '{"tool": "vfcapture", "version": "test", "stages": {"train": {"completed": "now",
  "version": "test", "seconds": 1, "params": {}, "summary": {}}}}' >"$ws/manifest.json"

# patch OFFSET FORMAT VALUES...: overwrite bytes of a copy of the seed, checksum fixed after
tamper() {
  python3 - "$seed" "$ws/train/model.vff" "$@" <<'PY'
import struct, sys
src, dst, offset, fmt = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
values = [float(v) if 'f' in fmt else int(v) for v in sys.argv[5:]]
data = bytearray(open(src, 'rb').read())
struct.pack_into('<' + fmt, data, offset, *values)
# the loader's running checksum over the pieces it reads: magic, version, size, header, values
M = (1 << 64) - 1
def h(x, b):
    i = 0
    while i + 8 <= len(b):
        x = ((x ^ struct.unpack_from('<Q', b, i)[0]) * 0x100000001b3) & M; x ^= x >> 29; i += 8
    for c in b[i:]:
        x = ((x ^ c) * 0x100000001b3) & M
    return x
x = 0xcbf29ce484222325
for a, b in ((0, 8), (8, 12), (12, 16), (16, 216), (216, len(data) - 8)):
    x = h(x, bytes(data[a:b]))
struct.pack_into('<Q', data, len(data) - 8, x)
open(dst, 'wb').write(bytes(data))
PY
}

render() { (ulimit -v 3000000; timeout 20 "$tool" render "$ws" --viewpoint 30,10,120,0,0,0 --size 32 -o "$tmp/view.png"); }

cp "$seed" "$ws/train/model.vff"
expect 0 "the intact model renders" -- render
# offsets in the seed: header at 16; density_shift +8, step_ratio +16; dims +144; box +168;
# the first grid value (a density) right after the 200-byte header
tamper 216 f nan
expect 1 "a NaN density" -- render
one_line_naming "a NaN density" "corrupt"
tamper 184 f nan
expect 1 "a NaN box" -- render
one_line_naming "a NaN box" "grid box"
tamper 32 f 1e-9
expect 1 "a tiny step ratio" -- render
one_line_naming "a tiny step ratio" "step"
tamper 24 f 1e30
expect 1 "an extreme density shift" -- render
one_line_naming "an extreme density shift" "density"
tamper 160 iii 4000 4000 4000
expect 1 "a header claiming a 4000^3 grid" -- render
one_line_naming "a header claiming a 4000^3 grid" "claims"
cli_finish
