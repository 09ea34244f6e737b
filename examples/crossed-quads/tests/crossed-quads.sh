#!/usr/bin/env bash
# The crossed quads through the CLI, end to end (ctest under xvfb-run): `treelod bake
# --technique crossed-quads` writes a package, `info` shows the chunk's summary (text and JSON),
# `render` draws the tree (pixels other than the background), `bench` times the technique. The
# CLI names no technique: all of this comes through the registries.
set -euo pipefail
treelod=$1; src=$2; out=$3
rm -rf "$out"; mkdir -p "$out"
fail() { echo "crossed-quads CLI test: $*"; exit 1; }

# 1. Bake and info.
"$treelod" bake "$src/media/oak.glb" --technique crossed-quads -q -o "$out/oak.treelod"
[ -s "$out/oak.treelod" ] || fail "no package written"
"$treelod" info "$out/oak.treelod" > "$out/info.txt"
grep -q "crossed-quads" "$out/info.txt" || { cat "$out/info.txt"; fail "info lists no crossed-quads chunk"; }
grep -q "2 quads at azimuths 0, 90 degrees" "$out/info.txt" || { cat "$out/info.txt"; fail "no summary in info"; }
"$treelod" info "$out/oak.treelod" --json > "$out/info.json"
python3 - "$out/info.json" <<'PY' || fail "info --json: see above"
import json, sys
info = json.load(open(sys.argv[1]))
text = json.dumps(info)
assert '"crossed-quads"' in text, "no crossed-quads chunk"
assert '"reference"' in text, "no reference chunk (the bake adds it)"
assert '"quadCount": 2' in text, "no crossed-quads summary"
print("info --json lists crossed-quads with its summary")
PY
"$treelod" bake --help > "$out/bake-help.txt" 2>&1 || true
grep -q "crossed-quads" "$out/bake-help.txt" || fail "bake --help does not list crossed-quads"

# 2. Render: a PNG with the tree in it (pixels unlike the corner's background colour).
"$treelod" render "$out/oak.treelod" --technique crossed-quads --camera orbit:30,10,1 --size 128x128 \
  -o "$out/oak.png"
"$treelod" render "$src/media/birch.glb" --technique crossed-quads --size 96x96 --supersample 1 -o "$out/birch.png"
for f in oak birch; do
  python3 - "$out/$f.png" <<'PY' || fail "$f.png is empty"
import struct, sys, zlib
data = open(sys.argv[1], "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
pos, idat, width = 8, b"", 0
while pos < len(data):
    size, kind = struct.unpack(">I4s", data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + size]
    if kind == b"IHDR":
        width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
        assert depth == 8 and colour in (2, 6) and interlace == 0, "unexpected PNG format"
        bpp = 3 if colour == 2 else 4
    elif kind == b"IDAT":
        idat += body
    pos += 12 + size
raw, stride, rows, prev = zlib.decompress(idat), width * bpp, [], bytearray(width * bpp)
for y in range(height):
    f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - bpp] if i >= bpp else 0
        b, c = prev[i], prev[i - bpp] if i >= bpp else 0
        p = [0, a, b, (a + b) // 2, 0][f]
        if f == 4:
            pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
            p = a if pa <= pb and pa <= pc else b if pb <= pc else c
        line[i] = (line[i] + p) & 255
    rows.append(line)
    prev = line
bg = rows[0][0:3]
tree = sum(1 for row in rows for x in range(width)
           if max(abs(row[x * bpp + k] - bg[k]) for k in range(3)) > 5)
print(f"{sys.argv[1]}: {tree} of {width * height} pixels are not background")
assert tree > 0.05 * width * height, "less than 5% of the picture is tree"
PY
done

# 3. A package without the chunk: exit 2, a message naming the chunk, no output.
"$treelod" bake "$src/media/birch.glb" -q -o "$out/birch-ref.treelod"
set +e
"$treelod" render "$out/birch-ref.treelod" --technique crossed-quads -o "$out/bad.png" 2> "$out/bad.txt"; code=$?
set -e
[ "$code" = 2 ] || fail "expected exit 2, got $code"
grep -q "crossed-quads" "$out/bad.txt" || { cat "$out/bad.txt"; fail "error does not name the chunk"; }
[ ! -e "$out/bad.png" ] || fail "bad.png written"

# 4. Bench: one tree, tiny settings; rows for crossed-quads beside the reference and the floor.
"$treelod" bench "$src/samples/scenes/single-tree.json" -o "$out/bench" --frames 3 --size 96x54 \
  --techniques crossed-quads --lod-bias 1 --samples 1 --shadow-size 0 --cache "$out/cache" -q
[ -s "$out/bench/frames.csv" ] || fail "bench wrote no frames.csv"
n=$(awk -F, 'NR > 1 && $2 == "crossed-quads"' "$out/bench/frames.csv" | wc -l)
[ "$n" = 3 ] || { head -5 "$out/bench/frames.csv"; fail "crossed-quads has $n rows in frames.csv, expected 3"; }
grep -q '"technique": "crossed-quads"' "$out/bench/summary.json" || fail "summary lacks crossed-quads"
echo "crossed-quads CLI ok"
