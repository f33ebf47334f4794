#!/usr/bin/env python3
"""Convert POV-Ray's linear 16-bit PNG (`+FN16 File_Gamma=1.0`) to a PFM (linear float), so
that `gtsphere compare` reads its values as they are (gtsphere decodes PNG as sRGB).

    png2pfm.py IN.png OUT.pfm [--exposure K]

Pure Python (zlib and struct): 8- or 16-bit, greyscale/RGB with or without alpha,
non-interlaced, all five PNG filters. Values are code / (2^depth - 1) / K (K from
wrl2pov.py --exposure, default 1); alpha is dropped.
"""

import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"png2pfm: {path} is not a PNG")
    pos, idat, header = 8, [], None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    width, height, depth, colour, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if channels is None or depth not in (8, 16) or interlace:
        sys.exit(f"png2pfm: unsupported PNG (colour type {colour}, depth {depth}, interlace {interlace})")
    bpp = channels * depth // 8
    stride = width * bpp
    raw = zlib.decompress(b"".join(idat))
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1 : (y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        rows.append(line)
        prev = line
    top = float((1 << depth) - 1)
    pixels = []
    for line in rows:
        if depth == 16:
            vals = struct.unpack(f">{width * channels}H", bytes(line))
        else:
            vals = list(line)
        row = []
        for x in range(width):
            px = vals[x * channels : (x + 1) * channels]
            if channels <= 2:
                row.append((px[0] / top,) * 3)
            else:
                row.append(tuple(v / top for v in px[:3]))
        pixels.append(row)
    return width, height, pixels


def write_pfm(path, width, height, pixels):
    with open(path, "wb") as f:
        f.write(f"PF\n{width} {height}\n-1.0\n".encode())
        for row in reversed(pixels):  # PFM rows go bottom to top
            f.write(struct.pack(f"<{3 * width}f", *[c for px in row for c in px]))


if __name__ == "__main__":
    argv = sys.argv[1:]
    k = 1.0
    if len(argv) == 4 and argv[2] == "--exposure":
        k = float(argv[3])
        argv = argv[:2]
    if len(argv) != 2:
        sys.exit(__doc__)
    w, h, px = read_png(argv[0])
    write_pfm(argv[1], w, h, [[tuple(c / k for c in p) for p in row] for row in px])
