#!/usr/bin/env python3
"""png_coverage.py IMAGE.png R,G,B MIN_ALL MIN_CENTRE

Coverage of a rendered picture: the share of pixels that differ from the background colour R,G,B
(by more than 8 in some channel), over the whole picture and over its central third (where a
framed object is). Exit 1 when either is below its minimum. Reads 8-bit RGB/RGBA PNGs with the
standard library only (zlib), so it runs wherever python3 does.
"""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(path + ": not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    channels = {2: 3, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace:
        raise ValueError(path + ": only 8-bit RGB/RGBA, not interlaced")
    raw, stride = zlib.decompress(idat), width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = previous[i]
            c = previous[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        previous = line
    return width, height, channels, rows


def main():
    path, background, min_all, min_centre = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
    bg = [int(v) for v in background.split(",")]
    width, height, channels, rows = read_png(path)
    covered = centre = centre_total = 0
    for y, row in enumerate(rows):
        for x in range(width):
            pixel = row[x * channels:x * channels + 3]
            hit = max(abs(pixel[c] - bg[c]) for c in range(3)) > 8
            covered += hit
            if width // 3 <= x < 2 * width // 3 and height // 3 <= y < 2 * height // 3:
                centre += hit
                centre_total += 1
    all_share, centre_share = covered / (width * height), centre / centre_total
    print("coverage: %.3f of the picture (minimum %.3f), %.3f of its centre (minimum %.3f)"
          % (all_share, min_all, centre_share, min_centre))
    return 0 if all_share >= min_all and centre_share >= min_centre else 1


if __name__ == "__main__":
    sys.exit(main())
