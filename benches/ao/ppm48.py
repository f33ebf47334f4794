#!/usr/bin/env python3
"""Tachyon's 16-bit PPM (`-format PPM48`: linear values, code = value * 65535, clamped to
[0, 1]) to an NPY of float64 RGB, so that `gtsphere compare` reads the values as they are.

    ppm48.py IN.ppm OUT.npy
"""
import sys

import numpy as np

data = open(sys.argv[1], "rb").read()
magic, size, maxval, px = data.split(b"\n", 3)
w, h = (int(v) for v in size.split())
assert magic == b"P6" and maxval == b"65535", (magic, maxval)
img = np.frombuffer(px[:6 * w * h], dtype=">u2").reshape(h, w, 3) / 65535.0
np.save(sys.argv[2], img)
