#!/usr/bin/env python3
"""Tachyon's 8-bit PPM (`-format PPM`, linear values, truncated: code = int(255 v)) to a PFM
(linear float), so that `gtsphere compare` reads the values as they are (gtsphere decodes
PNG as sRGB). With --side-by-side, also writes a PNG of gtsphere's PFM (left) beside the
Tachyon picture (right), both sRGB-encoded the same way, for looking at.

    ppm2pfm.py IN.ppm OUT.pfm [--side-by-side GTSPHERE.pfm OUT.png [--clamped OUT2.pfm]]

Prints how many pixels differ by more than 2/255 once gtsphere's values are clamped to 1 as
Tachyon's are (the two lighting models are the same Lambert term; see README.md), and the
largest difference. --clamped writes gtsphere's picture clamped to 1, for `gtsphere compare`.

Pure Python (struct, zlib).
"""

import argparse
import struct
import sys
import zlib


def read_ppm(path):
    data = open(path, "rb").read()
    fields, pos = [], 0
    while len(fields) < 4:  # P6, width, height, maxval, with # comments
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos)
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != b"P6" or int(fields[3]) != 255:
        sys.exit(f"ppm2pfm: {path}: only 8-bit binary PPM (P6, maxval 255)")
    w, h = int(fields[1]), int(fields[2])
    px = data[pos + 1:pos + 1 + 3 * w * h]
    # (code + 0.5) / 255: the middle of the interval that Tachyon's truncation maps to code.
    vals = [0.0 if c == 0 else (c + 0.5) / 255.0 for c in px]
    return w, h, vals  # row 0 at the top


def read_pfm(path):
    data = open(path, "rb").read()
    parts = data.split(b"\n", 3)
    if parts[0] != b"PF":
        sys.exit(f"ppm2pfm: {path}: only colour PFM")
    w, h = map(int, parts[1].split())
    scale = float(parts[2])
    fmt = ("<" if scale < 0 else ">") + "%df" % (3 * w * h)
    vals = struct.unpack(fmt, parts[3][:12 * w * h])
    rows = [vals[3 * w * j:3 * w * (j + 1)] for j in range(h)]  # PFM: bottom row first
    return w, h, [v for row in reversed(rows) for v in row]


def write_pfm(path, w, h, vals):
    rows = [vals[3 * w * j:3 * w * (j + 1)] for j in range(h)]
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        for row in reversed(rows):
            f.write(struct.pack("<%df" % (3 * w), *row))


def srgb8(v):
    v = min(max(v, 0.0), 1.0)
    v = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
    return int(round(255 * v))


def write_png(path, w, h, rgb):
    raw = b"".join(b"\x00" + bytes(rgb[3 * w * j:3 * w * (j + 1)]) for j in range(h))

    def chunk(kind, body):
        c = struct.pack(">I", len(body)) + kind + body
        return c + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 6)))
        f.write(chunk(b"IEND", b""))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("ppm")
    ap.add_argument("pfm")
    ap.add_argument("--side-by-side", nargs=2, metavar=("GTSPHERE_PFM", "OUT_PNG"))
    ap.add_argument("--clamped", metavar="OUT_PFM", help="gtsphere's PFM clamped to 1")
    a = ap.parse_args()
    w, h, t = read_ppm(a.ppm)
    write_pfm(a.pfm, w, h, t)
    if not a.side_by_side:
        return
    gw, gh, g = read_pfm(a.side_by_side[0])
    if (gw, gh) != (w, h):
        sys.exit(f"ppm2pfm: sizes differ: {gw}x{gh} and {w}x{h}")
    # Tachyon clamps to [0, 1] and truncates to 8 bits; gtsphere's PFM is unclamped (two
    # lights reach 1.6): clamp it, then allow 1/255 for the truncation and 1/255 more.
    worst, worst_at, off, over = 0.0, 0, 0, 0
    for k in range(w * h):
        d = max(abs(min(g[3 * k + c], 1.0) - t[3 * k + c]) for c in range(3))
        over += max(g[3 * k:3 * k + 3]) > 1.0
        off += d > 2.0 / 255
        if d > worst:
            worst, worst_at = d, k
    print(f"pixels {w * h}; above 1 in gtsphere (clamped) {over}; "
          f"differing by more than 2/255 after clamping {off}; "
          f"largest difference {worst:.4f} at ({worst_at % w}, {worst_at // w})")
    if a.clamped:
        write_pfm(a.clamped, w, h, [min(v, 1.0) for v in g])
    gap = 4
    W = 2 * w + gap
    rgb = bytearray(3 * W * h)
    for j in range(h):
        for i in range(w):
            for c in range(3):
                rgb[3 * (j * W + i) + c] = srgb8(g[3 * (j * w + i) + c])
                rgb[3 * (j * W + w + gap + i) + c] = srgb8(t[3 * (j * w + i) + c])
    write_png(a.side_by_side[1], W, h, rgb)


if __name__ == "__main__":
    main()
