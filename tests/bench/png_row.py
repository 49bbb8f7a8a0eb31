#!/usr/bin/env python3
"""Puts PNG images side by side, left to right, with a white gap: the panels of a figure row.

usage: png_row.py [--half] OUT.png IN.png [IN.png ...]

--half averages each image's 2x2 pixel blocks first (half the width and height). Reads the 8-bit RGB and RGBA PNGs visopt writes (non-interlaced), pads shorter images at the
bottom with white, and writes an 8-bit RGB PNG. Only the standard library (zlib), so the
reproduction script needs no image package.
"""
import struct
import sys
import zlib

GAP = 4


def read_png(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"png_row.py: {path}: not a PNG file")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    if header is None:
        sys.exit(f"png_row.py: {path}: no IHDR chunk")
    width, height, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace:
        sys.exit(f"png_row.py: {path}: only 8-bit non-interlaced RGB or RGBA is supported")
    bpp = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        filt = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if filt == 1:
                line[x] = (line[x] + a) & 255
            elif filt == 2:
                line[x] = (line[x] + b) & 255
            elif filt == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif filt == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        prev = line
        rgb = line if bpp == 3 else bytearray(v for i, v in enumerate(line) if i % 4 != 3)
        rows.append(bytes(rgb))
    return width, height, rows


def write_png(path, width, height, rows):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    def sub(row):  # filter type 1: each byte minus the byte one pixel to its left
        out = bytearray(row)
        for x in range(len(row) - 1, 2, -1):
            out[x] = (row[x] - row[x - 3]) & 255
        return bytes(out)
    raw = b"".join(b"\x01" + sub(r) for r in rows)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def halved(image):  # the mean of each 2x2 block, an odd last row or column dropped
    width, height, rows = image
    w, h = width // 2, height // 2
    out = []
    for y in range(h):
        a, b = rows[2 * y], rows[2 * y + 1]
        line = bytearray(3 * w)
        for x in range(w):
            for c in range(3):
                i = 6 * x + c
                line[3 * x + c] = (a[i] + a[i + 3] + b[i] + b[i + 3] + 2) // 4
        out.append(bytes(line))
    return w, h, out


def main():
    args = sys.argv[1:]
    half = bool(args) and args[0] == "--half"
    if half:
        args = args[1:]
    if len(args) < 2:
        sys.exit(__doc__)
    images = [read_png(p) for p in args[1:]]
    if half:
        images = [halved(i) for i in images]
    height = max(h for _, h, _ in images)
    width = sum(w for w, _, _ in images) + GAP * (len(images) - 1)
    gap = b"\xff" * (3 * GAP)
    rows = []
    for y in range(height):
        parts = [r[y] if y < h else b"\xff" * (3 * w) for w, h, r in images]
        rows.append(gap.join(parts))
    write_png(args[0], width, height, rows)


if __name__ == "__main__":
    main()
