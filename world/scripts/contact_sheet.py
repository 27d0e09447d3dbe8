#!/usr/bin/env python3
"""Tiles PPM frames into one PNG (stdlib only): contact_sheet.py OUT.png TILE_W COLUMNS A.ppm [B.ppm ...]

Each frame is scaled down (box filter, integer factor) to TILE_W pixels wide and labelled by
nothing but its position; used for docs/conditions.png.
"""
import struct
import sys
import zlib


def read_ppm(path):
    with open(path, "rb") as f:
        data = f.read()
    parts = data.split(maxsplit=4)
    if parts[0] != b"P6":
        raise SystemExit(f"{path}: not a binary PPM")
    w, h, maxval = int(parts[1]), int(parts[2]), int(parts[3])
    if maxval != 255:
        raise SystemExit(f"{path}: maxval {maxval} unsupported")
    pixels = parts[4][: w * h * 3]
    return w, h, pixels


def downscale(w, h, px, tile_w):
    f = max(1, w // tile_w)
    tw, th = w // f, h // f
    out = bytearray(tw * th * 3)
    for y in range(th):
        for x in range(tw):
            acc = [0, 0, 0]
            for dy in range(f):
                row = ((y * f + dy) * w + x * f) * 3
                for dx in range(f):
                    i = row + dx * 3
                    acc[0] += px[i]
                    acc[1] += px[i + 1]
                    acc[2] += px[i + 2]
            n = f * f
            o = (y * tw + x) * 3
            out[o:o + 3] = bytes((acc[0] // n, acc[1] // n, acc[2] // n))
    return tw, th, out


def write_png(path, w, h, rgb):
    raw = b"".join(b"\x00" + bytes(rgb[y * w * 3:(y + 1) * w * 3]) for y in range(h))

    def chunk(tag, body):
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def main():
    if len(sys.argv) < 5:
        raise SystemExit(__doc__)
    out, tile_w, cols, files = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4:]
    tiles = [downscale(*read_ppm(p), tile_w) for p in files]
    tw, th = tiles[0][0], tiles[0][1]
    rows = (len(tiles) + cols - 1) // cols
    W, H = cols * tw + (cols - 1) * 4, rows * th + (rows - 1) * 4
    sheet = bytearray(b"\xff" * (W * H * 3))
    for k, (w, h, px) in enumerate(tiles):
        ox, oy = (k % cols) * (tw + 4), (k // cols) * (th + 4)
        for y in range(min(h, th)):
            o = ((oy + y) * W + ox) * 3
            sheet[o:o + tw * 3] = px[y * w * 3:y * w * 3 + tw * 3]
    write_png(out, W, H, sheet)


if __name__ == "__main__":
    main()
