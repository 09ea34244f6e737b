#!/usr/bin/env python3
"""Writes samples/scenes/terrain-hills.png: the grey heightmap of terrain-pssm.json.

129 x 129 pixels, 8-bit grey (0..255 = 0..1 of the script's heightScale): a few rounded hills
and a valley, smooth enough that bilinear heights between pixels stay close to a mesh's.
Pure Python (zlib, struct): `python3 tools/terrain-heightmap.py [OUT.png]`.
"""
import math
import struct
import sys
import zlib

SIZE = 129  # 2^7 + 1: one Ogre::Terrain vertex per pixel

# (x, z in -1..1, radius, height): Gaussian hills
HILLS = [(-0.45, -0.35, 0.35, 0.55), (0.40, -0.20, 0.30, 0.45), (0.10, 0.45, 0.40, 0.35),
         (-0.55, 0.55, 0.25, 0.30), (0.65, 0.65, 0.22, 0.25)]


def height(u, v):
    h = 0.15 + 0.04 * math.sin(3.1 * u + 0.7) * math.cos(2.3 * v - 0.4)
    for x, z, r, a in HILLS:
        h += a * math.exp(-((u - x) ** 2 + (v - z) ** 2) / (r * r))
    return min(max(h, 0.0), 1.0)


def png(width, height_, rows):
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + bytes(row) for row in rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height_, 8, 0, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "samples/scenes/terrain-hills.png"
    rows = []
    for j in range(SIZE):  # rows run along +Z
        v = -1.0 + 2.0 * j / (SIZE - 1)
        rows.append([round(255 * height(-1.0 + 2.0 * i / (SIZE - 1), v)) for i in range(SIZE)])
    with open(out, "wb") as f:
        f.write(png(SIZE, SIZE, rows))


if __name__ == "__main__":
    main()
