"""A turntable: one scene (one BVH built once) rendered from 36 cameras around it, written
as turntable/frame_00.png ... frame_35.png, with each frame's progress and then its time.

    python examples/turntable.py [N_SPHERES] [SIZE]

The spheres are a random cloud with hard shadows from a fixed point light and a dim light
from above (the headlight is off), so the shadows stay put as the camera turns. Join the
frames with, for example, `ffmpeg -i turntable/frame_%02d.png`.
"""
import math
import os
import sys

import numpy as np

import gtsphere as gt

n = int(sys.argv[1]) if len(sys.argv) > 1 else 20_000
size = int(sys.argv[2]) if len(sys.argv) > 2 else 256
rng = np.random.default_rng(0)
centers = rng.normal(0.0, 0.5, (n, 3))
scene = gt.Scene.from_arrays(
    centers, 0.6 * n ** (-1 / 3) * 0.5, rng.uniform(0.3, 1.0, (n, 3)), headlight=False
)
scene.add_point_light((2, 3, 3), intensity=0.8)
scene.add_directional_light((0, -1, 0), intensity=0.3)
os.makedirs("turntable", exist_ok=True)
for k in range(36):
    a = 2 * math.pi * k / 36
    direction = (-math.sin(a), -0.3, -math.cos(a))
    cam = gt.Camera.frame(scene, direction=direction, up=(0, 1, 0))

    def progress(done, total):
        print(f"\rframe {k + 1}/36: {100 * done // total:3d} %", end="", flush=True)

    film = gt.render(scene, cam, size, size, spp=4, progress=progress)
    gt.save(film, f"turntable/frame_{k:02d}.png")
    print(f"\rframe {k + 1}/36: {film.seconds:.2f} s", flush=True)
