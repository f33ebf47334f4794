#!/usr/bin/env python3
"""A row of pictures for docs/evaluation.md: the exact AO (NPY, shown as sRGB grey) and some
of compare's heat maps, each scaled to 192 pixels across, as one small palette PNG.

    montage.py OUT.png EXACT.npy HEATMAP.png...
"""
import sys

import numpy as np
from PIL import Image

W = 192
tiles = []
a = np.clip(np.load(sys.argv[2])[..., 0], 0, 1)
srgb = np.where(a <= 0.0031308, 12.92 * a, 1.055 * a ** (1 / 2.4) - 0.055)
tiles.append(Image.fromarray((srgb * 255 + 0.5).astype(np.uint8)).convert("RGB"))
tiles += [Image.open(p).convert("RGB") for p in sys.argv[3:]]
tiles = [t.resize((W, round(t.height * W / t.width)), Image.LANCZOS) for t in tiles]
h = max(t.height for t in tiles)
out = Image.new("RGB", (W * len(tiles) + 4 * (len(tiles) - 1), h), "white")
for i, t in enumerate(tiles):
    out.paste(t, (i * (W + 4), 0))
out.quantize(64).save(sys.argv[1], optimize=True)
